"""Where the user points: the dual laser's mark, fused from the spots of the five IR images
(004 section 5.2).

The pointer has two parallel beams `laser_beam_separation` (1.5 cm) apart: one lit while the
user aims, both once the user confirms. `laser_spots` finds each image's spots, pairs them
and lifts them to `base`; here the views' points within `laser_match_m` are grouped (single
linkage), and the group the most cameras vouch for wins.

Which beam is which. 004 reports one position; this module reports the AIMING beam's hit, the
point the user picked before confirming. One image cannot tell the beams apart, but their
geometry can: the confirming beam leaves the pointer `laser_beam_separation` to the aiming
beam's left, horizontally and perpendicular to the beams, and runs parallel to it. So on any
surface, hit2 - hit1 = s * left + t * d (d along the beams), and since left is orthogonal to
d, (hit2 - hit1) . left = s exactly, whatever the surfaces are. `left` depends only on the
beams' heading, which the direction from the user's hand (`laser_origin`, needed only
roughly: a heading error of e changes the dot product to s * cos e) to the dot gives. The
aiming beam is the spot of the pair further right. That resolves the 0.75 cm bias the
midpoint of the two spots would carry. It cannot help when a camera sees just one spot of a
confirmed pair (the other hidden): such a view's point may be either beam's, so once any view
has resolved the pair, only resolved views' aiming points make up the reported mean, and the
others only count as agreeing views. If no camera sees both beams, the reported point may be
the confirming beam's, up to 1.5 cm off, and the state reads "aiming".

Two beams whose dots fall more than `laser_pair_px` apart in every image (the confirming beam
passes an object's edge and lands far behind) give two groups; a group offset from the
winner by about `laser_beam_separation` along `left` is taken as the other beam, not as a
disagreement, and the pair is resolved with the same rule.

Every function here reads only images, intrinsics and extrinsics: no simulator truth.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage

from laserpick.pipeline.laser_spots import find_spots, lift, pair_spots, spot_depth
from laserpick.settings import PerceptionSettings, get_settings
from laserpick.transforms import pinhole_project
from laserpick.types import DepthFrame, Failure, LaserMark

__all__ = ["KIND", "detect_mark", "direct_mark"]

KIND = "detect_laser"
#: A second group counts as the other beam when its offset along `left` is within this
#: fraction of the beam separation of the separation itself.
BEAM_OFFSET_TOL = 0.5
#: A camera vouches for a 3D point when one of its spots lies within this (px) of where the
#: point projects: about a dot's radius.
REPROJECT_PX = 3.0
#: A view vouches for a point only if some depth near its projection lies this close (m).
DEPTH_AGREE_M = 0.02


@dataclass(frozen=True)
class _Candidate:
    """One view's opinion of the mark, in `base` (m).

    paired: the image showed both beams here. resolved: both had depth, so `point` is
    known to be the aiming beam's (see the module docstring).
    """

    point: np.ndarray
    camera: int
    paired: bool
    resolved: bool


def _left(point: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Unit horizontal vector to the left of the beams' heading from `origin` to `point`."""
    yaw = math.atan2(point[1] - origin[1], point[0] - origin[0])
    return np.array([-math.sin(yaw), math.cos(yaw), 0.0])


def _aiming_first(a: np.ndarray, b: np.ndarray, origin: np.ndarray) -> tuple[np.ndarray, ...]:
    """The two beams' hits (m, `base`) ordered (aiming, confirming): the confirming beam lies
    to the left, so its hit has the larger component along `left`."""
    left = _left((a + b) / 2, origin)
    return (a, b) if a @ left <= b @ left else (b, a)


# --- per view ----------------------------------------------------------------------------------


