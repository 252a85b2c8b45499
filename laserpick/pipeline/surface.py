"""Flat support surfaces around a mark, after EL-E (paper 000, sections 4.2.1, 4.3.2, 4.4.3, 4.5).

Everything works on the points in a volume of interest (VOI) around a mark: a square column
`2 * voi_half_width` on a side (40 cm, the cross-section 000 4.4.3 implies), from `voi_below`
under the mark to `voi_above` over it. Points are float32 (N, 3) in `base` (x forward, y left,
z up; metres), so z is parallel to gravity as EL-E's histogram needs.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from laserpick.settings import PerceptionSettings
from laserpick.types import Failure, FusedCloud

#: 8-connectivity in a 2D grid (000 4.3.2).
_EIGHT = np.ones((3, 3), bool)
#: A placed object's footprint: the level positions within this (m) of its points' own.
FOOTPRINT_PAD = 0.01
#: Points (m) within this of a surface's height are the surface, not what stands on it.
SURFACE_BAND = 0.015
#: An object still stands where it was set down when points within its footprint rise to
#: this fraction of its height above the surface: an upright object's top is what the
#: cameras see best; one lying on its side reaches about its girth (a pill bottle 8 cm tall,
#: 4 cm round, half its height).
STANDING_FRACTION = 0.6
#: Fewest points that count as seeing something there: a top, or the bare surface.
SEEN_POINTS = 10
#: Fewer points than this above a surface are stray ones: it is bare.
STRAY_POINTS = 3


def on_floor(height: float) -> bool:
    """Whether a surface top at `height` (m, `base`) is the floor (z = 0), within
    SURFACE_BAND: nothing falls from it, and it is the support under what stands on it."""
    return height < SURFACE_BAND


def voi_mask(points: np.ndarray, center: np.ndarray, settings: PerceptionSettings) -> np.ndarray:
    """Boolean mask of the points inside the volume of interest around `center` (m, `base`)."""
    c = np.asarray(center, np.float32)
    d = points - c
    h = settings.voi_half_width
    return (
        (np.abs(d[:, 0]) <= h)
        & (np.abs(d[:, 1]) <= h)
        & (d[:, 2] >= -settings.voi_below)
        & (d[:, 2] <= settings.voi_above)
    )


def surface_height(
    points: np.ndarray, settings: PerceptionSettings, center: np.ndarray | None = None
) -> float | None:
    """Height z_top (m, `base`) of the top of the flat surface among `points`; 000 4.2.1.

    The z values go into bins of `histogram_bin` (2.5 mm). The fullest bin (n_max points) is
    taken to lie in the surface; from it the search climbs bin by bin to the first one holding
    fewer than `histogram_cut` * n_max points (n_max / 5). That bin's lower edge is z_top, the
    highest z still classed as surface: the top end of the surface's peak, not its middle, so
    it sits about 1.8 sigma of the depth noise above the true top.

    With `center`, only the points in the VOI around it count (see `voi_mask`); otherwise the
    caller has already chosen the points. None when there are no points.
    """
    if center is not None:
        points = points[voi_mask(points, center, settings)]
    if len(points) == 0:
        return None
    b = settings.histogram_bin
    # Bin i covers [z_i - b/2, z_i + b/2) with z_i = i * b, as in the paper.
    idx = np.floor(points[:, 2].astype(np.float64) / b + 0.5).astype(np.int64)
    lo = int(idx.min())
    counts = np.bincount(idx - lo)
    i_max = int(np.argmax(counts))
    cut = settings.histogram_cut * counts[i_max]
    above = np.nonzero(counts[i_max:] < cut)[0]
    # No sparse bin above the peak: the surface reaches the top of the VOI.
    i_top = i_max + (int(above[0]) if len(above) else len(counts) - i_max)
    return float((i_top + lo) * b - b / 2)


def _grid_cells(xy: np.ndarray, origin: np.ndarray, cell: float) -> np.ndarray:
    """Integer 2D cell of each xy (m) in a grid with corner `origin` and square `cell` (m)."""
    return np.floor((xy - origin) / cell).astype(np.int64)


def _occupancy(xy: np.ndarray, origin: np.ndarray, cell: float, shape: tuple[int, int]):
    """2D occupancy grid (bool) of the xy points in the grid, and each point's cell."""
    ij = _grid_cells(xy, origin, cell)
    ok = np.all((ij >= 0) & (ij < np.array(shape)), axis=1)
    grid = np.zeros(shape, bool)
    grid[ij[ok, 0], ij[ok, 1]] = True
    return grid, ij, ok


