"""The free-space test: a point is free where a camera saw past it. Depth images rendered
here by casting each pixel's ray at a box on a table, so where the box hides space is known
exactly."""

from __future__ import annotations

import numpy as np

from laserpick.pipeline.free_space import finger_probes, fingers_seen_free, seen_free
from laserpick.pipeline.types import DepthFrame, Grasp
from laserpick.settings import GraspSettings

TABLE = 0.46
BOX_CENTRE = np.array([1.5, 0.0, TABLE + 0.10])
BOX_HALF = np.array([0.03, 0.03, 0.10])  # a 6 x 6 x 20 cm box standing on the table
CAMERA = np.array([0.5, 0.0, 1.2])  # in front of it and above, as the scooter's are
S = GraspSettings()
TOL = S.free_space_tolerance


def _intrinsics(w: int = 160, h: int = 120, f: float = 140.0) -> np.ndarray:
    return np.array([[f, 0.0, w / 2], [0.0, f, h / 2], [0.0, 0.0, 1.0]])


def _looking_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """T_base_cam of a camera at `eye` whose optical axis (z) points at `target`, x right."""
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = eye
    return T


def _frame(box: bool = True) -> DepthFrame:
    """The box (if `box`) on the table seen from CAMERA: each pixel's depth along the optical
    axis to the nearest of the box and the table plane."""
    K, T = _intrinsics(), _looking_at(CAMERA, BOX_CENTRE)
    h, w = int(2 * K[1, 2]), int(2 * K[0, 2])
    v, u = np.mgrid[0:h, 0:w]
    rays_cam = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones((h, w))], -1)
    rays = rays_cam.reshape(-1, 3) @ T[:3, :3].T  # base; unit optical z component
    with np.errstate(divide="ignore", invalid="ignore"):
        t_table = np.where(rays[:, 2] < 0, (TABLE - CAMERA[2]) / rays[:, 2], np.inf)
        lo = (BOX_CENTRE - BOX_HALF - CAMERA) / rays
        hi = (BOX_CENTRE + BOX_HALF - CAMERA) / rays
    t_in = np.nanmax(np.minimum(lo, hi), axis=1)
    t_out = np.nanmin(np.maximum(lo, hi), axis=1)
    t_box = np.where(box & (t_in <= t_out) & (t_in > 0), t_in, np.inf)
    t = np.minimum(t_table, t_box)  # along a ray whose optical z is 1: t is the depth
    depth = np.where(np.isfinite(t), t, 0.0).reshape(h, w).astype(np.float32)
    return DepthFrame(depth, np.zeros((h, w), np.uint8), K, T, "front", 0.0)


def _side_grasp(closing: np.ndarray, approach: np.ndarray) -> Grasp:
    """A grasp at the box's middle, closing along `closing` across its 6 cm."""
    pose = np.eye(4)
    pose[:3, 0] = np.cross(closing, approach)
    pose[:3, 1], pose[:3, 2], pose[:3, 3] = closing, approach, BOX_CENTRE
    return Grasp(pose=pose, width=0.06)


def test_a_point_is_free_only_where_a_camera_saw_past_it():
    frame = _frame()
    in_front = BOX_CENTRE - [0.10, 0.0, 0.0]  # between the camera and the box
    behind = BOX_CENTRE + [0.10, 0.0, -0.05]  # in the box's shadow
    on_face = BOX_CENTRE - [BOX_HALF[0] + TOL / 2, 0.0, 0.0]  # within the tolerance of it
    beside = BOX_CENTRE + [0.0, 0.10, 0.0]  # the camera sees the table past it
    behind_camera = CAMERA - [0.5, 0.0, 0.0]
    free = seen_free(np.array([in_front, behind, on_face, beside, behind_camera]), [frame], TOL)
    assert free.tolist() == [True, False, False, True, False]
    # A pixel that read nothing says nothing: the point in front is no longer seen free.
    blank = DepthFrame(
        np.zeros_like(frame.depth), frame.ir, frame.K, frame.T_base_cam, "blank", 0.0
    )
    assert not seen_free(in_front[None], [blank], TOL).any()
    # A second camera that sees the shadowed point frees it.
    assert seen_free(behind[None], [frame, _frame(box=False)], TOL).all()


def test_a_finger_in_the_box_unseen_back_is_refused_one_beside_it_is_not():
    frame = _frame()
    down, along_x, along_y = np.array([0, 0, -1.0]), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    # From above, closing left-right: both fingers beside the box, where the camera sees
    # the table past them.
    across = _side_grasp(along_y, down)
    # From above, closing front-back: the far finger goes down behind the box, unseen.
    through = _side_grasp(along_x, down)
    assert fingers_seen_free([across, through], [frame], S).tolist() == [True, False]
    probes = finger_probes(through.pose[None], S)[0]
    far = probes[:, 0] > BOX_CENTRE[0]
    assert far.sum() == len(probes) // 2
    free = seen_free(probes, [frame], TOL)
    assert free[~far].all() and not free[far].any()
    # No frames, or the test turned off: nothing is refused.
    assert fingers_seen_free([through], [], S).all()
    off = S.model_copy(update={"free_space_share": 0.0})
    assert fingers_seen_free([through], [frame], off).all()
