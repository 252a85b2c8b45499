"""000 (Jain & Kemp, EL-E): the published outcome of grasping a cordless phone and a pill on
12 surfaces (section 5.1, Table 1)."""

from __future__ import annotations

from laserpick.bench.papers.figures import (
    Breakdown,
    Cite,
    Count,
    Figure,
    Reference,
    Row,
    TimingColumn,
    stage_timings,
)

C = Cite


_E1 = C("000", "5.1", "Table 1")


#: 000 Table 1, column by column: (measured height (m), phone grasped, pill grasped). The
#: surface names of the columns are not in the text; our `surfaces` scene gives column i the
#: name s{i:02d} at this height. The second half of the table prints two "Measured height"
#: rows (0.720 ... and 0.730 ...); the first is taken, as the scene does.
SURFACE_COLUMNS: tuple[tuple[float, bool, bool], ...] = (
    (0.008, True, True),
    (0.698, True, True),
    (0.390, True, False),
    (0.384, True, True),
    (0.730, True, False),
    (0.570, True, True),
    (0.720, True, True),
    (0.738, True, True),
    (0.746, True, False),
    (0.630, True, False),
    (0.852, True, True),
    (-0.004, True, False),
)


def _surface_rows() -> tuple[Row, ...]:
    rows = []
    for i, (height, phone, pill) in enumerate(SURFACE_COLUMNS, start=1):
        for model, ok in (("cordless_phone", phone), ("pill", pill)):
            match = (("surface", f"s{i:02d}"), ("model", model))
            rows.append(
                Row(f"column {i} ({height:.3f} m), {model}", ("yes" if ok else "no",), match)
            )
    return tuple(rows)


SURFACES = Reference(
    protocol="surfaces",
    experiment=(
        "000 §5.1, EL-E on 12 surfaces (two floors, five rectangular tables, a curved-edge "
        "table, two circular tables, a counter top, a set of drawers): one cordless phone and "
        "one pill trial per surface, 5-15 cm from the front edge"
    ),
    cite=_E1,
    figures=(
        Figure("Cordless phone grasped", "success:model=cordless_phone", Count(12, 12, 100), _E1),
        Figure("Pill grasped", "success:model=pill", Count(7, 12, 58), _E1),
        Figure(
            "Surface detection and approach",
            None,
            Count(24, 24, 100),
            C("000", "5.1"),
            note="not in our result; all 5 pill failures were segmentation failures",
        ),
    ),
    timings=(
        TimingColumn(
            "EL-E",
            C("000", "3.2"),
            stage_timings(acquire_cloud=(24.0, None)),
            note="the grasping behaviour's 320×200 tilting-laser scan; §5.1 reports no timings",
        ),
    ),
    breakdowns=(
        Breakdown(
            "EL-E's outcome per surface and object",
            _E1,
            ("grasped",),
            _surface_rows(),
            note="column i is our surface s{i:02d}, by the surfaces scene's mapping",
        ),
    ),
    notes=(
        "000 §5.1: mean absolute error of the estimated surface height 7.1 mm over the 24 "
        "trials (not in the bench result).",
    ),
)
