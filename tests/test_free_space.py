"""The free-space test: a point is free where a camera saw past it; and what a camera's view
cut off an object is carried on past its edge. Depth images rendered here by casting each
pixel's ray at a box on a table, so where the box hides space is known exactly."""

from __future__ import annotations

import numpy as np

from laserpick.description import dims
from laserpick.pipeline.collision import carried_shape
from laserpick.pipeline.free_space import (
    AT_ONCE_MAX,
    CAPTURE_FRAMES,
    OBJECT_SPAN_MAX,
    beyond_view,
    finger_probes,
    fingers_seen_free,
    hidden,
    seen_free,
)
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.perceive import Perception
from laserpick.settings import GraspSettings
from laserpick.types import (
    DepthFrame,
    FusedCloud,
    Grasp,
    LaserMark,
    Segmentation,
    SupportSurface,
)

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


def _frame(
    box: bool = True,
    centre: np.ndarray = BOX_CENTRE,
    half: np.ndarray = BOX_HALF,
    look_at: np.ndarray | None = None,
    f: float = 140.0,
    eye: np.ndarray = CAMERA,
) -> DepthFrame:
    """The box (if `box`; `centre`, `half` its extent, m) on the table seen from `eye`,
    looking at `look_at` (default: the box) with focal length `f` (px): each pixel's depth
    along the optical axis to the nearest of the box and the table plane."""
    K = _intrinsics(f=f)
    T = _looking_at(eye, centre if look_at is None else look_at)
    h, w = int(2 * K[1, 2]), int(2 * K[0, 2])
    v, u = np.mgrid[0:h, 0:w]
    rays_cam = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones((h, w))], -1)
    rays = rays_cam.reshape(-1, 3) @ T[:3, :3].T  # base; unit optical z component
    with np.errstate(divide="ignore", invalid="ignore"):
        t_table = np.where(rays[:, 2] < 0, (TABLE - eye[2]) / rays[:, 2], np.inf)
        lo = (centre - half - eye) / rays
        hi = (centre + half - eye) / rays
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


def test_several_frames_free_a_point_where_any_one_of_them_does():
    """Asked of several frames at once, with a tolerance per point, a point is free exactly
    where one of the frames, asked alone, sees past it."""
    frames = [_frame(), _frame(box=False), _frame(look_at=BOX_CENTRE + [0.0, 0.3, 0.0])]
    rng = np.random.default_rng(0)
    points = BOX_CENTRE + rng.uniform(-0.4, 0.4, (2000, 3))
    tol = rng.uniform(0.0, 0.03, len(points))
    alone = np.array([seen_free(points, [f], tol) for f in frames])
    assert alone.any(axis=0).sum() > alone[0].sum() > 0  # the later frames free some more
    assert (seen_free(points, frames, tol) == alone.any(axis=0)).all()
    assert not seen_free(points, [], tol).any()


def test_many_frames_asked_at_once_free_what_each_alone_frees():
    """The capture's frames are asked first (`CAPTURE_FRAMES`), then the rest about the points
    left; each group at once where the points are few, else frame by frame until they are
    (`AT_ONCE_MAX`): a point is free exactly where one frame, asked alone, sees past it,
    however many points are asked and whichever way they are."""
    # The first frames from the front, the rest from either side, which see into the box's
    # shadow as the first do not.
    eyes = [CAMERA + [dx, 0.0, 0.0] for dx in (0.0, -0.05, -0.1, -0.15, -0.2)]
    eyes += [CAMERA + [dx, dy, 0.0] for dx in (0.3, 0.6) for dy in (-0.6, 0.6)]
    frames = [_frame(eye=eye, look_at=BOX_CENTRE + [0.0, 0.0, -0.1]) for eye in eyes]
    assert len(frames) > CAPTURE_FRAMES
    rng = np.random.default_rng(1)
    around = ([-0.2, -0.2, -0.09], [0.2, 0.2, 0.15])
    behind = ([0.04, -0.03, -0.09], [0.2, 0.03, 0.09])  # in the shadow of the front frames
    # 50 points, each group asked at once; AT_ONCE_MAX points, one frame after another until
    # few are left, then the frames after that at once.
    assert 50 * len(frames) <= AT_ONCE_MAX
    for n, (lo, hi) in ((50, around), (AT_ONCE_MAX, behind)):
        points = BOX_CENTRE + rng.uniform(lo, hi, (n, 3))
        tol = rng.uniform(0.0, 0.03, n)
        alone = np.array([seen_free(points, [f], tol) for f in frames])
        first, rest = alone[:CAPTURE_FRAMES].any(axis=0), alone[CAPTURE_FRAMES:].any(axis=0)
        assert (rest & ~first).any()  # the frames asked after the capture's free some points
        assert (seen_free(points, frames, tol) == alone.any(axis=0)).all()