@dataclass
class _View:
    """One camera's spots (n, 2) (u, v px), whether each is one of an image pair, and the
    candidate points they gave."""

    frame: DepthFrame
    uv: np.ndarray
    in_pair: np.ndarray
    cands: list[_Candidate]

    def votes_for(self, point: np.ndarray, tol_px: float) -> tuple[bool, bool]:
        """(a spot lies within tol_px of where `point` (m, `base`) projects and the depth there
        does not hide the point, that spot is one of a pair). The depth test is loose (any
        depth in a small window, or none): a dot on a rim mixes the rim's depth with what lies
        behind it, and a view must still vouch for the rim."""
        if len(self.uv) == 0:
            return False, False
        uvs, z, front = pinhole_project(point, self.frame.K, self.frame.T_base_cam, 0.0)
        if not front[0]:
            return False, False
        uv = uvs[0]
        d = np.hypot(*(self.uv - uv).T)
        i = int(np.argmin(d))
        if d[i] > tol_px or not self._depth_allows(uv, float(z[0])):
            return False, False
        return True, bool(self.in_pair[i])

    def _depth_allows(self, uv: np.ndarray, z: float, half: int = 3) -> bool:
        """Whether the depth image near pixel `uv` could hold a surface at depth z (m): some
        valid depth in the window lies within DEPTH_AGREE_M of z, or none is valid. A point
        behind the surface this camera sees there is hidden from it, so it cannot vouch."""
        depth = self.frame.depth
        H, W = depth.shape
        iu, iv = round(float(uv[0])), round(float(uv[1]))
        win = depth[
            max(iv - half, 0) : min(iv + half + 1, H), max(iu - half, 0) : min(iu + half + 1, W)
        ]
        valid = win[win > 0]
        return valid.size == 0 or bool(np.any(np.abs(valid - z) < DEPTH_AGREE_M))


def _view(frame: DepthFrame, camera: int, s: PerceptionSettings, origin: np.ndarray) -> _View:
    """One view's spots and candidate points (m, `base`), one per pair or lone spot."""
    spots = find_spots(frame.ir, s.laser_threshold, s.laser_spot_min_px)
    in_pair = np.zeros(len(spots), bool)
    cands: list[_Candidate] = []
    for group in pair_spots(spots, s.laser_pair_px):
        in_pair[group] = len(group) == 2
        pts = []
        for i in group:
            z = spot_depth(frame.depth, spots[i].u, spots[i].v, s.laser_depth_window_px)
            if z is not None:
                pts.append(lift(frame, spots[i].u, spots[i].v, z))
        if len(group) == 2 and len(pts) == 2:
            aiming, _ = _aiming_first(pts[0], pts[1], origin)
            cands.append(_Candidate(aiming, camera, paired=True, resolved=True))
        else:
            # A lone spot, a pair with one spot lacking depth, or an odd cluster of three or
            # more: each point with depth stands alone, beam unknown.
            paired = len(group) == 2
            cands += [_Candidate(p, camera, paired=paired, resolved=False) for p in pts]
    uv = np.array([[sp.u, sp.v] for sp in spots]).reshape(-1, 2)
    return _View(frame, uv, in_pair, cands)


# --- across views ------------------------------------------------------------------------------


def _groups(cands: Sequence[_Candidate], match_m: float) -> list[list[_Candidate]]:
    """Candidates grouped by 3D proximity (single linkage at `match_m`)."""
    if len(cands) == 1:
        return [list(cands)]
    pts = np.array([c.point for c in cands])
    ids = fcluster(linkage(pts, method="single"), t=match_m, criterion="distance")
    return [[c for c, i in zip(cands, ids, strict=True) if i == k] for k in np.unique(ids)]


def _mean(group: Sequence[_Candidate]) -> np.ndarray:
    """A group's point: the mean of the resolved aiming points if any view resolved the
    pair, else of every point."""
    resolved = [c.point for c in group if c.resolved]
    return np.mean(resolved or [c.point for c in group], axis=0)


@dataclass
class _Group:
    """A group of agreeing candidates, its point (m, `base`), and the cameras whose images
    show a dot where that point projects (`voters`), of which `paired` show it in a pair."""

    members: list[_Candidate]
    point: np.ndarray
    voters: set[int]
    paired: set[int]

    @property
    def key(self) -> tuple[int, int, int]:
        """Support, best first: voting cameras, then cameras and points that lifted here."""
        return (len(self.voters), len({c.camera for c in self.members}), len(self.members))


def _scored(cands: Sequence[_Candidate], views: Sequence[_View], s: PerceptionSettings):
    """Groups of candidates with their votes, best supported first."""
    out = []
    for members in _groups(cands, s.laser_match_m):
        p = _mean(members)
        voters, paired = set(), set()
        for i, v in enumerate(views):
            hit, pair = v.votes_for(p, REPROJECT_PX)
            if hit:
                voters.add(i)
            if pair:
                paired.add(i)
        # A candidate's own camera always sees its spot (its point lies on the spot's ray).
        voters |= {c.camera for c in members}
        paired |= {c.camera for c in members if c.paired}
        out.append(_Group(members, p, voters, paired))
    out.sort(key=lambda g: g.key, reverse=True)
    return out


