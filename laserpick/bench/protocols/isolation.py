"""isolation (004 section 8.1): the six objects of an `isolation` scene, marked in a random
order, picked and dropped in the basket."""

from __future__ import annotations

from laserpick.bench.attempts import Attempt
from laserpick.bench.protocols.trials import (
    Options,
    instances,
    limit,
    protocol_scene,
    scripted_operator,
    shuffled,
)


def isolation(trial: int, seed: int, opt: Options) -> list[Attempt]:
    """One isolation trial: every object of the scene, in a random order, picked and dropped."""
    scene = protocol_scene("isolation", seed, opt)
    with scripted_operator(scene, trial, seed, opt) as op:
        order = limit(shuffled(op, instances(scene)), opt)
        return [op.pick_and_drop(op.new_attempt(n, opt.selection, opt.strategy)) for n in order]
