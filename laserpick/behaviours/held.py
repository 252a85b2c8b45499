"""What the hand holds after a pick (`Held`), and the way it came to hold it (`WayIn`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.pipeline.collision import CollisionChecker
from laserpick.types import Grasp

__all__ = ["Held", "WayIn"]


@dataclass
class Held:
    """What the hand holds after a pick: the grasp, its height above the support surface (m)
    (for placing, 004 section 7.3), the object's points in the TCP frame (m, thinned, its
    unseen back filled in by `carried_shape`: the planner carries them with the hand), its
    middle in the TCP frame (m; `object_middle`: a place that turns it turns it about this),
    the obstacles around it (`base`), and the odometry's pose (x, y, yaw; m, rad) where they
    were seen (None: not tied to a place). Once the scooter has moved, the obstacles must be
    taken anew (the session does, from a fresh capture). seen_tcp: where the cameras' view
    cut the object off, its points (TCP frame) without the part `beyond_view` stood in for
    (None: as points_tcp); what is left standing where the hand lets it go (`standing_at`)."""

    grasp: Grasp
    height_above_support: float
    points_tcp: np.ndarray
    middle_tcp: np.ndarray
    surroundings: CollisionChecker
    seen_from: np.ndarray | None = None
    seen_tcp: np.ndarray | None = None

    def clear_at(self, q: np.ndarray) -> bool:
        """Whether the arm at joint angles q (6,) rad, and what it holds, keep clear of the
        `surroundings`: where a carry's search may start."""
        return bool(self.surroundings.clearance_ok(q, payload=self.points_tcp)[0])

    def at(self, T_tcp: np.ndarray) -> np.ndarray:
        """The object's points (m, `base`) with the TCP at pose T_tcp (4, 4), `base`."""
        return self.points_tcp @ T_tcp[:3, :3].T + T_tcp[:3, 3]

    @property
    def as_seen_tcp(self) -> np.ndarray:
        """The object's points in the TCP frame (m) less what stood in for a part the view
        cut off: where it will be once let go. The part guessed for a carry's safety is no
        part of where it stands or falls."""
        return self.points_tcp if self.seen_tcp is None else self.seen_tcp

    def standing_at(self, T_tcp: np.ndarray) -> np.ndarray:
        """The object as it stands once let go with the TCP at pose T_tcp (4, 4), `base`
        (m, `base`): `as_seen_tcp` there. The part guessed for a carry's safety is space the
        open hand must not be kept out of: objects set down with it taken for part of them
        were pushed off their spots by the leaving hand; set down as seen, they stood."""
        return self.as_seen_tcp @ T_tcp[:3, :3].T + T_tcp[:3, 3]


@dataclass(frozen=True)
class WayIn:
    """How the hand came to hold what it holds, for setting it back down (`put_back`): the
    odometry's pose at the grasp (x, y, yaw; m, rad), the approach's joint path (N, 6, rad)
    from the pre-grasp pose to the grasp, and the joint paths run to the end since the hand
    closed there, in order."""

    base: np.ndarray
    approach: np.ndarray
    driven: tuple[np.ndarray, ...] = ()

    def way_back(self) -> np.ndarray:
        """Every joint path driven since the grasp, backwards, as one (N, 6)."""
        back = np.vstack([p[::-1] for p in reversed(self.driven)])
        keep = np.r_[True, np.abs(np.diff(back, axis=0)).max(axis=1) > 1e-9]
        return back[keep]
