"""Support surfaces (pipeline/surface.py): EL-E's height histogram on its twelve surfaces, the
flat-surface precondition and the place target. Run with -s to see the figures."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.surface import (
    is_flat_surface,
    place_target,
    still_standing,
    surface_height,
)
from laserpick.robot.sim.truth import capture
from laserpick.settings import PerceptionSettings
from laserpick.types import Failure, FusedCloud

SETTINGS = PerceptionSettings()
BEHIND_EDGE = 0.25  # m: where on each surface the height is asked for
FRONT_EDGE_X = 1.30  # m, world: every surface's front edge in the `surfaces` scene


def _true_height(surface) -> float:
    return 0.0 if surface.kind == "floor" else float(surface.height)


@pytest.fixture(scope="module")
def surfaces():
    """Per surface: (surface, cloud in `base`, scooter y in world). The scooter is teleported
    to face each surface in turn, 15 cm to the left of its centre as in the scene's start."""
    cap = capture("surfaces")
    sim = cap.robot.sim
    out = []
    for surf in cap.scene.surfaces:
        y0 = float(surf.xy[1]) + 0.15
        sim.data.qpos[sim.info.base_qpos] = [0.0, y0, 0.0]
        sim.settle(0.2)
        out.append((surf, fuse(cap.robot.capture(), SETTINGS), y0))
    yield out
    cap.close()


def _mark_on(cloud: FusedCloud, xy_base: np.ndarray, z: float) -> np.ndarray:
    """The laser's point: the cloud point nearest the surface point (x, y, z) in `base`."""
    target = np.array([*xy_base, z], np.float32)
    return cloud.points[np.argmin(np.linalg.norm(cloud.points - target, axis=1))]


def test_surface_heights_of_eles_twelve_surfaces(surfaces):
    errors = {}
    for surf, cloud, y0 in surfaces:
        truth = _true_height(surf)
        xy = np.array([FRONT_EDGE_X + BEHIND_EDGE, surf.xy[1] - y0])
        mark = _mark_on(cloud, xy, truth)
        h = surface_height(cloud.points, SETTINGS, center=mark)
        assert h is not None, surf.name
        errors[surf.name] = h - truth
    mm = {k: round(1000 * v, 1) for k, v in errors.items()}
    mean = 1000 * np.mean(np.abs(list(errors.values())))
    print(f"\nsurface height error (mm): {mm}; mean |error| {mean:.1f} mm (EL-E: 7.1 mm)")
    assert max(abs(v) for v in errors.values()) < 0.005, mm


def test_surface_height_histogram_rule():
    """A synthetic table: the peak bin holds n_max, and z_top is the lower edge of the first
    bin above it with fewer than n_max / 5 points, whatever lies higher up."""
    rng = np.random.default_rng(0)
    table = np.column_stack([rng.uniform(0, 0.4, (2, 4000)).T, rng.normal(0.7, 0.001, 4000)])
    cup = np.column_stack([rng.uniform(0.1, 0.15, (2, 600)).T, rng.uniform(0.7, 0.8, 600)])
    h = surface_height(np.concatenate([table, cup]).astype(np.float32), SETTINGS)
    assert h is not None and 0.700 < h < 0.705
    assert surface_height(np.zeros((0, 3), np.float32), SETTINGS) is None


def test_flat_surface(surfaces):
    surf, cloud, y0 = next(s for s in surfaces if s[0].name == "s05")  # a 73 cm table
    table = _mark_on(cloud, np.array([1.6, surf.xy[1] - y0]), surf.height)
    assert is_flat_surface(cloud.points, table, SETTINGS)
    # In the air, 40 cm above the table.
    air = table + np.array([0, 0, 0.4], np.float32)
    assert not is_flat_surface(cloud.points, air, SETTINGS)
    # On the phone's side, 1.5 cm above the table: EL-E's grasp check passes it (the VOI holds
    # the table), the place check does not (the mark is not on the surface).
    side = table.copy()
    side[2] = surf.height + 0.015
    assert not is_flat_surface(cloud.points, side, SETTINGS)
    assert is_flat_surface(cloud.points, side, SETTINGS, mark_on_surface=False)