def test_a_finger_in_the_box_unseen_back_is_refused_one_beside_it_is_not():
    frame = _frame()
    down, along_x, along_y = np.array([0, 0, -1.0]), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    # From above, closing left-right: both fingers beside the box, where the camera sees
    # the table past them.
    across = _side_grasp(along_y, down)
    # From above, closing front-back: the far finger goes down behind the box, unseen.
    through = _side_grasp(along_x, down)
    assert fingers_seen_free([across, through], [frame], S).tolist() == [True, False]
    probes = finger_probes(through.pose[None])[0]
    far = probes[:, 0] > BOX_CENTRE[0]
    assert far.sum() == len(probes) // 2
    free = seen_free(probes, [frame], TOL)
    assert free[~far].all() and not free[far].any()
    # No frames, or the test turned off: nothing is refused.
    assert fingers_seen_free([through], [], S).all()
    off = S.model_copy(update={"free_space_share": 0.0})
    assert fingers_seen_free([through], [frame], off).all()


BAR_CENTRE = np.array([1.5, 0.0, TABLE + 0.03])
BAR_HALF = np.array([0.03, 0.10, 0.03])  # a 6 x 20 x 6 cm bar lying across the view
UP, FRONT = np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0])


def _seen_surface(frame: DepthFrame, centre: np.ndarray, half: np.ndarray) -> np.ndarray:
    """What `frame` saw of the box at `centre` (`half` its extent, m): points on its top and
    front faces, 5 mm apart, that project into the image and that no nearer reading hides."""
    x, y, z = (np.arange(-h, h + 1e-9, 0.005) for h in half)
    top = np.stack(np.meshgrid(x, y, [half[2]]), -1).reshape(-1, 3)
    front = np.stack(np.meshgrid([-half[0]], y, z), -1).reshape(-1, 3)
    faces = centre + np.vstack([top, front])
    return faces[~hidden(faces, [frame], TOL)]


def test_an_object_cut_off_by_the_view_is_carried_on_beyond_its_edge():
    # The narrow camera looks 15 cm to the bar's left: its right edge cuts the bar's right
    # end (-y) off, as the high camera's upper edge cut a lying juice bottle's.
    cut = _frame(centre=BAR_CENTRE, half=BAR_HALF, look_at=BAR_CENTRE + [0, 0.15, -0.03], f=500)
    seen = _seen_surface(cut, BAR_CENTRE, BAR_HALF)
    far_end = BAR_CENTRE[1] - BAR_HALF[1]
    assert seen[:, 1].min() > far_end + 0.03  # the camera saw no more than 17 of its 20 cm
    more = beyond_view(seen, [cut], 0.02, TOL)
    assert len(more)
    # It goes on the way the view cut it off, to the longest object carried...
    assert more[:, 1].max() < seen[:, 1].min() + 0.005
    reach = seen[:, 1].max() - more[:, 1].min()
    assert OBJECT_SPAN_MAX <= reach < OBJECT_SPAN_MAX + 0.02  # to within the 2 cm step
    # ...only where no camera saw past...
    assert not seen_free(more, [cut], TOL).any()
    # ...and at the height the bar was seen at its cut.
    assert more[:, 2].min() > BAR_CENTRE[2] - BAR_HALF[2] - 0.01
    assert more[:, 2].max() < BAR_CENTRE[2] + BAR_HALF[2] + 0.01
    # The carried shape then spans the bar's whole length, where from what was seen alone
    # it spans that.
    assert carried_shape(np.vstack([seen, more]), TABLE)[:, 1].min() < far_end
    assert carried_shape(seen, TABLE)[:, 1].min() > far_end + 0.02
    # A view from elsewhere that saw the table past the bar's end ends it there.
    whole = _frame(centre=BAR_CENTRE, half=BAR_HALF)
    ended = beyond_view(seen, [cut], 0.02, TOL, TABLE, others=[whole])
    assert far_end - 0.02 < ended[:, 1].min() < far_end + 0.02


