"""Joint-space search problems saved for replay: with LASERPICK_RECORD_PLANS=DIR set, every
search `joint_search.joint_path` starts (the straight move was blocked, both ends clear) is written
to DIR as one .npz: the start and goal (rad), the collision checker's inputs (its cloud in
`base`, m; margin and floor clearance, m; the depth frames and the arm's own space of its
seen-space test) and the check's options. `bench/planners.py` replays them with each search.

With LASERPICK_RECORD_PICKS=DIR set, every pick's planning (`first_plan.plan_first`) is
written to DIR as one pickle of what it was given: the grasps and their clouds, where the
arm stood, the state of its generator, the order and settings, and what `admit` said of
each grasp. `bench/pick_planning.py` plans them again: the planning stage's time on a
machine of one's choosing, and the same picks planned by two versions of the code. A
pickle holds the classes by name: it is read by code whose grasp and cloud types match.
Loading a pickle runs what it names: load only recordings you made.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.collision.seen_space import OwnSpace
from laserpick.settings import MotionSettings
from laserpick.types import DepthFrame, Failure, Grasp

if TYPE_CHECKING:  # grasp_choice is above the searches that record problems here
    from laserpick.pipeline.grasp_choice import GraspSet

#: The environment variable naming the folder problems are written to; unset: none are.
RECORD_ENV = "LASERPICK_RECORD_PLANS"
#: The environment variable naming the folder picks' planning is written to; unset: none is.
RECORD_PICKS_ENV = "LASERPICK_RECORD_PICKS"
#: The checker options a problem keeps (`CollisionChecker.clearance_ok`'s keywords).
OPTIONS = ("hand", "seen", "payload", "margin")


def record_search(
    q_start: np.ndarray, q_goal: np.ndarray, checker: CollisionChecker, kw: dict
) -> Path | None:
    """Write the search from q_start to q_goal (6,) (rad) with `checker` and its options `kw`
    to $LASERPICK_RECORD_PLANS, named by a hash of its content (the same problem met twice is
    kept once). Returns the file, or None when recording is off."""
    folder = os.environ.get(RECORD_ENV)
    if not folder:
        return None
    arrays = {
        "q_start": np.asarray(q_start, float),
        "q_goal": np.asarray(q_goal, float),
        "points": checker.points,
        "margin": np.float64(checker.margin),
        "floor_clearance": np.float64(checker.floor_clearance),
        "own_centres": checker._own.centres,
        "own_reach": checker._own.reach,
    }
    for k, f in enumerate(checker.frames):
        arrays |= {f"depth_{k}": f.depth, f"K_{k}": f.K, f"T_{k}": f.T_base_cam}
    for name in OPTIONS:
        if kw.get(name) is not None:
            arrays[f"opt_{name}"] = np.asarray(kw[name])
    digest = hashlib.sha1()
    for name in sorted(arrays):
        digest.update(name.encode() + np.ascontiguousarray(arrays[name]).tobytes())
    path = Path(folder) / f"{digest.hexdigest()[:16]}.npz"
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        np.savez_compressed(path, **arrays)
    return path


def load_search(path: str | Path) -> tuple[np.ndarray, np.ndarray, CollisionChecker, dict]:
    """A problem `record_search` wrote: (q_start, q_goal, checker, kw) as they were."""
    data = np.load(path)
    frames = []
    k = 0
    while f"depth_{k}" in data:
        frames.append(
            DepthFrame(
                depth=data[f"depth_{k}"],
                ir=np.zeros((0, 0), np.uint8),
                K=data[f"K_{k}"],
                T_base_cam=data[f"T_{k}"],
                camera=f"recorded_{k}",
                stamp=0.0,
            )
        )
        k += 1
    checker = CollisionChecker(
        data["points"], margin=float(data["margin"]), filtered=True, frames=frames
    )
    checker.floor_clearance = float(data["floor_clearance"])
    checker._own = OwnSpace(data["own_centres"], data["own_reach"])
    kw = {}
    for name in OPTIONS:
        if f"opt_{name}" in data:
            value = data[f"opt_{name}"]
            kw[name] = value.item() if value.ndim == 0 else value
    return data["q_start"], data["q_goal"], checker, kw


def record_pick(
    found: GraspSet,
    q_now: np.ndarray,
    rng: np.random.Generator,
    order: Sequence[Grasp],
    settings: MotionSettings,
    admit: Callable[[Grasp], Failure | None] | None,
) -> Path | None:
    """Write what `plan_first` was given (`found`; q_now (6,) rad; the state of `rng`
    before it draws; `order`; `settings`, its `MotionSettings`; and `admit`'s
    verdict on each grasp of `order`) to $LASERPICK_RECORD_PICKS, named by its place among
    the picks recorded there and a hash of it (`0007-3fa2….pkl`), so the names sort in the
    order a run planned them. Returns the file, or None when recording is off."""
    folder = os.environ.get(RECORD_PICKS_ENV)
    if not folder:
        return None
    refusals = None if admit is None else [admit(g) for g in order]
    pick = {
        "found": found,
        "q_now": np.asarray(q_now, float),
        "rng_state": rng.bit_generator.state,
        "order": list(order),
        "settings": settings,
        "refusals": refusals,
    }
    blob = pickle.dumps(pick, protocol=pickle.HIGHEST_PROTOCOL)
    folder_path = Path(folder)
    folder_path.mkdir(parents=True, exist_ok=True)
    place = sum(1 for _ in folder_path.glob("*.pkl"))
    path = folder_path / f"{place:04d}-{hashlib.sha1(blob).hexdigest()[:16]}.pkl"
    path.write_bytes(blob)
    return path


def load_pick(path: str | Path) -> dict:
    """A pick `record_pick` wrote, as `plan_first`'s arguments: found, q_now, rng (a new
    generator in the recorded state), order, settings and admit (None, or the recorded
    verdicts by grasp)."""
    pick = pickle.loads(Path(path).read_bytes())
    rng = np.random.default_rng()
    rng.bit_generator.state = pick["rng_state"]
    order, refusals = pick["order"], pick["refusals"]
    return {
        "found": pick["found"],
        "q_now": pick["q_now"],
        "rng": rng,
        "order": order,
        # Settings added since the recording take their defaults.
        "settings": MotionSettings.model_validate(dict(vars(pick["settings"]))),
        "admit": None if refusals is None else _recorded_admit(order, refusals),
    }


def _recorded_admit(
    order: Sequence[Grasp], refusals: Sequence[Failure | None]
) -> Callable[[Grasp], Failure | None]:
    """`admit` as recorded: the verdict on each grasp of `order`, by the grasp itself."""
    verdicts = {id(g): r for g, r in zip(order, refusals, strict=True)}
    return lambda grasp: verdicts[id(grasp)]
