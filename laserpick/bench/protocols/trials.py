"""What every protocol shares: the run's options, a protocol's description, and the plumbing
of one trial (its scene, a session with the scripted operator, the objects to work through).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from laserpick.bench.attempts import Attempt
from laserpick.bench.picking import ScriptedOperator, open_session
from laserpick.robot.sim.scenes import Scene, load_scene
from laserpick.server.session import Selection, StrategyName


@dataclass(frozen=True)
class Options:
    """What a run varies. scene: a user scene file instead of the protocol's own; tremor_deg:
    the aim's angular noise (deg, standard deviation); objects: work through at most this
    many objects per trial (None: all; for quick runs)."""

    selection: Selection = "auto"
    strategy: StrategyName = "gpd"
    scene: str | None = None
    tremor_deg: float = 0.3
    objects: int | None = None


TrialFn = Callable[[int, int, Options], list[Attempt]]


@dataclass(frozen=True)
class Protocol:
    """One protocol: its name on the command line, what it reruns, its defaults, and the
    function that runs one trial."""

    name: str
    source: str  #: the paper and section it reruns
    trials: int  #: the paper's number of trials
    selection: Selection  #: the default selection mode
    strategy: StrategyName  #: the default grasp strategy
    run: TrialFn


@contextmanager
def scripted_operator(
    scene: Scene, trial: int, seed: int, opt: Options
) -> Iterator[ScriptedOperator]:
    """The scripted operator of trial `trial` on a fresh session in `scene`: the session,
    the sensors and the operator's draws seeded by `seed`, the aim's tremor from `opt`. The
    session is closed on leaving."""
    session = open_session(scene, seed)
    try:
        yield ScriptedOperator(
            session,
            np.random.default_rng(seed),
            trial=trial,
            seed=seed,
            tremor=math.radians(opt.tremor_deg),
        )
    finally:
        session.close()


def protocol_scene(default: str, seed: int, opt: Options) -> Scene:
    """The user's scene of `opt`, else the built-in scene `default`, loaded with `seed`."""
    return load_scene(opt.scene or default, seed=seed)


def limit(names: list[str], opt: Options) -> list[str]:
    """The first `opt.objects` of `names` (all of them when None)."""
    return names if opt.objects is None else names[: opt.objects]


def shuffled(op: ScriptedOperator, names: list[str]) -> list[str]:
    """A copy of `names` in a random order, drawn from the operator's generator."""
    names = list(names)
    op.rng.shuffle(names)
    return names


def instances(scene: Scene) -> list[str]:
    """The object instances of `scene`, in the order it places them."""
    return [p.instance for p in scene.placements]
