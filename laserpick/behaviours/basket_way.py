"""The way of what the hand holds to the basket: the postures that let it go over the
opening, best first, and the joint path to the first a search reaches. Pure planning, read
from nothing of the robot: it may run on a thread while the arm still lifts (`Ahead`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.behaviours.carry import holding_poses
from laserpick.behaviours.drop_postures import drop_configurations
from laserpick.behaviours.held import Held
from laserpick.pipeline.joint_search import joint_path_via
from laserpick.settings import Settings

__all__ = ["BasketWay", "basket_way", "drop_postures_for", "path_to_a_drop"]


@dataclass(frozen=True)
class BasketWay:
    """The carry to the basket as searched: the postures that let the object go over it,
    best first (rad), and the joint path (K, 6) rad to the first a search reached (None:
    none did). Where none did, `tucking`: the joint path (K, 6) rad the search found to the
    tucked pose, from which the carry searches on (None: none found or none needed)."""

    drops: list[np.ndarray]
    path: np.ndarray | None
    tucking: np.ndarray | None = None


def drop_postures_for(q_from: np.ndarray, held: Held, settings: Settings) -> list[np.ndarray]:
    """The postures (6,) rad that let `held` go over the basket, best first, as the carry
    from q_from (6,) rad reaches them (`drop_configurations`)."""
    return drop_configurations(
        q_from,
        held.surroundings,
        held.points_tcp,
        held.as_seen_tcp,
        settings=settings.behaviour,
        motion=settings.motion,
    )


def path_to_a_drop(
    q_from: np.ndarray,
    drops: list[np.ndarray],
    held: Held,
    settings: Settings,
    rng: np.random.Generator,
    reached: list[np.ndarray] | None = None,
) -> np.ndarray | None:
    """The joint path (K, 6) rad from q_from to one of the best `drop_tries` of `drops`: the
    straight move to the first that has one, else the first a search with `rng` toward all
    of them at once reaches (`joint_path`); where the direct search finds none, through the
    high ready pose, else through the tucked pose, the way out of a shelf's gap that the
    tuck takes, on to the basket without a stop there, the drops' wrists turned the short
    way from each (`joint_path_via`); None where none does. reached: as `joint_path_via`'s,
    the paths found to the high ready and the tucked pose."""
    tucked, high = holding_poses(held, settings)
    return joint_path_via(
        q_from,
        np.array(drops[: settings.behaviour.drop_tries]),
        held.surroundings,
        rng,
        settings.motion,
        via=(high, tucked),
        turn_goals=True,
        reached=reached,
        payload=held.points_tcp,
    )


def basket_way(
    q_from: np.ndarray, held: Held, settings: Settings, rng: np.random.Generator
) -> BasketWay | None:
    """The carry of `held` to the basket from q_from (6,) rad, searched with `rng`; None
    where the arm and what it holds are not clear there (the carry first rises clear,
    `Carrying.rise_clear`, and searches from where that leaves it). Where no way to the
    basket was found but one to the tucked pose was, the way keeps that (`tucking`)."""
    if not held.clear_at(q_from):
        return None
    drops = drop_postures_for(q_from, held, settings)
    reached: list[np.ndarray] = []
    path = path_to_a_drop(q_from, drops, held, settings, rng, reached) if drops else None
    if path is not None or not reached:
        return BasketWay(drops, path)
    tucked = holding_poses(held, settings)[0]
    tucking = next((leg for leg in reached if np.array_equal(leg[-1], tucked)), None)
    return BasketWay(drops, None, tucking)
