"""Tests of the object library and the scene loader: they load, compile, rest and fail clearly."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest

from laserpick.robot.sim.objects import (
    GRIPPABLE_WIDTH,
    GROUP_OPAQUE,
    GROUP_SPECULAR,
    GROUP_TRANSPARENT,
    LIBRARY,
    MAX_OBJECT_MASS,
    add_object_body,
    at_rest,
    min_width,
    rest_pose,
    support,
)
from laserpick.robot.sim.scenes import (
    Placement,
    Scene,
    SceneError,
    add_scene_to_spec,
    builtin_scene_names,
    load_scene,
    parse_scene,
)

DATA = Path(__file__).parent / "data"
STEPS = 200


def _compile(scene: Scene) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The scene on a ground plane, compiled, with forward kinematics done."""
    spec = mujoco.MjSpec()
    spec.worldbody.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[40, 40, 0.1])
    add_scene_to_spec(spec, scene)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def _assert_objects_rest(scene: Scene, steps: int = STEPS) -> None:
    """Step the scene and check every object stays put, above its surface."""
    model, data = _compile(scene)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    assert np.all(np.isfinite(data.qpos))
    for p in scene.placements:
        body = model.body(f"obj/{p.instance}").id
        moved = np.linalg.norm(data.xpos[body] - p.pos)
        assert moved < 0.02, f"{p.instance} moved {moved:.3f} m"
        top = scene.surface(p.surface).levels[p.level]
        lowest = data.xpos[body][2] - support(p.model, (0, 0, -1), data.xquat[body])
        assert lowest > top - 0.002, f"{p.instance} sank below {p.surface}"