def _beam_partner(
    best: _Group, others: Sequence[_Group], s: PerceptionSettings
) -> tuple[_Group, bool] | None:
    """A group that is the other beam of `best`: offset by about the beam separation along
    `left`. Returns (that group, whether it is the aiming beam), or None."""
    origin = np.asarray(s.laser_origin, float)
    left = _left(best.point, origin)
    sep = s.laser_beam_separation
    for g in others:
        if 2 * len(g.voters) < len(best.voters):
            continue  # too weakly supported to be the other beam: likely a mis-lifted dot
        offset = float((g.point - best.point) @ left)
        if abs(abs(offset) - sep) <= BEAM_OFFSET_TOL * sep:
            return g, offset < 0
    return None


def detect_mark(
    frames: Sequence[DepthFrame], settings: PerceptionSettings | None = None
) -> LaserMark | Failure:
    """The laser mark in `base` (m) from the IR and depth images of all sensors.

    Returns the aiming beam's hit, averaged over the views whose lifted points agree (see
    the module docstring). The winning group is the one the most cameras vouch for, where a
    camera vouches for a point when its image shows a dot where the point projects: this
    outvotes points lifted with the wrong depth (a dot on an object's rim, where the depth
    window reads the surface behind), which only the cameras that lifted them vouch for.
    `views` = the vouching cameras; the state is "confirmed" when at least half of them see
    the dot as one of a pair (two dots that close rarely happen by accident) or the second
    beam was found as its own group, else "aiming". Failure("detect_laser", ...) when no dot
    is seen, no dot has depth, the dot lies outside the workspace, or the views disagree (the
    two best groups have equal support and are not the two beams).
    """
    s = settings or get_settings().perception
    origin = np.asarray(s.laser_origin, float)
    lo, hi = np.asarray(s.workspace_min), np.asarray(s.workspace_max)
    views = [_view(f, i, s, origin) for i, f in enumerate(frames)]
    if not any(len(v.uv) for v in views):
        return Failure(KIND, "I can't see the laser dot: point it at the object and try again.")
    cands = [c for v in views for c in v.cands]
    if not cands:
        return Failure(
            KIND,
            "I can see the laser dot but can't tell how far away it is; it may be on something"
            " clear, shiny or too far away.",
        )
    groups = _scored(cands, views, s)
    inside = [g for g in groups if np.all((g.point >= lo) & (g.point <= hi))]
    if not inside:
        return Failure(KIND, "The laser dot is outside the area the arm can work in.")
    best = inside[0]
    # The confirming beam may graze past the target and land far behind it, outside the
    # workspace: it still tells which beam is which, so look for it among all groups. A group
    # some view resolved already holds the aiming beam's hit; the partner then only confirms.
    resolved = any(c.resolved for c in best.members)
    partner = _beam_partner(best, [g for g in groups if g is not best], s)
    rivals = [g for g in inside if g is not best]
    by_partner = False
    if partner is not None:
        group, is_aiming = partner
        rivals = [g for g in rivals if g is not group]
        by_partner = True
        if is_aiming and not resolved:
            if not any(g is group for g in inside):
                # The aiming beam, the one the user points with, is off in the distance.
                return Failure(KIND, "The laser dot is outside the area the arm can work in.")
            best = group
    if rivals and rivals[0].key[0] == best.key[0] and partner is None:
        return Failure(
            KIND,
            "The cameras disagree on where the laser dot is; hold the pointer still and try again.",
        )
    confirmed = by_partner or 2 * len(best.paired) >= len(best.voters)
    return LaserMark(
        point=best.point.astype(np.float64),
        state="confirmed" if confirmed else "aiming",
        views=len(best.voters),
    )


def direct_mark(
    point: Sequence[float] | np.ndarray, settings: PerceptionSettings | None = None
) -> LaserMark | Failure:
    """A mark given directly (touch screen, REST API, 3D view click): a point in `base` (m).

    Valid when it is three finite numbers inside the workspace box; then it is confirmed, with
    no views. Otherwise Failure("detect_laser", ...).
    """
    s = settings or get_settings().perception
    try:
        p = np.asarray(point, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        return Failure(KIND, "A marked point must be three numbers (x, y, z in metres).")
    if p.shape != (3,):
        return Failure(KIND, "A marked point must be three numbers (x, y, z in metres).")
    if not np.all(np.isfinite(p)):
        return Failure(KIND, "The marked point is not a finite position.")
    lo, hi = np.asarray(s.workspace_min), np.asarray(s.workspace_max)
    if not np.all((p >= lo) & (p <= hi)):
        return Failure(KIND, "The marked point is outside the area the arm can work in.")
    return LaserMark(point=p, state="confirmed", views=0, source="direct")
