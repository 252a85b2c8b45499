"""laserpick: assistive laser-directed pick and place with a UR5 on a mobility scooter."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("laserpick")
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "0+unknown"
