"""GPD-style grasp candidates on synthetic point clouds (no simulator).

The shapes (`gpd_shapes`) are sampled on a 3 mm grid with exact outward normals plus a little
noise, standing on a 4 mm grid of table points at z = 0. Frames: `base`-like, z up, metres.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gpd_shapes import box, cylinder, noisy, plate, table
from scipy.spatial import cKDTree

from laserpick.description.dims import GRIPPER_HAND
from laserpick.pipeline.gpd import CandidateSearch, detect_grasps
from laserpick.pipeline.gpd.antipodal import (
    guesses_face_seen,
)
from laserpick.pipeline.gpd.frames import (
    local_frames,
    sample_indices,
    tilted_frames,
)
from laserpick.pipeline.gpd.hand import cleared_hand
from laserpick.pipeline.gpd.recentre import patch_moves
from laserpick.settings import GraspSettings
from laserpick.types import Grasp

S = GraspSettings()
HAND = GRIPPER_HAND
FRICTION = math.radians(S.gpd_friction_deg)


def detect(target, normals, others=(), seed=0, settings=S) -> list[Grasp]:
    scene = np.vstack([table(), target, *others]).astype(np.float32)
    return detect_grasps(
        target.astype(np.float32), noisy(normals), scene, settings, np.random.default_rng(seed)
    )


def hand_coords(g: Grasp, pts: np.ndarray) -> np.ndarray:
    """Points in the grasp's frame (hand axis, closing, approach), origin at the fingertips'
    centre line (the TCP moved pad_depth / 2 forward)."""
    tips = g.position + g.approach * HAND.pad_depth / 2
    return (pts - tips) @ g.pose[:3, :3]


def in_fingers(g: Grasp, pts: np.ndarray, grow: float = 0.0) -> np.ndarray:
    """Mask of points inside either finger box (pad plus plate) of the open hand, each box
    grown by `grow` (m) on its four sides (not at the tip or the root)."""
    h, c, a = hand_coords(g, pts).T
    thick = HAND.pad_thickness + HAND.finger_thickness
    lateral = (np.abs(c) >= HAND.width_max / 2 - grow) & (
        np.abs(c) <= HAND.width_max / 2 + thick + grow
    )
    across = np.abs(h) <= HAND.finger_width / 2 + grow
    return lateral & across & (a <= 0) & (a >= -HAND.finger_length)


def in_palm(g: Grasp, pts: np.ndarray, grow: float = 0.0) -> np.ndarray:
    """Mask of points inside the palm box, grown by `grow` (m) on its four sides."""
    h, c, a = hand_coords(g, pts).T
    return (
        (np.abs(c) <= HAND.palm_width / 2 + grow)
        & (np.abs(h) <= HAND.palm_depth / 2 + grow)
        & (a <= -HAND.finger_length)
        & (a >= -HAND.finger_length - HAND.palm_length)
    )


def finger_corners(g: Grasp) -> np.ndarray:
    """The 16 corners of both finger boxes in `base`."""
    thick = HAND.pad_thickness + HAND.finger_thickness
    tips = g.position + g.approach * HAND.pad_depth / 2
    out = []
    for h in (-HAND.finger_width / 2, HAND.finger_width / 2):
        for c in (HAND.width_max / 2 + thick, -HAND.width_max / 2 - thick):
            for a in (0.0, -HAND.finger_length):
                out.append(tips + h * g.axis + c * g.closing + a * g.approach)
    return np.array(out)


@pytest.fixture(scope="module")
def cylinder_grasps() -> list[Grasp]:
    pts, n = cylinder()
    return detect(pts, n)


def test_cylinder_has_grasps_closing_horizontally_through_its_axis(cylinder_grasps):
    assert len(cylinder_grasps) > 20
    for g in cylinder_grasps:
        # Antipodal on a vertical cylinder: the closing axis is within the friction cone of
        # horizontal, and its line passes near the cylinder's axis: the contacts' normals
        # are within the cone, and the contacts lie within the pads' half-width of the line.
        assert abs(g.closing[2]) <= math.sin(FRICTION + math.radians(3))
        c = g.closing[:2] / np.linalg.norm(g.closing[:2])
        p = g.position[:2]
        near = 0.03 * math.sin(FRICTION) + HAND.pad_width / 2
        assert abs(p[0] * c[1] - p[1] * c[0]) < near


def test_cylinder_width_is_its_diameter(cylinder_grasps):
    widths = np.array([g.width for g in cylinder_grasps])
    assert np.median(widths) == pytest.approx(0.06, abs=0.005)
    level = [g.width for g in cylinder_grasps if abs(g.closing[2]) < math.sin(math.radians(5))]
    assert level and np.allclose(level, 0.06, atol=0.005)
    assert widths.max() <= HAND.width_max


def test_cylinder_grasps_stay_above_the_table(cylinder_grasps):
    table_pts = table()
    for g in cylinder_grasps:
        assert finger_corners(g)[:, 2].min() > 0.0
        assert not in_fingers(g, table_pts).any() and not in_palm(g, table_pts).any()


def test_cylinder_gets_top_and_side_grasps(cylinder_grasps):
    approach_z = np.array([g.approach[2] for g in cylinder_grasps])
    assert (approach_z < -0.9).sum() >= 3  # from above
    assert (np.abs(approach_z) < 0.3).sum() >= 3  # from the side


def test_a_can_from_above_is_centred_only_where_its_pads_meet_it_about_their_middle():
    """From above, the pads meet a can's side along the line through its axis. GPD's friction
    cone alone passes a hand tilted up to 20 degrees and shifted along the hand axis until
    that line lies at the pads' edge or past it (up to 15 mm on this can): such a pad meets
    the can with a corner. A grasp is `pads_centred` only where each pad meets it along its
    face (gpd_tangent_deg), about its middle (gpd_patch_offset)."""
    pts, n = cylinder(r=0.033, height=0.122)
    from_above = [g for g in detect(pts, n) if g.approach[2] < -0.7]
    # How far along the hand axis the can's axis passes from the TCP (m).
    off = np.array(
        [abs(np.array([-g.position[0], -g.position[1], 0.0]) @ g.axis) for g in from_above]
    )
    centred = np.array([g.pads_centred for g in from_above])
    assert centred.sum() >= 20
    assert off[centred].max() <= S.gpd_patch_offset
    assert off[~centred].max() > 2 * S.gpd_patch_offset


def can_axis_offset(g: Grasp, centre: tuple[float, float] = (0.0, 0.0)) -> float:
    """How far (m) along the hand axis an upright can's axis at `centre` passes from the TCP."""
    return float(np.array([centre[0] - g.position[0], centre[1] - g.position[1], 0.0]) @ g.axis)