def _voi_grid(center: np.ndarray, settings: PerceptionSettings) -> tuple[np.ndarray, int]:
    """Corner (m) and cells per side of the 2D grid over the VOI's cross-section."""
    h = settings.voi_half_width
    n = round(2 * h / settings.grid_cell_xy)
    return np.asarray(center[:2], np.float64) - h, n


def is_flat_surface(
    points: np.ndarray,
    mark_point: np.ndarray,
    settings: PerceptionSettings,
    mark_on_surface: bool = True,
) -> bool:
    """Whether the mark (m, `base`) lies on a flat, roughly horizontal surface; 000 4.4.3.

    EL-E's test: find z_top in the VOI around the mark, project the VOI points with z in
    [z_top - 0.1, z_top + 0.1] onto a 2D grid of `grid_cell_xy` (1 cm) cells covering the VOI's
    cross-section, and call it flat when more than `flat_fraction` (1/4) of the cells are
    occupied. A mark in the air sees an empty VOI; a mark on a wall sees few cells.

    EL-E uses it as a grasp precondition, where a mark on a cup on a table passes, since the
    VOI holds the table. With `mark_on_surface` (the default, for placing) the mark must also
    lie on that surface: within `mark_on_surface_tol` of z_top, which rules out a mark on an
    object's side.
    """
    mark = np.asarray(mark_point, np.float64)
    pts = points[voi_mask(points, mark, settings)]
    z_top = surface_height(pts, settings)
    if z_top is None:
        return False
    if mark_on_surface and abs(mark[2] - z_top) > settings.mark_on_surface_tol:
        return False
    band = np.abs(pts[:, 2] - z_top) <= settings.flat_band
    origin, n = _voi_grid(mark, settings)
    grid, _, _ = _occupancy(pts[band, :2], origin, settings.grid_cell_xy, (n, n))
    return bool(grid.sum() > settings.flat_fraction * grid.size)