def _write(tmp_path: Path, text: str, name: str = "broken.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# --- library ------------------------------------------------------------------------------


def test_library_size_and_optics() -> None:
    assert len(LIBRARY) >= 30
    non_opaque = [o for o in LIBRARY.values() if o.optical != "opaque"]
    assert len(non_opaque) >= 3
    assert {o.optical for o in non_opaque} == {"transparent", "specular"}
    for needed in ("soda_can", "water_bottle", "spray_bottle", "pill_bottle", "mug", "bowl",
                   "pill", "tv_remote", "cordless_phone", "toothbrush", "fork", "spoon",
                   "stuffed_toy", "ball", "tea_box"):  # fmt: skip
        assert needed in LIBRARY


@pytest.mark.parametrize("name", sorted(LIBRARY))
def test_library_object_compiles_with_its_mass(name: str) -> None:
    obj = LIBRARY[name]
    assert 0 < obj.mass <= MAX_OBJECT_MASS
    assert min_width(obj) <= GRIPPABLE_WIDTH + 1e-9, "too wide for the 85 mm gripper"
    assert obj.height == pytest.approx(support(obj, (0, 0, 1)))
    spec = mujoco.MjSpec()
    rp = rest_pose(obj)
    body = add_object_body(spec, "x", obj, [0, 0, rp.z], rp.quat)
    assert body.name == "obj/x"
    model = spec.compile()
    b = model.body("obj/x")
    assert b.mass[0] == pytest.approx(obj.mass, rel=0.01)
    assert model.joint("obj/x").type[0] == mujoco.mjtJoint.mjJNT_FREE
    group = {"opaque": GROUP_OPAQUE, "transparent": GROUP_TRANSPARENT}.get(
        obj.optical, GROUP_SPECULAR
    )
    for k in range(len(obj.parts)):
        g = model.geom(f"obj/x/{k}")
        assert g.group[0] == group
        assert g.condim[0] == 6 and g.friction[2] > 0  # rolling friction: a laid can stays
        assert g.friction[0] == pytest.approx(obj.friction)
        if obj.optical == "transparent":
            assert g.rgba[3] == pytest.approx(0.3)


def test_every_library_object_stands_at_rest_upright() -> None:
    """Each object stood upright and tipped 3 degrees about each of four level axes comes back
    (`at_rest`): a scene's upright objects are at rest, not balanced."""
    assert [name for name, obj in sorted(LIBRARY.items()) if not at_rest(obj)] == []


def test_at_rest_tells_a_lying_object_that_rests_from_one_that_tips_over() -> None:
    """Lying (`rest_pose(lying=True)`, the quarter turn with the lowest centre of mass), a
    box and a can rest; a banana stands on its arc, a mug on its rim and handle, a bowl on
    its rim: balanced, and tipped over at a touch."""
    for name in ("tea_box", "soda_can", "cereal_box", "tissue_packet"):
        assert at_rest(LIBRARY[name], lying=True), name
    for name in ("banana", "mug", "bowl"):
        assert not at_rest(LIBRARY[name], lying=True), name


# --- built-in scenes ------------------------------------------------------------------------


def test_builtin_names() -> None:
    assert {"isolation", "kitchen", "surfaces", "jeeves"} <= set(builtin_scene_names())


@pytest.mark.parametrize("name", builtin_scene_names())
def test_builtin_scene_loads_compiles_and_rests(name: str) -> None:
    scene = load_scene(name)
    assert scene.name == name
    assert scene.placements
    model, _ = _compile(scene)
    for surf in scene.surfaces:
        body = model.body(f"surface/{surf.name}")
        for g in range(model.ngeom):
            if model.geom_bodyid[g] == body.id:
                assert model.geom(g).name.startswith(f"surface/{surf.name}/")
                assert model.geom_group[g] == GROUP_OPAQUE
    _assert_objects_rest(scene)


def test_isolation_matches_paper() -> None:
    scene = load_scene("isolation")
    (table,) = scene.surfaces
    assert table.height == pytest.approx(0.46)
    assert len(scene.placements) == 6
    for p in scene.placements:
        assert p.model.optical == "opaque"
        assert not p.lying
        x, y = _footprint_centre(p)
        assert 1.35 <= x <= 1.75 and -0.55 <= y <= 0.25, "outside the reachable region"
    for seed in range(5):
        assert len(load_scene("isolation", seed=seed).placements) == 6


def test_kitchen_heights() -> None:
    scene = load_scene("kitchen")
    heights = sorted(s.height for s in scene.surfaces)
    assert heights == pytest.approx([0.0, 0.31, 0.73, 0.87, 1.0, 1.08])
    shelf = scene.surface("bookshelf")
    assert 0.69 in shelf.levels and shelf.levels[-1] == pytest.approx(1.0)
    assert {p.surface for p in scene.placements} == {s.name for s in scene.surfaces}


def test_surfaces_scene_heights_and_objects() -> None:
    scene = load_scene("surfaces")
    heights = [s.height for s in scene.surfaces]
    measured = [0.008, 0.698, 0.390, 0.384, 0.730, 0.570, 0.720, 0.738, 0.746, 0.630, 0.852, 0.0]
    assert heights == pytest.approx(measured)
    models = {p.model.name for p in scene.placements}
    assert {"cordless_phone", "pill"} <= models


def test_jeeves_markers() -> None:
    scene = load_scene("jeeves")
    (table,) = scene.surfaces
    assert len(scene.markers) == 6
    x0, _, y0, y1 = table.area()
    front = table.to_world(np.array([x0, 0.0]))[0]
    depths = sorted({round(float(m[0] - front), 3) for m in scene.markers.values()})
    assert depths == [0.05, 0.15]
    ys = sorted({round(float(table.to_local(m[:2])[1]), 3) for m in scene.markers.values()})
    assert np.diff(ys) == pytest.approx([0.15, 0.15])
    assert ys[0] - y0 == pytest.approx(0.05) and y1 - ys[-1] == pytest.approx(0.05)
    for m in scene.markers.values():
        assert m[2] == pytest.approx(table.height)
    (can,) = scene.placements
    assert can.pos[:2] == pytest.approx(scene.markers["loc1"][:2])


# --- random placement -------------------------------------------------------------------------

_RANDOM = """
name: rand
surfaces:
  - {name: t, kind: table, xy: [1.7, 0.0], size: [0.8, 1.2], height: 0.6}
random:
  - {count: 10, on: t, models: any, min_gap: 0.03, orientation: coin_flip, seed: 2}
"""


def _poses(scene: Scene) -> np.ndarray:
    return np.array([np.r_[p.pos, p.quat] for p in scene.placements])


def _footprint_centre(p: Placement) -> np.ndarray:
    """World xy of a placed object's footprint centre: its rest-pose centre turned by its yaw."""
    rp = rest_pose(p.model, p.lying)
    # The placement orientation is yaw * rest; recover the yaw from q * rest^-1.
    inv = np.array([rp.quat[0], -rp.quat[1], -rp.quat[2], -rp.quat[3]])
    q = np.zeros(4)
    mujoco.mju_mulQuat(q, np.asarray(p.quat, float), inv)
    assert abs(q[1]) < 1e-9 and abs(q[2]) < 1e-9, "not a pure yaw"
    yaw = 2 * math.atan2(q[3], q[0])
    c, s = math.cos(yaw), math.sin(yaw)
    offset = np.array([c * rp.center[0] - s * rp.center[1], s * rp.center[0] + c * rp.center[1]])
    return p.pos[:2] + offset


def test_random_placement_respects_gap_and_seed() -> None:
    a = parse_scene(_RANDOM)
    b = parse_scene(_RANDOM)
    assert len(a.placements) == 10
    assert np.array_equal(_poses(a), _poses(b))
    assert [p.model.name for p in a.placements] == [p.model.name for p in b.placements]
    c = parse_scene(_RANDOM, seed=99)
    assert not np.allclose(_poses(a), _poses(c))
    assert {p.lying for p in a.placements} == {True, False}
    assert len({p.instance for p in a.placements}) == 10
    table = a.surfaces[0]
    feet = []
    for p in a.placements:
        radius = rest_pose(p.model, p.lying).radius
        centre = _footprint_centre(p)
        feet.append((centre, radius))
        assert table.contains(centre, margin=0.05 + radius - 1e-6)
    for i in range(len(feet)):
        for j in range(i):
            gap = np.linalg.norm(feet[i][0] - feet[j][0]) - feet[i][1] - feet[j][1]
            assert gap >= 0.03 - 1e-9


def test_a_coin_flip_lays_on_its_side_only_what_rests_there() -> None:
    """Heads lays an object on its side only where it rests so; a banana stands. The coin
    is still tossed for it, so the objects after it are drawn as before."""
    lying = standing = 0
    for seed in range(6):
        for p in parse_scene(_RANDOM, seed=seed).placements:
            assert at_rest(p.model, lying=p.lying), (seed, p.instance)
            lying += p.lying
            standing += not at_rest(p.model, lying=True)
    assert lying > 0 and standing > 0


def test_random_placements_settle() -> None:
    scene = parse_scene(_RANDOM.replace("coin_flip", "upright"), seed=5)
    _assert_objects_rest(scene)


# --- user meshes -------------------------------------------------------------------------------


def test_user_mesh_scene_loads_and_rests() -> None:
    scene = load_scene(DATA / "user_scene.yaml")
    block = scene.placement("block_a").model
    assert block.height == pytest.approx(0.07)
    verts = np.vstack([m.vertices for m in block.meshes])
    assert verts[:, 2].min() == pytest.approx(0.0)
    assert (verts[:, 0].min() + verts[:, 0].max()) == pytest.approx(0.0, abs=1e-9)
    assert scene.placement("hex_a").model.optical == "specular"
    model, _ = _compile(scene)
    assert model.body("obj/block_a").mass[0] == pytest.approx(0.15)
    assert model.geom("obj/hex_a/0").group == GROUP_SPECULAR
    _assert_objects_rest(scene)


def test_mesh_model_needs_a_base_dir() -> None:
    text = (DATA / "user_scene.yaml").read_text()
    with pytest.raises(SceneError, match=r"models\.block\.mesh"):
        parse_scene(text)
    scene = parse_scene(text, base_dir=DATA)
    assert len(scene.placements) == 6


# --- errors ---------------------------------------------------------------------------------

_BASE = """
name: broken
surfaces:
  - {name: table, kind: table, xy: [1.6, -0.15], size: [0.6, 1.0], height: 0.46}
"""
_MODEL = _BASE + "models:\n  m: {mesh: MESH, mass: MASS}\n"

_BROKEN = {
    "yaml_syntax": (_BASE + "objects: [\n  {name: a, model: mug\n", "line", "YAML syntax error"),
    "top_level": ("- a\n- b\n", "(top level)", "expected a mapping"),
    "unknown_key": (
        _BASE + "objects:\n  - {name: a, model: mug, on: table, xy: [1.5, 0], colour: red}\n",
        "objects[0].colour",
        "unknown field",
    ),
    "unknown_model": (
        _BASE + "objects:\n  - {name: a, model: flux_capacitor, on: table, xy: [1.5, 0]}\n",
        "objects[0].model",
        "unknown model 'flux_capacitor'",
    ),
    "unknown_surface": (
        _BASE + "objects:\n  - {name: a, model: mug, on: desk, xy: [1.5, 0]}\n",
        "objects[0].on",
        "unknown surface 'desk'",
    ),
    "wrong_type": (
        _BASE + "random:\n  - {count: six, on: table}\n",
        "random[0].count",
        "integer",
    ),
    "nan": (
        _BASE.replace("height: 0.46", "height: .nan"),
        "surfaces[0].height",
        "finite",
    ),
    "negative_size": (
        _BASE.replace("size: [0.6, 1.0]", "size: [-0.6, 1.0]"),
        "surfaces[0].size[0]",
        "greater than 0",
    ),
    "negative_mass": (
        _MODEL.replace("MESH", "hex_can.stl").replace("MASS", "-1"),
        "models.m.mass",
        "greater than 0",
    ),
    "path_traversal": (
        _MODEL.replace("MESH", "../hex_can.stl").replace("MASS", "0.2"),
        "models.m.mesh",
        "'..'",
    ),
    "absolute_outside": (
        _MODEL.replace("MESH", "/etc/hostname.stl").replace("MASS", "0.2"),
        "models.m.mesh",
        "outside",
    ),
    "missing_mesh": (
        _MODEL.replace("MESH", "nowhere.obj").replace("MASS", "0.2"),
        "models.m.mesh",
        "not found",
    ),
    "empty_mesh": (
        _MODEL.replace("MESH", "empty.obj").replace("MASS", "0.2"),
        "models.m.mesh",
        "holds no triangles",
    ),
    "bad_mesh_type": (
        _MODEL.replace("MESH", "hex_can.ply").replace("MASS", "0.2"),
        "models.m.mesh",
        "only OBJ and STL",
    ),
    "does_not_fit": (
        _BASE + "objects:\n  - {name: a, model: cereal_box, on: table, xy: [1.32, 0]}\n",
        "objects[0].xy",
        "does not fit",
    ),
    "overlap": (
        _BASE + "objects:\n  - {name: a, model: mug, on: table, xy: [1.5, 0]}\n"
        "  - {name: b, model: soda_can, on: table, xy: [1.52, 0]}\n",
        "objects[1]",
        "overlaps 'a'",
    ),
    "level_on_table": (
        _BASE + "objects:\n  - {name: a, model: mug, on: table, xy: [1.5, 0], level: 1}\n",
        "objects[0].level",
        "only shelves",
    ),
    "too_tall_for_shelf": (
        "name: s\nsurfaces:\n  - {name: sh, kind: shelf, xy: [1.6, 0], size: [0.3, 0.8], "
        "levels: [0.3, 0.5]}\n"
        "objects:\n  - {name: a, model: cereal_box, on: sh, level: 0, xy: [1.55, 0]}\n",
        "objects[0].level",
        "clearance",
    ),
    "surface_on_scooter": (
        _BASE.replace("xy: [1.6, -0.15]", "xy: [0.8, 0.0]"),
        "surfaces[0]",
        "overlaps the scooter",
    ),
    "cannot_place": (
        _BASE + "random:\n  - {count: 60, on: table, models: [mug], min_gap: 0.05}\n",
        "random[0]",
        "could not place",
    ),
    "duplicate_name": (
        _BASE + "objects:\n  - {name: a, model: mug, on: table, xy: [1.4, 0]}\n"
        "  - {name: a, model: mug, on: table, xy: [1.7, 0]}\n",
        "objects[1].name",
        "duplicate",
    ),
    "lying_banana": (
        _BASE + "objects:\n  - {name: b, model: banana, on: table, xy: [1.4, 0], lying: true}\n",
        "objects[0].lying",
        "does not rest on its side",
    ),
    "bad_name": (
        _BASE + "objects:\n  - {name: 'a b', model: mug, on: table, xy: [1.4, 0]}\n",
        "objects[0].name",
        "letters, digits",
    ),
}


@pytest.mark.parametrize("case", sorted(_BROKEN))
def test_broken_scene_errors_name_file_field_and_problem(tmp_path: Path, case: str) -> None:
    text, field_path, problem = _BROKEN[case]
    shutil.copy(DATA / "hex_can.stl", tmp_path / "hex_can.stl")
    (tmp_path / "hex_can.ply").write_text("ply\n")
    scene_dir = tmp_path / "scenes"
    scene_dir.mkdir()
    shutil.copy(DATA / "hex_can.stl", scene_dir / "hex_can.stl")
    (scene_dir / "empty.obj").write_text("# no geometry\n")
    path = _write(scene_dir, text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    msg = str(info.value)
    assert "broken.yaml" in msg
    assert field_path in msg
    assert problem in msg


def test_decompose_without_coacd_is_a_clear_error(tmp_path: Path) -> None:
    try:
        import coacd  # noqa: F401
    except ImportError:
        pass
    else:
        pytest.skip("coacd is installed")
    shutil.copy(DATA / "hex_can.stl", tmp_path / "hex_can.stl")
    text = _BASE + "models:\n  m: {mesh: hex_can.stl, mass: 0.2, collision: decompose}\n"
    with pytest.raises(SceneError, match=r"models\.m\.collision.*coacd"):
        load_scene(_write(tmp_path, text))


def test_unknown_builtin_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match="no built-in scene"):
        load_scene("atlantis")
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.yaml")


def test_on_key_is_not_a_boolean() -> None:
    scene = parse_scene(
        _BASE + "objects:\n  - {name: a, model: mug, on: table, xy: [1.5, 0], lying: false}\n"
    )
    assert scene.placements[0].surface == "table"