def test_off_centre_hands_are_turned_and_shifted_onto_their_patch():
    """GPD's eight orientations do not include a sample's normal, so no hand comes straight
    down onto a can's top: the nearest lean 13 degrees, and close across it at that slant,
    where no pad meets it along its face. patch_moves turns each such hand about its axis
    onto the normals its pads touch, and shifts it along its axis onto the patch where they
    would meet the can along their face."""
    pts, n = cylinder(r=0.033, height=0.122)
    normals, scene = noisy(n), np.vstack([table(), pts]).astype(np.float32)
    hand = cleared_hand(HAND, S.side_clearance)
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    tgt = pts - centre
    tree = cKDTree(tgt)
    idx = sample_indices(len(tgt), S.gpd_samples, np.random.default_rng(0))
    normal, axis = local_frames(tgt, normals, idx, S, tree)
    search = CandidateSearch(tgt, normals, scene, centre, tree, hand, S, None, lambda _: None)
    found = search.candidates(tgt[idx], normal, axis)
    above = np.flatnonzero(~found.centred & (found.poses[:, 2, 2] < -0.9))
    off = found.subset(above)
    turn, shift = patch_moves(tgt, normals, hand, S, off)
    moved = np.isfinite(shift)
    assert moved.mean() > 0.8
    # The turn levels the closing axis: it turns it by about as much as it leans.
    lean = np.arcsin(off.poses[:, 2, 1])
    assert np.abs(np.sin(turn - lean)[moved]).max() < math.sin(math.radians(S.gpd_tangent_deg))
    # The shift brings the can's axis (through the target's centre) to the TCP, along the
    # hand axis.
    axis_at = -np.einsum("gi,gi->g", off.poses[:, :2, 0], off.poses[:, :2, 3])
    assert np.median(np.abs(shift - axis_at)[moved]) < 0.002