def surface_region(
    points: np.ndarray, mark_point: np.ndarray, z_top: float, settings: PerceptionSettings
) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The surface's footprint around the mark, after 000 4.3.2.

    Points with z in [z_top - `surface_band`, z_top] (all of them, not only the VOI's, so the
    surface's far edges are seen) go onto a 2D grid of `grid_cell_xy` cells, a square 1 m
    around the mark; the 8-connected component holding the mark's cell is the surface. EL-E
    takes the largest component; the one under the mark is what a place needs.

    Returns (component mask (n, n) bool, grid corner xy (m), cell (m)), or None when the mark's
    cell is not on the surface.
    """
    cell = settings.grid_cell_xy
    half = 0.5  # m: a place reaches at most this far from the mark for its edge
    mark = np.asarray(mark_point, np.float64)
    band = (points[:, 2] >= z_top - settings.surface_band) & (points[:, 2] <= z_top)
    near = band & np.all(np.abs(points[:, :2] - mark[:2]) <= half, axis=1)
    origin = mark[:2] - half
    n = round(2 * half / cell)
    grid, _, _ = _occupancy(points[near, :2], origin, cell, (n, n))
    # One cell of closing fills the odd empty cell that noise or a shadow leaves.
    # (Padded with copies of the border so the grid's edges are not eroded away.)
    grid = ndimage.binary_closing(np.pad(grid, 1, mode="edge"), _EIGHT)[1:-1, 1:-1]
    labels, _ = ndimage.label(grid, structure=_EIGHT)
    i, j = _grid_cells(mark[None, :2], origin, cell)[0]
    lab = labels[i, j]
    if lab == 0:
        return None
    return labels == lab, origin, cell


def front_edge_x(region: np.ndarray, origin: np.ndarray, cell: float, y: float) -> float | None:
    """x (m, `base`) of the surface's front edge (the side facing the robot) at lateral y.

    The robot sits at smaller x than the surface, so the front edge along the line through y
    lies in the front-most cell of the region in y's column of cells. We return that cell's
    back border: the true edge is at or in front of it, so a place moved back from it is never
    closer to the edge than asked (at most one cell, 1 cm, farther). None if the column is
    empty.
    """
    j = int(np.floor((y - origin[1]) / cell))
    if not 0 <= j < region.shape[1]:
        return None
    rows = np.nonzero(region[:, j])[0]
    if len(rows) == 0:
        return None
    return float(origin[0] + (rows.min() + 1) * cell)


def place_target(
    cloud: FusedCloud, mark_point: np.ndarray, settings: PerceptionSettings
) -> np.ndarray | Failure:
    """Where to set an object down for a place mark (m, `base`); 000 4.5.

    The mark must be on a flat surface (`is_flat_surface`). If it lies less than
    `place_edge_margin` (10 cm) behind the surface's front edge, the edge nearest the robot,
    it moves straight back (+x) until it is 10 cm behind that edge. Not on the floor
    (`on_floor`): nothing falls from it, and its nearest seen boundary is only where the
    cameras' view begins, not an edge to keep clear of. Returns the (3,) point on the
    surface at height z_top, or a Failure.
    """
    mark = np.asarray(mark_point, np.float64)
    pts = cloud.points
    if not is_flat_surface(pts, mark, settings):
        return Failure("precondition", "that spot is not on a flat surface")
    z_top = surface_height(pts, settings, center=mark)
    assert z_top is not None  # is_flat_surface found it
    found = surface_region(pts, mark, z_top, settings)
    if found is None:
        return Failure("precondition", "that spot is not on a flat surface")
    region, origin, cell = found
    x, y = float(mark[0]), float(mark[1])
    edge = front_edge_x(region, origin, cell, y)
    if edge is not None and not on_floor(z_top) and x - edge < settings.place_edge_margin:
        x = edge + settings.place_edge_margin
    return np.array([x, y, z_top], np.float32)


def still_standing(points: np.ndarray, standing: np.ndarray, surface_z: float) -> bool | None:
    """The place's post-condition (EL-E 000 section 6: a behaviour that knows whether it
    succeeded): whether an object set down still stands where it was let go, by what the
    cameras see once the arm has gone.

    points: the cloud now (m, `base`), the arm's own points left out; standing: the object
    as it was let go (its carried shape, m, `base`); surface_z: the height (m) of the
    surface it was set on. Within its footprint (its level extent, FOOTPRINT_PAD wider):
    True when SEEN_POINTS or more rise to STANDING_FRACTION of its height above the
    surface; False when the cameras see the surface bare there, SEEN_POINTS or more of it
    and fewer than STRAY_POINTS above it (the object is gone: it fell off the spot, or the
    hand took it along); None otherwise, nothing known. Something lower than expected but
    still there is None, not False: an object let go tilted settles flat on its mark, lower
    than it was held.
    """
    height = float(standing[:, 2].max()) - surface_z
    if len(points) == 0 or height <= SURFACE_BAND:
        return None
    d, _ = cKDTree(standing[:, :2]).query(points[:, :2], distance_upper_bound=FOOTPRINT_PAD)
    above = points[np.isfinite(d), 2] - surface_z
    if np.count_nonzero(above >= STANDING_FRACTION * height) >= SEEN_POINTS:
        return True
    on_it = np.count_nonzero(above >= SURFACE_BAND)
    if on_it < STRAY_POINTS and np.count_nonzero(np.abs(above) < SURFACE_BAND) >= SEEN_POINTS:
        return False
    return None
