"""in-situ (004 section 8.2): ten of the `kitchen` objects; the user drives from the start
to each object's surface and tries until the object is in the basket (at most MAX_TRIES)."""

from __future__ import annotations

from laserpick.bench.attempts import Attempt
from laserpick.bench.parking import NO_PARKING
from laserpick.bench.protocols.retries import MAX_TRIES, TaskSpot, still_there
from laserpick.bench.protocols.trials import (
    Options,
    instances,
    limit,
    protocol_scene,
    scripted_operator,
    shuffled,
)

IN_SITU_OBJECTS = 10


def in_situ(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One in-situ trial: drive to each object and try until it is in the basket."""
    scene = protocol_scene("kitchen", seed, opt)
    out = []
    with scripted_operator(scene, trial, seed, opt) as op:
        names = shuffled(op, instances(scene))[:IN_SITU_OBJECTS]
        for task, name in enumerate(limit(names, opt)):
            spot = TaskSpot(op, scene, name)
            op.back_up, op.park_left = spot.back_up, spot.park_left
            parked = spot.go()
            for _ in range(MAX_TRIES):
                rec = op.new_attempt(name, opt.selection, opt.strategy)
                rec.task = task
                if not parked:
                    rec.fail("precondition", NO_PARKING)
                    out.append(rec)
                    break
                stood = op.referee.world_position(name)
                out.append(op.pick_and_drop(rec))
                if rec.success or not still_there(op, name, stood):
                    break
                if rec.failure == "ik_plan":
                    spot.after(rec)
                    parked = spot.go()
    return out
