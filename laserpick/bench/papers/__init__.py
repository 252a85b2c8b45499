"""The published figures each `laserpick bench` protocol is compared against.

Every figure carries its citation (seed paper id, section, table) and is copied from the plain
text of the papers in /work/shared/seeds/. Where a paper does not report a figure, the value
is None; where a number is worked out from a table rather than printed, its note says so.
`figures` says how a figure is written down; one module a paper holds its figures as data
(`ur5_scooter`: 004, `el_e`: 000, `jeeves`: 003, `laser_scan`: 002). Our own targets are in
`bench.targets`.

Units: rates are fractions (0..1) unless a field says percent; times in s; heights in m.

Two things the papers do *not* give, so that no one goes looking for them here:

- 004 Table 1 (§8.1) holds only the two overall rates (grasp and detection success, with the
  baseline's); 004 publishes no per-object results and no failure breakdown for §8.1. The
  failure kinds of our runs follow 004 Tables 3 and 5 (§8.2, §8.3).
- The "Work of [5]" column in 004's tables is Gualtieri et al., ICRA 2017, as 004 prints it;
  it is not paper 002 (Shultz et al.), whose own table (46.7 % mean success) is LASER_SCAN's.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from laserpick.bench.papers.el_e import SURFACES
from laserpick.bench.papers.figures import (
    Breakdown,
    Cite,
    Count,
    Figure,
    Reference,
    Row,
    Timing,
    TimingColumn,
)
from laserpick.bench.papers.jeeves import JEEVES
from laserpick.bench.papers.laser_scan import LASER_SCAN
from laserpick.bench.papers.ur5_scooter import IN_SITU, ISOLATION, PICK_PLACE, SELECTION

__all__ = [
    "PAPERS",
    "REFERENCES",
    "Breakdown",
    "Cite",
    "Count",
    "Figure",
    "Reference",
    "Row",
    "Timing",
    "TimingColumn",
    "reference",
]

#: The seed papers, by id.
PAPERS = MappingProxyType(
    {
        "000": "Jain & Kemp, EL-E",
        "002": "Shultz et al., Baxter arm on a scooter",
        "003": "Huckaby et al., Jeeves",
        "004": "Wang et al., UR5 on a scooter",
    }
)

#: The reference of each protocol.
REFERENCES: Mapping[str, Reference] = MappingProxyType(
    {r.protocol: r for r in (ISOLATION, IN_SITU, PICK_PLACE, SELECTION, SURFACES, JEEVES,
                             LASER_SCAN)}
)  # fmt: skip


def reference(protocol: str) -> Reference:
    """The published reference of a protocol (KeyError for an unknown one)."""
    return REFERENCES[protocol]
