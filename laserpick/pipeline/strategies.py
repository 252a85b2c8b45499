"""Raw grasp candidates on a perceived target, by one of three strategies (004 section 6.2;
000 section 4.4; 003 section IV):

- "gpd": GPD-style 6-DOF candidates on the target (`gpd.detect_grasps`), optionally with its
  unseen back filled in by symmetry, or with the hand tilted about its closing axis; only
  those whose fingers go where the cameras saw free space.
- "overhead": EL-E's single overhead grasp from the target's 2D occupancy.
- "vertical": a top-down grasp across the narrow side of the target's top, as Jeeves takes
  once its base has centred the object.

Frames: `base` (x forward, y left, z up), metres, radians.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from scipy.spatial import cKDTree

from laserpick.description.dims import ARM_MOUNT_POS, GRIPPER_HAND
from laserpick.pipeline.collision import mirrored_back
from laserpick.pipeline.free_space import fingers_seen_free
from laserpick.pipeline.gpd import detect_grasps
from laserpick.pipeline.overhead import overhead_grasp
from laserpick.pipeline.perceive import Perception
from laserpick.pipeline.surface import surface_height
from laserpick.settings import Settings
from laserpick.types import Failure, Grasp

Strategy = Literal["gpd", "overhead", "vertical"]
STRATEGIES: tuple[Strategy, ...] = ("gpd", "overhead", "vertical")
VERTICAL_BITE = 0.02  #: m the fingertips of a vertical grasp reach below the object's top
VERTICAL_FLOOR_GAP = 0.003  #: m they stay above the support surface
VERTICAL_CAP = 0.005  #: m below the top that a vertical grasp counts as the object's top face
VERTICAL_TOP_POINTS = 30  #: points needed to place a vertical grasp by its band or top face
#: Fewest other target points within a grid cell of a point that stands above the surface
#: for EL-E's grasp to count it as the object's: the table's speckle stands alone. Ours.
SPECKLE_NEIGHBOURS = 3


def vertical_grasp(
    target: np.ndarray, support: float | None, settings: Settings
) -> Grasp | Failure:
    """A top-down grasp on the target's top band, closing across its narrow side, the pads
    reaching 2 cm below the top but stopping 3 mm above the support surface at `support`
    (m). The hand is centred on the band's extent across, which must leave the open fingers
    side_clearance on each side, and along it on the middle of the object's top face.

    The band is the target's points within VERTICAL_BITE of its top, where the fingers go,
    when the cameras see enough of it; the top face, those within VERTICAL_CAP. The cameras
    look down on the object from the front and see its top whole; they see less of its sides
    and back, and the mean of all its points lies toward them (a mug's by 1.5 cm, enough for
    its far rim to meet the far finger).
    """
    top = float(target[:, 2].max())
    band = target[target[:, 2] > top - VERTICAL_BITE]
    band = band if len(band) >= VERTICAL_TOP_POINTS else target
    cap = target[target[:, 2] > top - VERTICAL_CAP]
    centre = (cap if len(cap) >= VERTICAL_TOP_POINTS else band).mean(axis=0)
    xy = band[:, :2] - centre[:2]
    _, vecs = np.linalg.eigh(np.cov(xy.T) if len(xy) > 2 else np.eye(2))
    closing = np.append(vecs[:, 0], 0.0)
    across = xy @ vecs[:, 0]
    # Robust extent: a few stray points (a shadow's edge, the table's rim) do not widen it.
    lo, hi = np.percentile(across, [0.5, 99.5])
    width = float(hi - lo)
    if width > GRIPPER_HAND.width_max - 2 * settings.grasp.side_clearance:
        return Failure("detect_grasp", "The object is wider than the gripper opens.")
    middle = centre + 0.5 * (lo + hi) * closing
    approach = np.array([0.0, 0.0, -1.0])
    pose = np.eye(4)
    pose[:3, 0] = np.cross(closing, approach)
    pose[:3, 1] = closing
    pose[:3, 2] = approach
    tips = top - VERTICAL_BITE
    if support is not None:
        tips = max(tips, support + VERTICAL_FLOOR_GAP)
    pose[:3, 3] = [middle[0], middle[1], tips + GRIPPER_HAND.pad_depth / 2]
    return Grasp(pose=pose, width=width)


def _above_surface(
    points: np.ndarray, target: np.ndarray, mark: np.ndarray, settings: Settings
) -> np.ndarray:
    """The `target` points (m, `base`) that stand above the surface at the `mark`: EL-E
    grasps what its segmentation left once the surface's points were gone (000 section
    4.2.2), so its overhead grasp takes the target's points over the top of the surface's
    height histogram in the VOI (`surface_height`), by one grid layer, as `segment`'s grid
    does, less the surface's speckle (under SPECKLE_NEIGHBOURS others within a grid cell).
    Without it, 004's 10 cm fallback ball about a pill holds thousands of table points, and
    the raised-point rule picks a stray one. The whole target where no surface is seen."""
    s = settings.perception
    z_top = surface_height(points, s, center=mark)
    if z_top is None:
        return target
    above = target[target[:, 2] > z_top + s.grid_surface_margin]
    if len(above) == 0:
        return above
    near = cKDTree(above).query_ball_point(above, s.grid_cell_xy, return_length=True)
    return above[near > SPECKLE_NEIGHBOURS]  # each point counts itself


def candidates(
    perception: Perception,
    strategy: Strategy,
    settings: Settings,
    rng: np.random.Generator,
    *,
    complete: bool = False,
    tilted: bool = False,
) -> list[Grasp] | Failure:
    """Raw grasp candidates on the perceived target. complete: for "gpd", add the target's
    back as `mirrored_back` guesses it (to the target and to the obstacles). tilted: for
    "gpd", the hand tilted about its closing axis by `gpd_tilts_deg` instead of untilted.
    GPD's are only those whose fingers go where the cameras saw free space
    (`fingers_seen_free`): its collision test knows only the seen surfaces."""
    cloud, seg = perception.cloud, perception.segmentation
    assert seg is not None
    target = cloud.points[seg.indices].astype(np.float64)
    if strategy == "gpd":
        normals, scene = cloud.normals[seg.indices], cloud.points
        guessed = None
        if complete:
            back, back_normals = mirrored_back(target, normals)
            guessed = np.r_[np.zeros(len(target), bool), np.ones(len(back), bool)]
            target, normals = np.vstack([target, back]), np.vstack([normals, back_normals])
            scene = np.vstack([scene, back])
        tilts = tuple(np.radians(settings.grasp.gpd_tilts_deg)) if tilted else (0.0,)
        found = detect_grasps(
            target, normals, scene, settings.grasp, rng=rng, tilts=tilts, guessed=guessed
        )
        seen = fingers_seen_free(found, perception.frames, settings.grasp)
        return [g for g, ok in zip(found, seen, strict=True) if ok]
    support = seg.surface.height if seg.surface is not None else None
    if strategy == "overhead":
        floor = support if support is not None else float(target[:, 2].min())
        assert perception.mark is not None  # segmented: there is a mark
        target = _above_surface(cloud.points, target, perception.mark.point, settings)
        if len(target) == 0:
            return Failure("detect_grasp", "Nothing stands above the surface at the mark.")
        g = overhead_grasp(target, cloud.points, floor, ARM_MOUNT_POS[:2])
    else:
        g = vertical_grasp(target, support, settings)
    return g if isinstance(g, Failure) else [g]
