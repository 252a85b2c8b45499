"""Where the arm can hold an object over the basket to let it go: the candidate postures
(computed once: the basket is fixed to the scooter), and their ranking for one object."""

from __future__ import annotations

import functools
import itertools
import threading
from collections.abc import Callable, Sequence

import numpy as np

from laserpick.behaviours.laid_in import hand_turns, laid_in_candidates, scooter_only
from laserpick.description import dims
from laserpick.description.kinematics import ik_tcp, tcp_pose
from laserpick.pipeline.collision import CollisionChecker, held_at
from laserpick.pipeline.motion_limits import motion_limits
from laserpick.pipeline.timing import Limits, straight_times
from laserpick.settings import BehaviourSettings, MotionSettings, get_settings

__all__ = [
    "basket_opening",
    "clear_carrying",
    "drop_candidates",
    "drop_configurations",
    "holds_over_basket",
    "past_the_opening",
    "rank_drop_postures",
    "reach_times",
    "warm_drop_postures",
]

#: A rank key: (past the opening?, coarse fall, steps past, fall, time to reach it).
DropRank = tuple[int, int, int, int, float]
#: Postures checked at once: the check's arrays grow with postures x payload points x spheres.
CHUNK = 64
#: Configurations along the straight joint move whose TCP arc `reach_times` sums.
REACH_SAMPLES = 16


def drop_candidates(
    tilted: bool = False, heights: Sequence[float] | None = None
) -> tuple[np.ndarray, ...]:
    """Joint configurations for releasing over the basket, the arm clear of the scooter (rad).

    Upright (the default): the TCP over (or just inside) the basket's opening, the gripper
    pointing down or tilted up to 30 deg, turned about its axis in 30 deg steps over half a
    turn (the other half holds the object the other way round: with it, a pill bottle lying
    in the hand was let go half turned and missed the basket, not traced). Tilted: the
    gripper tilted 45-90 deg from down, toward any side, its TCP up to 20 cm beside the
    opening: for a tall object held at its top, which hangs too deep below a downward hand
    for any reachable height (the arm reaches at most 26 cm above the rim pointing down), so
    it is laid over the opening instead. heights: the TCP's heights over the rim (m;
    default: the settings' `drop_heights`). Computed once for each: the basket is fixed to
    the scooter.
    """
    if heights is None:
        heights = get_settings().behaviour.drop_heights
    return _drop_candidates(tilted, tuple(heights))


def warm_drop_postures(settings: BehaviourSettings | None = None) -> threading.Thread:
    """Work out both families of `drop_candidates` (at the settings' `drop_heights`) on a
    daemon thread, started and returned: a server does so as it starts, so that its first
    pick for the basket does not wait for them (about 0.5 s upright and 2-4 s tilted on a
    2-core machine, once a process)."""
    heights = (settings or get_settings().behaviour).drop_heights

    def work() -> None:
        drop_candidates(heights=heights)
        drop_candidates(tilted=True, heights=heights)

    thread = threading.Thread(target=work, name="drop-postures", daemon=True)
    thread.start()
    return thread


@functools.cache
def _drop_candidates(tilted: bool, heights: tuple[float, ...]) -> tuple[np.ndarray, ...]:
    centre, inner = dims.BASKET_CENTER, dims.BASKET_INNER
    rim = centre[2] + inner[2] / 2
    free = scooter_only()
    if tilted:
        offsets = np.linspace(-0.2, 0.2, 5)
        turns = hand_turns(np.arange(0, 360, 30), (45, 60, 75, 90))
        grid = itertools.product(offsets, offsets, heights, turns)
    else:
        dxs, dys = (np.linspace(-0.3, 0.3, 3) * inner[i] for i in range(2))
        grid = itertools.product(dxs, dys, heights, hand_turns(np.arange(0, 180, 30), (0, 15, 30)))
    out = []
    for dx, dy, dz, R in grid:
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = [centre[0] + dx, centre[1] + dy, rim + dz]
        Q = ik_tcp(T, dims.UR5_READY_Q)
        out += [q for q, ok in zip(Q, free.clearance_ok(Q), strict=True) if ok]
    return tuple(out)


