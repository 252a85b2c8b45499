"""003 (Huckaby et al., Jeeves): the published success per object and failures per table
location of its grasping experiment (sections V-VI, Tables I and II)."""

from __future__ import annotations

from laserpick.bench.papers.figures import (
    Breakdown,
    Cite,
    Count,
    Figure,
    Reference,
    Row,
)

C = Cite


_J1 = C("003", "VI", "Table I")


_J2 = C("003", "VI", "Table II")


#: 003 Table I: object, success (%), shape class.
JEEVES_OBJECTS: tuple[tuple[str, float, str], ...] = (
    ("Pringles", 100, "narrow"),
    ("Fanta", 100, "narrow"),
    ("Coke", 100, "narrow"),
    ("Cable Ties", 91.7, "wide"),
    ("Clorox", 95.8, "wide"),
    ("Mango Tea", 100, "box"),
    ("Earl Grey", 83.3, "box"),
    ("Goo Gone", 91.7, "odd"),
    ("Vitamins", 100, "odd"),
    ("Buzz", 58.3, "odd"),
)


#: 003 Table II: failed grasps per table location (1-6), by shape (wide, narrow, box, odd, total).
JEEVES_LOCATION_FAILURES: tuple[tuple[int, int, int, int, int], ...] = (
    (0, 0, 0, 3, 3),
    (0, 0, 2, 2, 4),
    (1, 0, 0, 1, 2),
    (1, 0, 0, 1, 2),
    (0, 0, 0, 2, 2),
    (1, 0, 2, 3, 6),
)


JEEVES = Reference(
    protocol="jeeves",
    experiment=(
        "003 §V, Jeeves' grasping experiment: ten objects, 24 attempts each, cycled through six "
        "marked table locations (5 and 15 cm from the front edge, 15 cm apart)"
    ),
    cite=_J1,
    figures=(
        Figure(
            "Grasp success, all objects",
            "grasp_success_rate",
            Count(221, 240),
            _J1,
            note="not printed: 10 × 24 attempts (§V) and Table I's rates; 19 failures (Table II)",
        ),
        Figure(
            "Narrow cylinders (Pringles, Fanta, Coke)",
            "success:model=soda_can",
            Count(None, None, 100),
            _J1,
            note="our soda can stands for 003's cans",
        ),
        Figure("Wide cylinders", None, Count(None, None, 93.75), _J1),
        Figure("Boxes", None, Count(None, None, 91.67), _J1),
        Figure("Odd shapes", None, Count(None, None, 83.33), _J1),
    ),
    breakdowns=(
        Breakdown(
            "Failed grasps per table location",
            _J2,
            ("wide", "narrow", "box", "odd", "total"),
            tuple(
                Row(f"location {i}", v, (("location", f"loc{i}"),))
                for i, v in enumerate(JEEVES_LOCATION_FAILURES, start=1)
            ),
            ours="failures",
            note=(
                "40 attempts per location (24 per object over six locations; derived). 003's "
                "numbering is in its Fig. 6, not in the text; ours is the jeeves scene's loc1-loc6"
            ),
        ),
        Breakdown(
            "Jeeves' success per object",
            _J1,
            ("success %", "shape"),
            tuple(Row(name, (pct, shape)) for name, pct, shape in JEEVES_OBJECTS),
        ),
    ),
    notes=(
        "003 reports no per-attempt timings; the whole experiment took ten to eleven hours "
        "(003 §VI).",
    ),
)