def test_an_object_seen_whole_is_not_carried_on():
    whole = _frame(centre=BAR_CENTRE, half=BAR_HALF)
    seen = _seen_surface(whole, BAR_CENTRE, BAR_HALF)
    assert seen[:, 1].min() < BAR_CENTRE[1] - BAR_HALF[1] + 0.005
    assert len(beyond_view(seen, [whole], 0.02, TOL)) == 0
    # Cut off in one camera's view, but seen whole in another's: not cut off.
    cut = _frame(centre=BAR_CENTRE, half=BAR_HALF, look_at=BAR_CENTRE + [0, 0.15, -0.03], f=500)
    assert len(beyond_view(seen, [cut, whole], 0.02, TOL)) == 0


def test_find_grasps_carries_a_target_the_view_cut_off_on_past_its_edge():
    cut = _frame(centre=BAR_CENTRE, half=BAR_HALF, look_at=BAR_CENTRE + [0, 0.15, -0.03], f=500)
    bar = _seen_surface(cut, BAR_CENTRE, BAR_HALF)
    bar_normals = np.where((bar[:, 2] > BAR_CENTRE[2] + BAR_HALF[2] - 1e-9)[:, None], UP, FRONT)
    x, y = np.meshgrid(np.arange(1.2, 1.8, 0.006), np.arange(-0.3, 0.3, 0.006))
    table = np.c_[x.ravel(), y.ravel(), np.full(x.size, TABLE)]
    table = table[~hidden(table, [cut], TOL)]
    n = len(bar) + len(table)
    cloud = FusedCloud(
        np.vstack([bar, table]).astype(np.float32),
        np.vstack([bar_normals, np.tile(UP, (len(table), 1))]).astype(np.float32),
        np.zeros(n, np.uint8),
        np.arange(n, dtype=np.int32),
        ("front",),
    )
    surface = SupportSurface(TABLE, np.array([0.0, 0.0, 1.0, -TABLE]))
    seg = Segmentation(np.arange(len(bar)), "cluster", surface)
    mark = LaserMark(bar[np.argmax(bar[:, 2])], "confirmed", 0, "direct")
    far_end = BAR_CENTRE[1] - BAR_HALF[1]
    found = find_grasps(Perception(cloud, mark, seg, None, frames=(cut,)), dims.UR5_READY_Q)
    assert isinstance(found, GraspSet), found
    assert found.cut_off[:, 1].min() < far_end
    assert found.cut_off[:, 2].min() > TABLE  # none on the table it stands on
    assert found.carried[:, 1].min() < far_end
    # Without the frames it was seen in, nothing says the view cut it off.
    alone = find_grasps(Perception(cloud, mark, seg, None), dims.UR5_READY_Q)
    assert isinstance(alone, GraspSet) and len(alone.cut_off) == 0
    assert alone.carried[:, 1].min() > far_end + 0.02