def drop_configurations(
    q_ref: np.ndarray,
    checker: CollisionChecker,
    payload: np.ndarray,
    falls: np.ndarray | None = None,
    *,
    settings: BehaviourSettings,
    motion: MotionSettings | None = None,
) -> list[np.ndarray]:
    """Clear joint configurations that hold the object over the basket's opening, best
    first (rad): those of `drop_candidates()`, and where fewer than `drop_tries` of them
    hold the whole object inside, the postures that lay this object in
    (`laid_in_candidates`) and the tilted ones after them (an object that fits inside from
    one upright posture only stays in the hand where no path reaches that one).

    payload (P, 3), TCP frame (m): the points kept clear of everything, as carried.
    falls (F, 3), TCP frame (m): the object as it falls when let go (default `payload`):
    less the part that stands in for what the view cut off (`Held.as_seen_tcp`), which
    would pull the middle it is held by off the real object's, and let it fall beside the
    basket. motion: the carrying limits the ranking times the way there by (default: the
    settings').

    Postures that hold every point of the object inside the opening (1 cm in from the walls)
    come first, upright before laid in and tilted, each by the shortest fall (in `fall_step`
    steps: a long fall bounces the object out), then the soonest reached from q_ref
    (`reach_times`). Then those that hold its middle there, upright and tilted together
    (`rank_drop_postures`). A posture that does not hold even the middle over the opening is
    left out: an object let go there would fall beside the basket, onto the scooter or the
    floor. So is one that holds any of it past the opening's back edge, over the tiller and
    the rider's hands. Empty when none is left. The basket sits close beside the arm's base,
    between the tiller, the sensor posts and the projector, so few postures reach over it:
    they are searched, not assumed.
    """
    falls = payload if falls is None else falls
    upright, *others = _posture_families(payload, falls, q_ref, checker.margin, settings)
    ranked = rank_drop_postures(upright(), q_ref, checker, payload, falls, settings, motion)
    if sum(key[0] == 0 for key, _ in ranked) < settings.drop_tries:
        for more in others:
            ranked += rank_drop_postures(more(), q_ref, checker, payload, falls, settings, motion)
        inside = [kq for kq in ranked if kq[0][0] == 0]
        past = sorted((kq for kq in ranked if kq[0][0] != 0), key=lambda kq: kq[0])
        ranked = inside + past
    return [q for _, q in ranked]


def holds_over_basket(
    payload: np.ndarray,
    falls: np.ndarray | None = None,
    *,
    margin: float,
    settings: BehaviourSettings,
) -> bool:
    """Whether some posture that `drop_configurations` searches holds this object over the
    basket, clear of the scooter, its rider and the arm (`margin`, m, kept from them).

    payload, falls (P, 3), TCP frame (m): the object as carried and as it falls, as for
    `drop_configurations`. Asked before a pick for the basket, of each grasp: the object
    held that way by its end may hang where no posture clears the scooter, and would then
    be carried and brought back. No cloud is asked: what lies around the pick is not
    around the basket, so a grasp refused here could not have been dropped from. The
    postures are checked a chunk at a time, upright, laid in, then tilted, and the answer
    is yes at the first that holds it."""
    falls = payload if falls is None else falls
    free = scooter_only(margin)
    q_ref = dims.UR5_READY_Q
    for family in _posture_families(payload, falls, q_ref, margin, settings):
        candidates = family()
        for i in range(0, len(candidates), CHUNK):
            chunk = candidates[i : i + CHUNK]
            if rank_drop_postures(chunk, q_ref, free, payload, falls, settings):
                return True
    return False


def _posture_families(
    payload: np.ndarray,
    falls: np.ndarray,
    q_ref: np.ndarray,
    margin: float,
    settings: BehaviourSettings,
) -> tuple[Callable[[], Sequence[np.ndarray]], ...]:
    """The drop's postures (rad) in the order they are searched, each worked out when first
    asked: upright (`drop_candidates`), laying this object in (`laid_in_candidates`, from
    q_ref, `margin` m off the walls), tilted."""
    return (
        lambda: drop_candidates(heights=settings.drop_heights),
        lambda: laid_in_candidates(np.vstack([payload, falls]), q_ref, settings.drop_lows, margin),
        lambda: drop_candidates(tilted=True, heights=settings.drop_heights),
    )


