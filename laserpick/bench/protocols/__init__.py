"""The papers' experiments as benchmark protocols, one trial at a time.

Each protocol is a function of (trial index, seed, options) that builds its scene, runs one
trial through a `Session` with the `ScriptedOperator`, and returns the trial's `Attempt`s. A
trial depends on nothing but its arguments, so trials can run in any process, on any machine,
in any order, and give the same attempts for the same seed. One module a protocol:

- isolation (004 section 8.1): the six objects of an `isolation` scene, marked in a random
  order, picked and dropped in the basket.
- in_situ (004 section 8.2): ten of the `kitchen` objects; the user drives from the start to
  each object's surface and tries until the object is in the basket (at most MAX_TRIES).
- pick_place (004 section 8.3): every `kitchen` object, upright or on its side by coin flip,
  picked and set down on another surface (where: `place_spots`).
- selection (004 section 8.4): two objects side by side; one attempt with automatic and one
  with manual selection, each from the same start.
- surfaces (000 section 5.1): the phone and the pill on each of the twelve surfaces of the
  `surfaces` scene, with EL-E's overhead grasp.
- jeeves (003 section V): one object per trial (ten models in turn) on each of the `jeeves`
  table's six locations, the scooter 40 cm back; the centroid approach, then a top grasp.
- laser_scan (002 section II.D): the laser stepped across each object of an `isolation` scene
  on a 1.5 cm grid; one grasp attempt per point, the object put back after each.

`trials` holds what they share (options, a trial's session), `retries` when the user tries an
object again; where the user parks and drives is `bench.parking`.

With `--scene FILE`, a protocol runs on the user's scene instead of its own: its objects
are worked through in the protocol's way (for selection, each trial marks one random object).
"""

from __future__ import annotations

from laserpick.bench.protocols.in_situ import in_situ
from laserpick.bench.protocols.isolation import isolation
from laserpick.bench.protocols.jeeves import jeeves, jeeves_scene
from laserpick.bench.protocols.laser_scan import laser_scan
from laserpick.bench.protocols.pick_place import pick_place
from laserpick.bench.protocols.selection import selection
from laserpick.bench.protocols.surfaces import surfaces
from laserpick.bench.protocols.trials import Options, Protocol, TrialFn, scripted_operator

__all__ = ["PROTOCOLS", "Options", "Protocol", "TrialFn", "jeeves_scene", "scripted_operator"]

PROTOCOLS: dict[str, Protocol] = {
    p.name: p
    for p in (
        Protocol("isolation", "004 section 8.1, Tables 1-2", 15, "auto", "gpd", isolation),
        Protocol("in-situ", "004 section 8.2, Tables 3-4", 5, "auto", "gpd", in_situ),
        Protocol("pick-place", "004 section 8.3, Tables 5-6", 3, "manual", "gpd", pick_place),
        Protocol("selection", "004 section 8.4, Table 7", 50, "auto", "gpd", selection),
        Protocol("surfaces", "000 (EL-E) section 5.1, Table 1", 1, "auto", "overhead", surfaces),
        Protocol("jeeves", "003 (Jeeves) sections V-VI, Tables I-II", 10, "auto", "jeeves", jeeves),
        Protocol("laser-scan", "002 sections II.D and III, Table I", 3, "auto", "gpd", laser_scan),
    )
}
