"""laserpick: assistive laser-directed pick and place with a UR5 on a mobility scooter.

The rooms, bottom up: `types` and `description` (shared values, the robot's facts), `robot`
(the `Robot` seam and its implementations) beside `pipeline` (perception and grasp decisions),
`behaviours`, then `server` and `console`, and `bench` and `cli` on top. Each room's
`__init__` names its public surface.
"""

from importlib.metadata import PackageNotFoundError, version

__all__ = ["__version__"]

try:
    __version__ = version("laserpick")
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "0+unknown"
