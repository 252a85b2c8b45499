"""A scene with your own mesh: write a mesh and a scene YAML, load it, simulate, capture once.

A scene file names the scooter's start pose, the surfaces, your mesh models (OBJ or STL files
beside the YAML) and where objects stand; `load_scene` checks it and names any mistake with
its field. This script makes a hexagonal block with trimesh (in millimetres, scaled to metres
in the YAML), stands it on a table beside a library soda can, lets the simulator settle the
scene, captures the five depth cameras once, and says where each object came to rest and how
many points of the fused cloud fall on it. Run:

    python examples/03_own_meshes_scene.py [--dir DIR] [--record OUT]

`--dir` keeps the mesh and the YAML there (default: a temporary directory); `--record OUT`
also saves the capture as a recording for example 02.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh

from laserpick.pipeline.cloud import fuse
from laserpick.robot.gl_backend import choose_gl_backend
from laserpick.robot.recording import Recording, capture_from, write_recording

SCENE = """\
name: my_desk
scooter: {x: 0.0, y: 0.0, yaw_deg: 0.0}   # base frame in world: x forward, y left, z up
surfaces:
  - {name: desk, kind: table, xy: [1.60, -0.15], size: [0.6, 1.0], height: 0.50}
models:
  hex_block: {mesh: hex_block_mm.stl, scale: 0.001, mass: 0.15, friction: 0.7,
              rgba: [0.2, 0.5, 0.9, 1]}
objects:
  - {name: my_block, model: hex_block, on: desk, xy: [1.45, -0.30], yaw_deg: 15}
  - {name: can, model: soda_can, on: desk, xy: [1.55, -0.05]}
"""


def write_scene(directory: Path) -> Path:
    """The mesh (a 6-sided prism, 60 mm across and 80 mm tall, in mm) and the scene YAML."""
    block = trimesh.creation.cylinder(radius=30.0, height=80.0, sections=6)
    block.export(directory / "hex_block_mm.stl")
    path = directory / "my_desk.yaml"
    path.write_text(SCENE)
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, help="where to write the mesh and the scene")
    parser.add_argument("--record", type=Path, metavar="OUT", help="save the capture here")
    args = parser.parse_args()
    choose_gl_backend()  # before the simulator loads MuJoCo: EGL or OSMesa if MUJOCO_GL is unset
    from laserpick.robot.sim import SceneError, load_scene
    from laserpick.robot.sim.truth import SimTruth, capture

    with tempfile.TemporaryDirectory(prefix="laserpick-scene-") as tmp:
        directory = args.dir or Path(tmp)
        directory.mkdir(parents=True, exist_ok=True)
        try:
            scene = load_scene(write_scene(directory))
        except SceneError as exc:
            sys.exit(str(exc))
        print(f"scene {scene.name!r}: {', '.join(p.instance for p in scene.placements)}")

        captured = capture(scene)  # the simulator, headless: settled for 0.5 s, one capture
        try:
            cloud = fuse(captured.frames)
            truth = SimTruth(captured.robot)  # simulator truth: where things really are
            for p in scene.placements:
                seen = int(np.count_nonzero(captured.object_points(cloud, p.instance)))
                where = np.round(truth.position(p.instance), 3)
                print(f"{p.instance}: rests at {where} m in base, {seen} cloud points on it")
            if args.record is not None:
                recording = Recording(
                    (capture_from(captured.robot),), captured.robot.projector(), "example 03"
                )
                print(f"recording written to {write_recording(args.record, recording)}")
        finally:
            captured.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