def test_recentring_adds_centred_hands_after_the_first():
    pts, n = cylinder(r=0.033, height=0.122)
    first = detect(pts, n, settings=S.model_copy(update={"gpd_recentre": 0.0}))
    both = detect(pts, n)
    assert len(both) > len(first)
    for g, h in zip(first, both, strict=False):  # GPD's own candidates come first, unchanged
        np.testing.assert_array_equal(g.pose, h.pose)
    added = both[len(first) :]
    assert all(g.pads_centred for g in added)
    above = [g for g in both if g.approach[2] < -0.9]
    level = math.sin(math.radians(S.gpd_tangent_deg))
    assert all(abs(can_axis_offset(g)) <= S.gpd_patch_offset for g in above if g.pads_centred)
    assert all(abs(g.closing[2]) <= level for g in added if g.approach[2] < -0.9)
    n_first = sum(g.pads_centred and g.approach[2] < -0.9 for g in first)
    assert sum(g.pads_centred for g in above) >= 2 * n_first


def slant_about_approach(g: Grasp) -> float:
    """Degrees between a grasp's closing axis and the nearest face normal of a box whose
    faces lie along `base`'s axes, seen along its approach."""
    k = int(np.argmax(np.abs(g.closing)))
    face = np.eye(3)[k] * np.sign(g.closing[k])
    return abs(math.degrees(math.atan2(face @ g.axis, face @ g.closing)))


@pytest.mark.parametrize("size", [(0.106, 0.054, 0.025), (0.05, 0.03, 0.10)])
def test_hands_on_a_box_are_turned_square_to_its_sides(size):
    """A flat face gives the curvature axis no direction, so GPD's hands come onto a box
    turned any way about their approach, and the friction cone passes pads up to 20 degrees
    off its sides: they hold it on two diagonal edges. Each is replaced by the hand turned
    square to the faces its pads meet, where that one passes."""
    pts, n = box(size)
    plain = [
        detect(pts, n, seed=k, settings=S.model_copy(update={"gpd_square": False}))
        for k in range(3)
    ]
    square = [detect(pts, n, seed=k) for k in range(3)]
    assert [len(g) for g in square] == [len(g) for g in plain]
    before = [slant_about_approach(g) for gs in plain for g in gs]
    after = [slant_about_approach(g) for gs in square for g in gs]
    assert max(before) > 6.0
    assert max(after) < 3.0
    assert all(0 < g.width <= HAND.width_max for gs in square for g in gs)