def clear_carrying(checker: CollisionChecker, Q: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """(B,) bool: `checker.clearance_ok` of configurations Q (B, 6) (rad) carrying `payload`
    (P, 3), TCP frame (m), asked in chunks of CHUNK (the check's arrays grow with
    configurations x payload points x spheres)."""
    out = np.zeros(len(Q), bool)
    for i in range(0, len(Q), CHUNK):
        out[i : i + CHUNK] = checker.clearance_ok(Q[i : i + CHUNK], payload=payload)
    return out


def basket_opening() -> tuple[np.ndarray, np.ndarray]:
    """The basket's opening, 1 cm in from its walls: its lower and upper corners (m, `base`
    xy)."""
    half = dims.BASKET_INNER[:2] / 2
    return dims.BASKET_CENTER[:2] - half + 0.01, dims.BASKET_CENTER[:2] + half - 0.01


def past_the_opening(held: np.ndarray) -> np.ndarray:
    """How far (m) each point of `held` (..., 3) (m, `base`) lies past the basket's opening,
    across: 0 over it."""
    lo, hi = basket_opening()
    xy = held[..., :2]
    return np.maximum(np.maximum(lo - xy, xy - hi), 0.0).max(axis=-1)


def rank_drop_postures(
    candidates: Sequence[np.ndarray],
    q_ref: np.ndarray,
    checker: CollisionChecker,
    payload: np.ndarray,
    falls: np.ndarray,
    settings: BehaviourSettings,
    motion: MotionSettings | None = None,
) -> list[tuple[DropRank, np.ndarray]]:
    """The clear `candidates` (clear with `payload`, TCP frame, m) that hold the middle of
    the object as it falls (`falls`, TCP frame, m) over the opening, and none of it past the
    opening's back edge, toward the rider, each with its rank key, sorted. Wholly inside the
    opening: (0, 0, 0, fall, time); partly past it: (1, coarse fall, steps past, fall,
    time). The fall is the object's lowest point over the basket's floor in `fall_step`
    steps (coarse: `overhang_fall_step`), the reach past the opening in `overhang_step`
    steps, and time how long the carry there from `q_ref` takes (`reach_times`, s, at the
    carrying limits of `motion`; default: the settings')."""
    if not candidates:
        return []
    floor = dims.BASKET_FLOOR
    Q = np.array(candidates)
    T = tcp_pose(Q)
    pts = falls if len(falls) else np.zeros((1, 3))
    held = held_at(T, pts)  # (B, P, 3)
    # Past the back wall are the tiller, the handlebars and the rider's hands: nothing is let
    # go reaching over it: a cereal box let go near it came to rest on the handlebars.
    rider_side = (basket_opening()[0][0] - held[..., 0]).max(axis=1) > 0
    keep = (past_the_opening(held.mean(axis=1)) == 0) & ~rider_side
    Q, held = Q[keep], held[keep]
    clear = clear_carrying(checker, Q, payload)
    past = past_the_opening(held).max(axis=1)
    # In steps, 0 where wholly inside; the 1e-9 keeps float noise from adding a step.
    past = np.ceil(past / settings.overhang_step - 1e-9).astype(int)
    drop = held[..., 2].min(axis=1) - floor
    fall = (drop // settings.fall_step).astype(int)
    coarse = (drop // settings.overhang_fall_step).astype(int)
    motion = motion or get_settings().motion
    soon = reach_times(q_ref, Q, motion_limits(motion, carrying=True))
    ranked = [
        (
            (0, 0, 0, int(fall[i]), float(soon[i]))
            if past[i] == 0
            else (1, int(coarse[i]), int(past[i]), int(fall[i]), float(soon[i])),
            Q[i],
        )
        for i in np.flatnonzero(clear)
    ]
    ranked.sort(key=lambda kq: kq[0])
    return ranked


def reach_times(q_ref: np.ndarray, Q: np.ndarray, limits: Limits) -> np.ndarray:
    """(B,) how long (s) the straight joint move from q_ref (6,) to each of Q (B, 6) (rad)
    takes at the speed limits of `limits`, no acceleration (`timing.straight_times`). The
    TCP's arc and the hand's turning count: a posture a little nearer in joint space may
    swing the hand around the arm's mount, or turn it further, and the carry is held to
    the TCP cap near people and the carrying turn cap."""
    if len(Q) == 0:
        return np.zeros(0)
    return straight_times(np.broadcast_to(q_ref, Q.shape), Q, limits, REACH_SAMPLES)