def test_place_moves_back_from_the_front_edge(surfaces):
    for name in ("s03", "s09", "s11"):
        surf, cloud, y0 = next(s for s in surfaces if s[0].name == name)
        y = surf.xy[1] - y0 + 0.2  # clear of the phone and the pill
        mark = _mark_on(cloud, np.array([FRONT_EDGE_X + 0.03, y]), surf.height)
        place = place_target(cloud, mark, SETTINGS)
        assert not isinstance(place, Failure), f"{name}: {place}"
        behind = place[0] - FRONT_EDGE_X
        print(f"\n{name}: mark {mark[0] - FRONT_EDGE_X:.3f} m behind the edge -> {behind:.3f} m")
        # (1 mm: float32 rounding of the grid where a cell border meets the true edge.)
        assert SETTINGS.place_edge_margin - 0.001 <= behind <= SETTINGS.place_edge_margin + 0.015
        assert abs(place[1] - mark[1]) < 1e-6
        assert abs(place[2] - surf.height) < 0.005
        # A mark already well behind the edge stays where it is.
        far = _mark_on(cloud, np.array([FRONT_EDGE_X + 0.2, y]), surf.height)
        kept = place_target(cloud, far, SETTINGS)
        assert not isinstance(kept, Failure)
        assert np.allclose(kept[:2], far[:2])


def test_a_mark_on_the_floor_is_not_moved_back(surfaces):
    """The floor has no edge to fall from: its nearest seen boundary is where the cameras'
    view begins. A mark 3 cm past that stays where it is, not moved back 10 cm from it."""
    surf, cloud, y0 = next(s for s in surfaces if s[0].kind == "floor")
    y = float(surf.xy[1]) - y0
    pts = cloud.points
    floor = pts[(np.abs(pts[:, 2]) < 0.01) & (np.abs(pts[:, 1] - y) < 0.05)]
    mark = _mark_on(cloud, np.array([float(floor[:, 0].min()) + 0.03, y]), 0.0)
    place = place_target(cloud, mark, SETTINGS)
    assert not isinstance(place, Failure), place
    assert np.allclose(place[:2], mark[:2])


def test_place_off_a_surface_fails(surfaces):
    surf, cloud, y0 = next(s for s in surfaces if s[0].name == "s09")
    mark = _mark_on(cloud, np.array([1.6, surf.xy[1] - y0]), surf.height)
    air = mark + np.array([0, 0, 0.3], np.float32)
    got = place_target(cloud, air, SETTINGS)
    assert isinstance(got, Failure) and got.kind == "precondition"
    assert got.message == "that spot is not on a flat surface"


def test_still_standing_says_so_only_from_what_it_sees():
    """A 12 cm can set down on a 73 cm table: its seen front and top standing there (True);
    rolled off the spot, or the table bare there (False); lying on the spot, 6.6 cm high
    (None: something is there, lower than expected); nothing seen at the spot, or only a
    few stray points (None)."""
    top, r, h = 0.73, 0.033, 0.12
    ring = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    zs = np.arange(0.0, h + 1e-9, 0.01)
    can = np.vstack([np.c_[r * np.cos(ring), r * np.sin(ring), np.full(24, z)] for z in zs])
    standing = can + [1.5, -0.3, top]
    xs, ys = np.meshgrid(np.arange(1.3, 1.7, 0.005), np.arange(-0.5, -0.1, 0.005))
    table = np.c_[xs.ravel(), ys.ravel(), np.full(xs.size, top)]
    bare = table[np.hypot(table[:, 0] - 1.5, table[:, 1] + 0.3) > r]  # hidden under it
    front = standing[standing[:, 0] <= 1.5]  # what cameras in front see of it
    assert still_standing(np.vstack([bare, front]), standing, top) is True
    lying = np.c_[can[:, 2] - h / 2, can[:, 1], can[:, 0] + r] + [1.5, -0.3, top]
    under = (np.abs(table[:, 0] - 1.5) <= h / 2) & (np.abs(table[:, 1] + 0.3) <= r)
    assert still_standing(np.vstack([table[~under], lying]), standing, top) is None
    rolled = lying + [0.0, -0.12, 0.0]  # off the spot
    under = (np.abs(table[:, 0] - 1.5) <= h / 2) & (np.abs(table[:, 1] + 0.42) <= r)
    assert still_standing(np.vstack([table[~under], rolled]), standing, top) is False
    assert still_standing(table, standing, top) is False
    assert still_standing(np.zeros((0, 3)), standing, top) is None
    far = table[np.hypot(table[:, 0] - 1.5, table[:, 1] + 0.3) > 0.1]
    assert still_standing(far, standing, top) is None
    assert still_standing(np.vstack([far, front[:5]]), standing, top) is None
