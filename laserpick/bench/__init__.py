"""Benchmarks: the papers' experiments rerun in simulation with a scripted operator.

`laserpick bench --protocol NAME` runs one (see `protocols` and docs/bench.md);
`laserpick bench --compare OLD.json NEW.json` lists the attempts that differ between two
runs (`compare`).

- `protocols/`: the experiments, one module each; `runner`: their trials inline, in worker
  processes or on Ray; `results`: the result JSON; `attempts`: one attempt's record.
- `picking`: the scripted operator, through the session; `referee`: the simulator's truth it
  reads to aim, choose and drive (each read listed in docs/bench.md); `parking`, `driving`
  and `route_planning`: where it parks and how it drives there.
- `papers/`: the papers' published figures; `targets`: ours; `report/`: Markdown and PNG;
  `scoring`: scores against the truth.

Importing this package loads no simulator: the command line parses with PROTOCOL_NAMES.
"""

__all__ = ["FAILURE_KINDS", "MOTION_STAGES", "PROTOCOL_NAMES", "STAGES"]

#: The protocols, in the order the papers' experiments are listed (`protocols.PROTOCOLS` has
#: the same keys; kept here so that the command line parses without loading the simulator).
PROTOCOL_NAMES = (
    "isolation",
    "in-situ",
    "pick-place",
    "selection",
    "surfaces",
    "jeeves",
    "laser-scan",
)
#: The failure kinds, in the pipeline's order: 004's (Tables 3 and 5) and "precondition"
#: (e.g. no object at the mark). Every failed attempt is counted under one.
FAILURE_KINDS = (
    "detect_laser",
    "precondition",
    "detect_grasp",
    "ik_plan",
    "wrong_object",
    "execute",
)
#: The stages timed per attempt (s). All but execute_sim are wall-clock time of the pipeline;
#: plan_carry is the planning the arm stands still for while the hand holds the object (its
#: postures and paths to the basket, the tuck and the place; the way to the basket is searched
#: while the arm lifts, and counts only where it outlasts the lift: `Ahead`); execute_sim is
#: simulated time from "go" until the hand lets go of the object (in the basket or at the
#: place mark); attempt_total is their sum.
STAGES = (
    "acquire_cloud",
    "detect_laser",
    "segment",
    "detect_grasp",
    "filter",
    "select",
    "plan",
    "plan_carry",
    "execute_sim",
    "attempt_total",
)
#: execute_sim split into the arm's stages (simulated s), at the session's progress messages:
#: to the pre-grasp, the guarded approach, closing the hand, the re-grip and lift, and the
#: carry until the hand has let go (pick-and-drop; a pick-and-place ends holding). Not part
#: of attempt_total: they are execute_sim again.
MOTION_STAGES = ("to_grasp", "approach", "close", "lift", "carry")
