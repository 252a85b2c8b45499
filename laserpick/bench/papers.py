"""The published figures each `laserpick bench` protocol is compared against, and our targets.

Every figure carries its citation (seed paper id, section, table) and is copied from the plain
text of the papers in /work/shared/seeds/. Where a paper does not report a figure, the value
is None; where a number is worked out from a table rather than printed, its note says so.

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
from dataclasses import dataclass, field
from types import MappingProxyType

#: The protocols of `laserpick bench --protocol`.
PROTOCOLS = ("isolation", "in-situ", "pick-place", "selection", "surfaces", "jeeves", "laser-scan")
#: The seed papers, by id.
PAPERS = MappingProxyType(
    {
        "000": "Jain & Kemp, EL-E",
        "002": "Shultz et al., Baxter arm on a scooter",
        "003": "Huckaby et al., Jeeves",
        "004": "Wang et al., UR5 on a scooter",
    }
)


@dataclass(frozen=True)
class Cite:
    """Where a figure is printed: seed paper id, section and (if any) table."""

    paper: str
    section: str
    table: str | None = None

    def __str__(self) -> str:
        where = f"{self.paper} §{self.section}"
        return f"{where}, {self.table}" if self.table else where


@dataclass(frozen=True)
class Count:
    """A published k of n, with the percentage as printed (None where not printed)."""

    k: int | None = None
    n: int | None = None
    percent: float | None = None

    @property
    def rate(self) -> float | None:
        """The fraction (0..1): the printed percentage, else k/n, else None."""
        if self.percent is not None:
            return self.percent / 100.0
        if self.k is not None and self.n:
            return self.k / self.n
        return None

    def __str__(self) -> str:
        rate = self.rate
        if rate is None:
            return "not reported"
        p = self.percent if self.percent is not None else 100 * rate
        text = f"{p:.2f} %" if self.percent is not None and round(p, 1) != p else f"{p:.1f} %"
        return f"{text} ({self.k}/{self.n})" if self.k is not None and self.n else text


@dataclass(frozen=True)
class Figure:
    """One published figure and the metric of ours it is compared with.

    metric: how `report` computes ours from a result; one of
      "grasp_success_rate", "detect_success_rate", "task_success_rate" (the result's rates);
      "grasp_per_detection" (objects grasped / attempts whose grasp was on the object);
      "failure:<kind>[+<kind>...]" (those failures over the attempts that reached the kind's
      stage, 004's way of counting in Tables 3 and 5);
      "per_attempt:<kind>" (failures of the kind over all attempts, 004 Table 7's way);
      "success:model=<name>" (grasp successes over attempts of that model);
      "mean_object_success" (mean over models of grasp successes / attempts, 002's average);
      "pooled_success" (all grasp successes / all attempts);
      "objects_picked" (models grasped at least once / models tried);
      None: we measure nothing comparable.
    mode: for "selection", the result's mode ("auto" or "manual") the figure is compared with.
    baseline: the "Work of [5]" column of 004's tables, where it has one.
    """

    label: str
    metric: str | None
    value: Count | None
    cite: Cite
    baseline: Count | None = None
    mode: str | None = None
    note: str = ""


@dataclass(frozen=True)
class Timing:
    """A published stage time: mean and standard deviation (s); None where not printed."""

    mean_s: float | None
    std_s: float | None = None


@dataclass(frozen=True)
class TimingColumn:
    """One column of a published timing table, keyed by our stage names (picking.STAGES);
    `extra` holds the rows we do not time (driving, task totals)."""

    label: str
    cite: Cite
    stages: Mapping[str, Timing]
    extra: Mapping[str, Timing] = field(default_factory=dict)
    note: str = ""


@dataclass(frozen=True)
class Row:
    """One row of a published breakdown; `match` picks our records for the row by record field
    ("model", "surface", or "location": a `locN` found in the record's surface or instance)."""

    name: str
    values: tuple[object, ...]
    match: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Breakdown:
    """A published table by object, surface or location, printed beside ours.

    ours: what to show for our matching records: "success" (grasp successes / attempts) or
    "failures" (failed attempts / attempts).
    """

    title: str
    cite: Cite
    columns: tuple[str, ...]
    rows: tuple[Row, ...]
    ours: str = "success"
    note: str = ""


@dataclass(frozen=True)
class Reference:
    """What one protocol reruns and everything the paper publishes for it."""

    protocol: str
    experiment: str
    cite: Cite
    figures: tuple[Figure, ...]
    timings: tuple[TimingColumn, ...] = ()
    breakdowns: tuple[Breakdown, ...] = ()
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class Target:
    """A target of ours (from the issue), checked by `report.check_targets`.

    metric: "grasp_success_rate", "detect_success_rate", "task_success_rate" (>= threshold),
    "attempt_total_s" (mean attempt time, < threshold, s), or "wrong_object_manual_vs_auto"
    (manual per-attempt wrong-object rate <= threshold x the automatic one).
    protocols: the protocols it applies to; empty: all.
    """

    label: str
    metric: str
    op: str
    threshold: float
    protocols: tuple[str, ...] = ()

    def applies(self, protocol: str) -> bool:
        return not self.protocols or protocol in self.protocols


def _stages(**kw: tuple[float | None, float | None]) -> Mapping[str, Timing]:
    return MappingProxyType({k: Timing(*v) for k, v in kw.items()})


C = Cite

# --- 004 §8.1: grasping in isolation ----------------------------------------------------------
ISOLATION = Reference(
    protocol="isolation",
    experiment=(
        "004 §8.1, grasping in isolation: 15 trials, six random upright objects on a 46 cm table, "
        "stationary scooter, automatic selection, pick-and-drop (90 objects, 104 attempts)"
    ),
    cite=C("004", "8.1", "Table 1"),
    figures=(
        Figure(
            "Grasp success",
            "grasp_per_detection",
            Count(90, 96, 93.8),
            C("004", "8.1", "Table 1"),
            baseline=Count(78, 87, 89.6),
            note=(
                "004's definition: grasps that reached the basket / attempts whose grasp was on "
                "the object; ours the same (objects grasped / attempts detected)"
            ),
        ),
        Figure(
            "Grasp success per attempt",
            "grasp_success_rate",
            Count(90, 104),
            C("004", "8.1"),
            note=(
                "not printed: 90 objects grasped in 104 attempts (text); the result's "
                "grasp_success_rate counts this way"
            ),
        ),
        Figure(
            "Detection success",
            "detect_success_rate",
            Count(96, 104, 92.3),
            C("004", "8.1", "Table 1"),
            baseline=Count(108, 123, 87.8),
            note="attempts whose selected grasp was on the desired object / attempts",
        ),
        Figure(
            "Objects retrieved",
            "task_success_rate",
            Count(90, 90),
            C("004", "8.1"),
            note="text: 'It took our system 104 attempts to grasp these 90 objects'",
        ),
    ),
    timings=(
        TimingColumn(
            "004",
            C("004", "8.1", "Table 2"),
            _stages(
                acquire_cloud=(None, 2.4),
                detect_laser=(5.8, 5.3),
                detect_grasp=(7.4, 2.3),
                filter=(1.6, 0.6),
                plan=(2.4, 2.8),
                execute_sim=(24.2, 1.1),
                attempt_total=(51.7, 7.2),
            ),
            note=(
                "Table 2's Avg. cell for 'Acquire Point Cloud' is empty in the text (2.4 s stands "
                "in the Std. column); the text gives 51.7 s per grasp, the same as the table"
            ),
        ),
    ),
    notes=(
        "004 publishes no per-object results and no failure breakdown for §8.1 (Table 1 holds "
        "only the overall rates); our per-object failure table has no published counterpart.",
    ),
)

# --- 004 §8.2: grasping in-situ ---------------------------------------------------------------
_T3 = C("004", "8.2", "Table 3")
IN_SITU = Reference(
    protocol="in-situ",
    experiment=(
        "004 §8.2, grasping in-situ: 5 trials of 10 objects in a kitchen (73 cm and 31 cm tables, "
        "100 cm and 69 cm shelves), automatic selection, pick-and-drop, re-triggered until done"
    ),
    cite=_T3,
    figures=(
        Figure("Task success", "task_success_rate", Count(48, 50, 96.0), _T3, Count(43, 50, 86.0)),
        Figure(
            "Detect Laser failure",
            "failure:detect_laser",
            Count(7, 68, 10.3),
            _T3,
            Count(5, 66, 7.6),
        ),
        Figure(
            "Lost Track failure",
            None,
            None,
            _T3,
            Count(14, 93, 15.1),
            note="'n.a.' for 004: it needs no metric SLAM",
        ),
        Figure(
            "Plan Grasp failure",
            "failure:detect_grasp+ik_plan",
            Count(6, 58, 10.3),
            _T3,
            Count(13, 79, 16.5),
            note="grasp detection, IK or motion planning (text, §8.2)",
        ),
        Figure(
            "Wrong Object failure",
            "failure:wrong_object",
            Count(3, 68, 4.4),
            _T3,
            Count(2, 66, 3.0),
        ),
        Figure(
            "Execute Grasp failure",
            "failure:execute",
            Count(2, 50, 4.0),
            _T3,
            Count(17, 61, 27.9),
        ),
    ),
    timings=(
        TimingColumn(
            "004",
            C("004", "8.2", "Table 4"),
            _stages(
                acquire_cloud=(8.6, 2.7),
                detect_laser=(6.0, 3.6),
                detect_grasp=(4.7, 1.7),
                filter=(1.6, 0.9),
                plan=(2.9, 2.9),
                execute_sim=(24.3, 1.1),
                attempt_total=(50.7, 5.7),
            ),
            extra=_stages(
                driving=(11.4, 4.7), system_task_total=(57.7, 15.3), task_total=(69.0, 18.4)
            ),
            note="the baseline [5]: task total 128 ± 99 s, no stage times",
        ),
    ),
)

# --- 004 §8.3: pick-and-place in-situ ---------------------------------------------------------
_T5 = C("004", "8.3", "Table 5")
_PLACE_NOTE = "placing; our result does not count place failures apart"
PICK_PLACE = Reference(
    protocol="pick-place",
    experiment=(
        "004 §8.3, pick-and-place in-situ: 3 trials of 28 objects over seven kitchen surfaces "
        "(adds a 108 cm high table, an 87 cm counter and the ground), manual selection"
    ),
    cite=_T5,
    figures=(
        Figure("Task success", "task_success_rate", Count(81, 84, 96.4), _T5),
        Figure("Detect Laser failure (grasping)", "failure:detect_laser", Count(3, 150, 2.0), _T5),
        Figure("Detect Grasp failure (grasping)", "failure:detect_grasp", Count(12, 150, 8.0), _T5),
        Figure("IK/Planning failure (grasping)", "failure:ik_plan", Count(27, 135, 20.0), _T5),
        Figure("Wrong Object failure (grasping)", "failure:wrong_object", Count(0, 135, 0.0), _T5),
        Figure("Execute failure (grasping)", "failure:execute", Count(13, 108, 12.0), _T5),
        Figure("Detect Laser failure (placing)", None, Count(1, 104, 1.0), _T5, note=_PLACE_NOTE),
        Figure("IK/Planning failure (placing)", None, Count(8, 103, 7.8), _T5, note=_PLACE_NOTE),
        Figure("Execute failure (placing)", None, Count(3, 95, 3.2), _T5, note=_PLACE_NOTE),
    ),
    timings=(
        TimingColumn(
            "004 grasping",
            C("004", "8.3", "Table 6"),
            _stages(
                acquire_cloud=(8.3, 2.5),
                detect_laser=(6.0, 2.2),
                detect_grasp=(3.7, 1.6),
                filter=(4.9, 2.6),
                select=(2.5, 2.6),
                plan=(7.5, 6.4),
                execute_sim=(17.1, 3.9),
                attempt_total=(53.3, 9.5),
            ),
            extra=_stages(system_task_total=(129.9, None)),
            note="System Task Total 129.9 s (its Std. is not in the text; §8.3: '130s')",
        ),
        TimingColumn(
            "004 placing",
            C("004", "8.3", "Table 6"),
            _stages(
                acquire_cloud=(9.5, 4.4),
                detect_laser=(4.7, 3.0),
                plan=(1.1, 5.0),
                execute_sim=(15.6, 1.5),
                attempt_total=(35.1, 10.2),
            ),
            note=(
                "the text labels only the first pair of columns ('Grasping'); the second pair "
                "(dashes for grasp detection, filter and selection) is the placing attempt"
            ),
        ),
    ),
    notes=(
        "In 13 of the 81 successful tasks a nearby object had to be moved out of the way first "
        "(004 §8.3).",
    ),
)

# --- 004 §8.4: automatic against manual selection ---------------------------------------------
_T7 = C("004", "8.4", "Table 7")
SELECTION = Reference(
    protocol="selection",
    experiment=(
        "004 §8.4, automatic against manual grasp selection: 50 trials of two objects side by "
        "side on the §8.1 table, one pick-and-drop attempt on the target in each mode"
    ),
    cite=_T7,
    figures=(
        Figure("Wrong Object failure", "per_attempt:wrong_object", Count(13, 50, 26.0), _T7,
               mode="auto"),
        Figure("Wrong Object failure", "per_attempt:wrong_object", Count(4, 50, 8.0), _T7,
               mode="manual"),
        Figure("Grasp Execution failure", "per_attempt:execute", Count(3, 50, 6.0), _T7,
               mode="auto"),
        Figure("Grasp Execution failure", "per_attempt:execute", Count(7, 50, 14.0), _T7,
               mode="manual"),
    ),
)  # fmt: skip

# --- 000 §5.1: EL-E on 12 surfaces ------------------------------------------------------------
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
            _stages(acquire_cloud=(24.0, None)),
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

# --- 003 §V-VI: Jeeves, six table locations --------------------------------------------------
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

# --- 002 §III: Baxter arm on a scooter, laser scanned over each object ------------------------
_S1 = C("002", "III", "Table I")
#: 002 Table I: object, attempts, successes, success %, bad points, narrow, knocked (None: empty
#: cell). The cause counts do not add up to the failures (the agar packet: 7 attempts, 11 bad
#: points; the text: it 'had more bad points than possible valid grasp points').
LASER_SCAN_OBJECTS: tuple[tuple[str, int, int, float, int | None, int | None, int | None], ...] = (
    ("Rocket", 15, 14, 93.3, 1, 8, 3),
    ("Blue Ball", 15, 11, 73.3, 2, None, 2),
    ("Spice Jar", 15, 11, 73.3, 1, None, 2),
    ("Soapbox", 14, 10, 71.4, None, None, None),
    ("Vacuum Nozzle", 13, 8, 61.5, 2, None, 1),
    ("Stuffed Drill", 15, 9, 60.0, 2, None, None),
    ("Tissue Packet", 12, 7, 58.3, None, None, 1),
    ("Stuffed Toy Screw", 9, 5, 55.6, None, 2, None),
    ("Creamer", 16, 8, 50.0, 1, None, 3),
    ("White Pepper", 9, 4, 44.4, 3, None, None),
    ("Black Pepper", 22, 9, 40.9, 2, None, 9),
    ("Water Bottle", 22, 7, 31.8, 5, None, 7),
    ("Blue Bottle", 33, 12, 36.4, None, 4, 8),
    ("Coffee Stirrers", 28, 8, 28.6, None, None, 9),
    ("White Bottle", 47, 11, 23.4, 1, 2, 13),
    ("Mouse", 13, 3, 23.1, 2, 1, None),
    ("Lobster", 13, 2, 15.4, 2, 4, None),
    ("Agar Flake Packet", 7, 0, 0.0, 11, None, None),
)
#: The nearest model of our library for some of 002's objects (by kind; not the same objects).
LASER_SCAN_COUNTERPARTS = MappingProxyType(
    {
        "Blue Ball": "ball",
        "Spice Jar": "spice_jar",
        "Soapbox": "soap_box",
        "Tissue Packet": "tissue_packet",
        "Mouse": "computer_mouse",
    }
)


def _laser_scan_rows() -> tuple[Row, ...]:
    rows = []
    for name, *values in LASER_SCAN_OBJECTS:
        model = LASER_SCAN_COUNTERPARTS.get(name)
        rows.append(Row(name, tuple(values), (("model", model),) if model else ()))
    return tuple(rows)


LASER_SCAN = Reference(
    protocol="laser-scan",
    experiment=(
        "002 §II-III: the laser scanned over each object in steps of about 1.5 cm, one grasp "
        "attempt per laser point, single objects on a 46 cm table 75 cm from the camera"
    ),
    cite=_S1,
    figures=(
        Figure(
            "Mean success over objects",
            "mean_object_success",
            Count(None, None, 46.7),
            C("002", "III"),
            note="the mean of Table I's per-object rates",
        ),
        Figure(
            "Successes / attempts, pooled",
            "pooled_success",
            Count(139, 318),
            _S1,
            note="not printed: Table I's columns summed",
        ),
        Figure(
            "Objects picked at least once",
            "objects_picked",
            Count(17, 18),
            C("002", "III"),
            note="text: 'all but one of the objects'; 18 rows in Table I",
        ),
    ),
    breakdowns=(
        Breakdown(
            "Success per object",
            _S1,
            ("attempts", "successes", "success %", "bad points", "narrow", "knocked"),
            _laser_scan_rows(),
            note=(
                "ours beside an object: our nearest library model, not the same object; the "
                "cause counts do not add up to the failures (see papers.LASER_SCAN_OBJECTS)"
            ),
        ),
    ),
    notes=(
        "002 lists 'five categories' of failure but names three (bad points, narrow grasps, "
        "knocked object); it reports no timings.",
    ),
)

#: The reference of each protocol.
REFERENCES: Mapping[str, Reference] = MappingProxyType(
    {r.protocol: r for r in (ISOLATION, IN_SITU, PICK_PLACE, SELECTION, SURFACES, JEEVES,
                             LASER_SCAN)}
)  # fmt: skip

#: Our targets (from the issue).
TARGETS: tuple[Target, ...] = (
    Target(
        "Grasp success per attempt (004: 93.8 % per detected attempt)",
        "grasp_success_rate",
        ">=",
        0.94,
        ("isolation",),
    ),
    Target("Detection success (004: 92.3 %)", "detect_success_rate", ">=", 0.92, ("isolation",)),
    Target("Task success (004: 96.0 %)", "task_success_rate", ">=", 0.96, ("in-situ",)),
    Target("Task success (004: 96.4 %)", "task_success_rate", ">=", 0.96, ("pick-place",)),
    Target(
        "Manual wrong-object rate at most half the automatic (004: 8 % against 26 %)",
        "wrong_object_manual_vs_auto",
        "<=",
        0.5,
        ("selection",),
    ),
    Target("Mean attempt time", "attempt_total_s", "<", 20.0),
)


def reference(protocol: str) -> Reference:
    """The published reference of a protocol (KeyError for an unknown one)."""
    return REFERENCES[protocol]


def targets(protocol: str) -> tuple[Target, ...]:
    """The targets that apply to a protocol."""
    return tuple(t for t in TARGETS if t.applies(protocol))


def attempt_time_reference(protocol: str) -> tuple[Timing, Cite] | None:
    """The paper's mean attempt time for a protocol (s) and where it is printed, if any."""
    for column in reference(protocol).timings:
        timing = column.stages.get("attempt_total")
        if timing is not None and timing.mean_s is not None:
            return timing, column.cite
    return None