def test_tilted_frames_lean_the_normal_toward_the_axis_about_the_closing_axis():
    rng = np.random.default_rng(4)
    normal = rng.normal(size=(5, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    axis = np.cross(normal, rng.normal(size=(5, 3)))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    tilts = np.radians([0.0, 30.0, -60.0])
    n2, a2 = tilted_frames(normal, axis, tilts)
    assert n2.shape == a2.shape == (15, 3)
    for t, beta in enumerate(tilts):
        rows = slice(5 * t, 5 * t + 5)
        assert np.allclose(np.cross(n2[rows], a2[rows]), np.cross(normal, axis))  # closing
        assert np.allclose(np.sum(n2[rows] * normal, axis=1), math.cos(beta))
        assert np.allclose(np.sum(n2[rows] * axis, axis=1), math.sin(beta))


def test_a_lying_cylinder_is_grasped_across_its_girth_from_along_its_axis_only_tilted():
    """A can lying along x: GPD's frames (hand axis along the can) approach it square to its
    axis; tilted about the closing axis, the hand also comes in along it, from the front and
    above, still closing across the girth."""
    r = 0.022
    pts, n = cylinder(r=r, height=0.10)
    # Lay it down along x: (x, y, z) -> (z - 5 cm, y, r - x), on the table.
    turn = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    pts = pts @ turn.T + [-0.05, 0.0, r]
    n = n @ turn.T
    upright = detect(pts, n)
    assert upright and max(abs(g.approach[0]) for g in upright) < 0.35
    scene = np.vstack([table(), pts]).astype(np.float32)
    tilts = tuple(np.radians(S.gpd_tilts_deg))
    tilted = detect_grasps(
        pts.astype(np.float32), noisy(n), scene, S, np.random.default_rng(0), tilts=tilts
    )
    leaning = [g for g in tilted if abs(g.approach[0]) > 0.45]
    assert len(leaning) >= 3
    for g in leaning:
        assert abs(g.closing[0]) < math.sin(FRICTION + math.radians(3))  # across the girth
        assert g.width == pytest.approx(2 * r, abs=0.006)
        assert not in_fingers(g, table()).any() and finger_corners(g)[:, 2].min() > 0.0


def test_narrow_box_closes_across_its_small_faces():
    pts, n = box((0.05, 0.03, 0.10))
    grasps = detect(pts, n)
    assert grasps
    for g in grasps:
        # Across the 3 cm or the 5 cm faces (width up to the friction cone's slant), never
        # across the 10 cm height.
        assert g.width <= HAND.width_max
        assert min(abs(g.width - 0.03), abs(g.width - 0.05)) < 0.012
        assert abs(g.closing[2]) < 0.5
    widths = np.array([g.width for g in grasps])
    assert (np.abs(widths - 0.03) < 0.005).any() and (np.abs(widths - 0.05) < 0.005).any()


def test_wide_box_has_no_grasp_wider_than_the_hand():
    pts, n = box((0.12, 0.12, 0.12))
    grasps = detect(pts, n)
    assert all(0 < g.width <= HAND.width_max for g in grasps)
    # Across any face it is 12 cm: nothing may close there.
    for g in grasps:
        assert np.max(np.abs(g.closing)) < math.cos(FRICTION)


def two_plates(tilt_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Two 4 x 4 cm vertical plates at y = +-2 cm, 5 cm above the table, normals facing out;
    the +y plate tilted by `tilt_deg` about its horizontal centre line."""
    X, Y, Z = np.eye(3)
    a, b = 0.04 * X, 0.04 * Z
    right = plate(np.array([-0.02, -0.02, 0.05]), a, b, -Y)
    t = math.radians(tilt_deg)
    n = math.cos(t) * Y - math.sin(t) * Z  # tilted about x
    up = math.sin(t) * Y + math.cos(t) * Z
    centre = np.array([0.0, 0.02, 0.07])
    left = plate(centre - 0.02 * X - 0.02 * up, a, 0.04 * up, n)
    return np.vstack([right[0], left[0]]), np.vstack([right[1], left[1]])


def test_parallel_plates_are_antipodal():
    pts, n = two_plates(0.0)
    grasps = detect(pts, n)
    assert grasps
    for g in grasps:
        assert abs(g.closing[1]) > math.cos(FRICTION)
        assert g.width == pytest.approx(0.04, abs=0.006)


def test_tilted_plate_is_not_antipodal():
    pts, n = two_plates(60.0)
    assert detect(pts, n) == []


def test_a_pad_on_guessed_points_only_must_face_the_seen_ones():
    # Frames 0-3, pads 0 (left) and 1 (right); depths along the approach (m).
    f = np.array([0, 0, 1, 1, 2, 2, 3, 3])
    side = np.array([0, 1, 0, 1, 0, 1, 0, 1])
    depth = np.array([0.004, -0.004, 0.004, 0.002, 0.004, -0.004, 0.0, 0.0], np.float32)
    guessed = np.array([0, 1, 0, 1, 0, 0, 1, 1], bool)
    contacts = [(f, side, depth, guessed)]
    wider = [(np.array([0]), np.array([0]), np.array([0.010], np.float32), np.array([False]))]
    ok = guesses_face_seen(contacts + wider, 4)
    # 0: the guessed pad (-4 mm) lies in front of the seen one (4-10 mm): refused.
    # 1: the guessed pad at 2 mm, the seen one at 4 mm: no overlap, refused; with the seen
    #    pad reaching 2 mm it is kept. 2: both seen: the rule does not apply.
    # 3: both pads guessed: nothing seen is held, refused.
    np.testing.assert_array_equal(ok, [False, False, True, False])
    reach = [(np.array([1]), np.array([0]), np.array([0.002], np.float32), np.array([False]))]
    assert guesses_face_seen(contacts + reach, 4)[1]


def test_a_guessed_plate_beside_the_seen_one_is_not_grasped_across_the_seam():
    # A seen plate at y = -2 cm, z 3-7 cm, and a guessed one at y = +2 cm, z 7-11 cm: from
    # straight above, the pads would straddle the seam, one on each, at different depths.
    # From the side, or leaning along the plates, both pads meet their plates at one depth.
    X, Y, Z = np.eye(3)
    seen = plate(np.array([-0.02, -0.02, 0.03]), 0.04 * X, 0.04 * Z, -Y)
    back = plate(np.array([-0.02, 0.02, 0.07]), 0.04 * X, 0.04 * Z, Y)
    pts, n = np.vstack([seen[0], back[0]]), noisy(np.vstack([seen[1], back[1]]))
    guessed = np.r_[np.zeros(len(seen[0]), bool), np.ones(len(back[0]), bool)]
    scene = np.vstack([table(), pts]).astype(np.float32)

    def run(flags: np.ndarray | None) -> list[Grasp]:
        rng = np.random.default_rng(0)
        return detect_grasps(pts.astype(np.float32), n, scene, S, rng, guessed=flags)

    def faces(g: Grasp) -> bool:
        """Whether the pads' seen and guessed points overlap in depth (the plates are flat:
        every point between the pads is a contact)."""
        h, c, a = hand_coords(g, pts).T
        pad = (np.abs(h) < HAND.pad_width / 2) & (a <= 0) & (a >= -HAND.pad_depth)
        pad &= np.abs(c) < HAND.width_max / 2
        on_seen, on_guess = a[pad & ~guessed], a[pad & guessed]
        return max(on_seen.min(), on_guess.min()) <= min(on_seen.max(), on_guess.max())

    free, ruled = run(None), run(guessed)
    assert any(g.approach[2] < -0.9 and not faces(g) for g in free)  # from above
    assert ruled and all(faces(g) for g in ruled)
    assert {g.pose.tobytes() for g in ruled} <= {g.pose.tobytes() for g in free}
    unflagged = run(np.zeros(len(pts), bool))  # all seen: nothing changes
    assert [g.pose.tobytes() for g in unflagged] == [g.pose.tobytes() for g in free]


def test_neighbour_blocks_fingers():
    pts, n = cylinder()
    # A 4 x 4 x 10 cm box 1 cm from the cylinder's side (+x).
    other, _ = box((0.04, 0.04, 0.10), centre=(0.03 + 0.01 + 0.02, 0.0))
    grasps = detect(pts, n, others=(other,))
    assert grasps
    for g in grasps:
        assert not in_fingers(g, other).any()
        assert not in_palm(g, other).any()


def test_the_hand_keeps_its_side_clearance_from_every_point():
    # A seen edge can lie a few mm short of the real one, and the arm tracks to a few mm: no
    # point, of the object or of its neighbour, comes within side_clearance of a finger's
    # faces and edges or the palm's sides. (The binned test is exact at the inner faces and
    # errs outward elsewhere, so no allowance is needed.)
    pts, n = cylinder()
    other, _ = box((0.04, 0.04, 0.10), centre=(0.03 + 0.01 + 0.02, 0.0))
    grasps = detect(pts, n, others=(other,))
    assert grasps
    near = S.side_clearance - 1e-6
    for g in grasps:
        for cloud in (pts, other):
            assert not in_fingers(g, cloud, grow=near).any()
            assert not in_palm(g, cloud, grow=near).any()
    assert max(g.width for g in grasps) <= HAND.width_max - 2 * S.side_clearance


def test_without_side_clearance_the_fingers_may_graze_the_object():
    # The same detection with no clearance finds grasps the clearance rules out: the
    # clearance test above is not passing because no grasp ever came close.
    pts, n = cylinder()
    other, _ = box((0.04, 0.04, 0.10), centre=(0.03 + 0.01 + 0.02, 0.0))
    scene = np.vstack([table(), pts, other]).astype(np.float32)
    bare = S.model_copy(update={"side_clearance": 0.0})
    grasps = detect_grasps(pts, noisy(n), scene, bare, np.random.default_rng(3))
    near = S.side_clearance - 1e-6
    assert any(in_fingers(g, np.vstack([pts, other]), grow=near).any() for g in grasps)
    # Side grasps closing straight along x below the box's top would put a finger through it.
    assert not any(
        abs(g.closing[0]) > 0.98 and abs(g.approach[2]) < 0.3 and g.position[2] < 0.09
        for g in grasps
    )


def test_same_seed_same_grasps():
    pts, n = cylinder()
    a, b = detect(pts, n, seed=3), detect(pts, n, seed=3)
    assert len(a) == len(b)
    assert all(
        np.array_equal(x.pose, y.pose) and x.width == y.width for x, y in zip(a, b, strict=True)
    )
    c = detect(pts, n, seed=4)
    assert len(c) != len(a) or any(
        not np.array_equal(x.pose, y.pose) for x, y in zip(a, c, strict=False)
    )


def test_tiny_target_gives_nothing():
    assert detect_grasps(np.zeros((2, 3)), np.zeros((2, 3)), table()) == []
