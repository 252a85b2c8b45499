"""The dynamic spatial augmented reality highlight (paper 004, section 4).

The projector is modelled as a pinhole camera with the projector's intrinsics and pose: the
target's points are projected into that virtual camera, and the image is white (255) where
they land and black elsewhere. Sent to the projector, the white pixels light the target.

Frames: `T_base_proj` is the projector's optical frame in `base`, OpenCV convention (x right,
y down, z out of the lens), and K uses pixel centres at integer coordinates, like
`DepthFrame.K`.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from laserpick.types import Projector

#: Bounds (px) on the splat radius chosen from the projected point spacing.
MIN_RADIUS_PX, MAX_RADIUS_PX = 1, 8


def projector_intrinsics(
    w: int, h: int, W: float, H: float, X: float, Y: float, Z: float
) -> np.ndarray:
    """K (3x3, px) of a projector from 004's wall calibration (section 4).

    The projector, facing a wall square on at distance Z, shows a w x h image:
      w, h: the image's width and height in pixels;
      W, H: the width and height (m) of the projected image measured on the wall;
      X, Y: the distances (m) on the wall from the principal point (where the optical axis
        meets the wall) to the image's top-left corner, along its width and height;
      Z: the distance (m) from the projector to the wall.
    Then fx = fy = w Z / W, and the principal point is (w X / W, h Y / H) measured from the
    image's top-left corner. The corner is at (-0.5, -0.5) in the OpenCV convention this
    codebase uses (pixel centres at integers), so K's cx, cy are those values minus 0.5.
    """
    f = w * Z / W
    cx = w * X / W - 0.5
    cy = h * Y / H - 0.5
    return np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])


def _splat_radius(pixels: np.ndarray) -> int:
    """A disc radius (px) that closes the gaps between projected points: the 90th percentile
    of each pixel's distance to its nearest other pixel, within [MIN_RADIUS_PX, MAX_RADIUS_PX].
    """
    if len(pixels) < 2:
        return MIN_RADIUS_PX
    d, _ = cKDTree(pixels).query(pixels, k=2)
    r = int(np.ceil(np.percentile(d[:, 1], 90)))
    return int(np.clip(r, MIN_RADIUS_PX, MAX_RADIUS_PX))


def _disc(radius: int) -> np.ndarray:
    r = np.arange(-radius, radius + 1)
    return (r[:, None] ** 2 + r[None, :] ** 2) <= radius * radius


def highlight_points(
    projector: Projector, points_base: np.ndarray, radius_px: int | None = None
) -> np.ndarray:
    """The projector image (height, width) uint8 lighting `points_base` (N, 3) m.

    Each point in front of the projector that lands in the image is drawn as a disc of
    `radius_px` pixels (default: from the projected points' spacing, so the lit region is
    solid rather than a sieve); everything else is black (0).
    """
    img = np.zeros((projector.height, projector.width), np.uint8)
    uv, front = projector.project(points_base)
    px = np.round(uv[front]).astype(np.int64)
    inside = (
        (px[:, 0] >= 0)
        & (px[:, 0] < projector.width)
        & (px[:, 1] >= 0)
        & (px[:, 1] < projector.height)
    )
    px = np.unique(px[inside], axis=0)
    if len(px) == 0:
        return img
    r = _splat_radius(px) if radius_px is None else int(radius_px)
    # Dilate only the bounding box of the points (plus the radius): a few thousand pixels
    # instead of the whole million.
    u0, v0 = np.maximum(px.min(axis=0) - r, 0)
    u1 = min(int(px[:, 0].max()) + r + 1, projector.width)
    v1 = min(int(px[:, 1].max()) + r + 1, projector.height)
    box = np.zeros((v1 - v0, u1 - u0), bool)
    box[px[:, 1] - v0, px[:, 0] - u0] = True
    if r > 0:
        box = ndimage.binary_dilation(box, structure=_disc(r))
    img[v0:v1, u0:u1] = box.view(np.uint8) * np.uint8(255)
    return img


def _fill_polygon(img: np.ndarray, poly: np.ndarray) -> None:
    """Set the pixels of `img` whose centres lie inside the convex polygon `poly` (n, 2)
    (u, v px, in order around it) to 255, in place."""
    H, W = img.shape
    u0, v0 = np.maximum(np.floor(poly.min(axis=0)).astype(int), 0)
    u1 = min(int(np.ceil(poly[:, 0].max())) + 1, W)
    v1 = min(int(np.ceil(poly[:, 1].max())) + 1, H)
    if u0 >= u1 or v0 >= v1:
        return
    uu, vv = np.meshgrid(np.arange(u0, u1), np.arange(v0, v1))
    a, b = poly, np.roll(poly, -1, axis=0)
    # Inside a convex polygon: on the same side of every edge.
    cross = (b[:, 0, None, None] - a[:, 0, None, None]) * (vv - a[:, 1, None, None]) - (
        b[:, 1, None, None] - a[:, 1, None, None]
    ) * (uu - a[:, 0, None, None])
    inside = np.all(cross >= 0, axis=0) | np.all(cross <= 0, axis=0)
    img[v0:v1, u0:u1][inside] = 255


def highlight_disc(
    projector: Projector,
    center_base: np.ndarray,
    normal_base: np.ndarray = (0.0, 0.0, 1.0),
    radius: float = 0.04,
    sides: int = 48,
) -> np.ndarray:
    """The projector image (height, width) uint8 lighting a disc of `radius` (m) about
    `center_base` (m) on the plane with normal `normal_base`, e.g. where an object will be
    placed. The disc's rim is sampled at `sides` points and the projected polygon filled
    (a disc seen through a pinhole is an ellipse, so convex). Black if any rim point lies
    behind the projector.
    """
    img = np.zeros((projector.height, projector.width), np.uint8)
    c = np.asarray(center_base, dtype=float).reshape(3)
    n = np.asarray(normal_base, dtype=float).reshape(3)
    n /= np.linalg.norm(n)
    # Two unit vectors spanning the disc's plane.
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    ang = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    rim = c + radius * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2)
    uv, front = projector.project(rim)
    if not front.all():
        return img
    _fill_polygon(img, uv)
    return img
