"""User mesh models: a scene's OBJ or STL files, checked and turned into object models."""

from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from laserpick.robot.sim.objects import TRANSPARENT_ALPHA, MeshAsset, ObjectModel, Part
from laserpick.robot.sim.scenes.errors import Fail
from laserpick.robot.sim.scenes.schema import ModelCfg

if TYPE_CHECKING:
    import trimesh

#: Largest mesh file accepted (bytes) and most faces in a mesh.
MAX_MESH_BYTES = 20 * 1024 * 1024
MAX_MESH_FACES = 200_000
#: Largest extent of a user mesh after scaling (m): household objects, not furniture.
MAX_MESH_EXTENT = 1.0
_DEFAULT_MODEL_RGBA = (0.7, 0.7, 0.72, 1.0)

#: Convex pieces of a mesh: (vertices (N, 3), faces (M, 3)) each.
Pieces = list[tuple[np.ndarray, np.ndarray]]


def _mesh_file(mc: ModelCfg, base_dir: Path | None, fail: Fail, path: str) -> Path:
    """The mesh file's full path, checked: inside the scene's directory, OBJ or STL, there,
    and under `MAX_MESH_BYTES`."""
    if base_dir is None:
        raise fail(f"{path}.mesh", "mesh models need the scene file's directory (base_dir)")
    rel = Path(mc.mesh)
    if ".." in rel.parts:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} must not contain '..'")
    base = base_dir.resolve()
    full = (rel if rel.is_absolute() else base / rel).resolve()
    if not full.is_relative_to(base):
        raise fail(f"{path}.mesh", f"{mc.mesh!r} lies outside the scene file's directory")
    if full.suffix.lower() not in (".obj", ".stl"):
        raise fail(f"{path}.mesh", f"{mc.mesh!r}: only OBJ and STL meshes are supported")
    if not full.is_file():
        raise fail(f"{path}.mesh", f"mesh file {mc.mesh!r} not found")
    nbytes = full.stat().st_size
    if nbytes > MAX_MESH_BYTES:
        raise fail(
            f"{path}.mesh",
            f"{mc.mesh!r} is {nbytes / 1e6:.1f} MB; the limit is {MAX_MESH_BYTES / 1e6:.0f} MB",
        )
    return full


def _read_mesh(full: Path, mc: ModelCfg, fail: Fail, path: str) -> trimesh.Trimesh:
    """The mesh in the file, checked: triangles, at most `MAX_MESH_FACES`, finite."""
    import trimesh

    try:
        # Load from bytes, with no resolver: an OBJ's mtllib or textures are never opened.
        mesh = trimesh.load(
            io.BytesIO(full.read_bytes()),
            file_type=full.suffix.lower()[1:],
            force="mesh",
            process=True,
        )
    except Exception as exc:  # trimesh raises many kinds of errors on bad files
        raise fail(f"{path}.mesh", f"cannot read {mc.mesh!r}: {exc}") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} holds no triangles")
    if len(mesh.faces) > MAX_MESH_FACES:
        raise fail(
            f"{path}.mesh",
            f"{mc.mesh!r} has {len(mesh.faces)} faces; the limit is {MAX_MESH_FACES}",
        )
    if not np.all(np.isfinite(mesh.vertices)):
        raise fail(f"{path}.mesh", f"{mc.mesh!r} has non-finite vertices")
    return mesh


def _scaled(
    mesh: trimesh.Trimesh, mc: ModelCfg, fail: Fail, path: str
) -> tuple[np.ndarray, trimesh.Trimesh]:
    """The mesh scaled, centred in xy on its bounding box and lifted so its lowest point is at
    z = 0: its vertices (N, 3) (m) and the processed mesh. Checked to be an object's size,
    not flat and not furniture."""
    import trimesh

    verts = np.asarray(mesh.vertices, dtype=float) * np.asarray(mc.scale)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    ext = hi - lo
    if ext.max() > MAX_MESH_EXTENT:
        raise fail(
            f"{path}.scale",
            f"the scaled mesh is {ext.max():.2f} m across; objects must stay "
            f"under {MAX_MESH_EXTENT} m (is the scale right? mm files need scale 0.001)",
        )
    if ext.min() < 1e-3:
        raise fail(f"{path}.mesh", f"{mc.mesh!r} is flat (under 1 mm thick); it needs a volume")
    verts = verts - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    return verts, trimesh.Trimesh(verts, np.asarray(mesh.faces), process=True)


def _convex_pieces(mesh: trimesh.Trimesh, mc: ModelCfg, fail: Fail, path: str) -> Pieces:
    """The mesh's collision pieces: its convex hull, or its coacd convex decomposition."""
    import trimesh

    if mc.collision == "hull":
        hull = mesh.convex_hull
        return [(np.asarray(hull.vertices), np.asarray(hull.faces))]
    try:
        import coacd  # type: ignore[import-not-found]
    except ImportError:
        raise fail(
            f"{path}.collision",
            "'decompose' needs the coacd package (pip install coacd); use 'hull' instead",
        ) from None
    try:
        coacd.set_log_level("error")
        parts = coacd.run_coacd(coacd.Mesh(mesh.vertices, mesh.faces))
    except Exception as exc:
        raise fail(f"{path}.collision", f"convex decomposition failed: {exc}") from None
    pieces = []
    for v, f in parts:
        piece = trimesh.Trimesh(np.asarray(v), np.asarray(f)).convex_hull
        if piece.volume > 1e-9:
            pieces.append((np.asarray(piece.vertices), np.asarray(piece.faces)))
    if not pieces:
        raise fail(f"{path}.collision", "convex decomposition produced no pieces")
    return pieces


def mesh_model(
    name: str, mc: ModelCfg, base_dir: Path | None, fail: Fail, path: str
) -> ObjectModel:
    """Load a user mesh model: checks the path, size and content, then builds collision parts.

    The mesh is scaled, centred in xy on its bounding box and lifted so its lowest point is at
    z = 0. `collision: hull` uses its convex hull (what MuJoCo would collide anyway);
    `decompose` splits it into convex pieces with coacd so concave shapes stay concave.
    """
    full = _mesh_file(mc, base_dir, fail, path)
    verts, mesh = _scaled(_read_mesh(full, mc, fail, path), mc, fail, path)
    pieces = _convex_pieces(mesh, mc, fail, path)
    meshes = tuple(MeshAsset(f"part{k}", v, f) for k, (v, f) in enumerate(pieces))
    parts_ = tuple(Part("mesh", (), mesh=m.name) for m in meshes)
    rgba = mc.rgba
    if rgba is None:
        rgba = _DEFAULT_MODEL_RGBA
        if mc.optical == "transparent":
            rgba = (*_DEFAULT_MODEL_RGBA[:3], TRANSPARENT_ALPHA)
    return ObjectModel(
        name=name,
        category=mc.category,
        parts=parts_,
        mass=mc.mass,
        friction=mc.friction,
        rgba=rgba,
        optical=mc.optical,
        height=float(verts[:, 2].max()),
        meshes=meshes,
    )
