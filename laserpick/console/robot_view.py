"""The robot in the 3D view, drawn from its description and its reported joint state.

Every part of `laserpick.description.visuals.PARTS` (the scooter, the arm's mount, the six
links, the gripper and its fingers) becomes one viser frame under `ROBOT_ROOT`, its shapes
merged into one mesh per colour. The root frame stands at the scooter's odometry pose in
`world`; the parts' frames are posed in `base` by `part_poses(q, width)`. So any robot that
reports its joints, its gripper's opening and its odometry (`Robot.state()`) is drawn the
same, simulated or real.

Frames and units: the root in `world` (z up), the parts in `base`; metres, radians.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import trimesh
import viser

from laserpick.console.scene_nodes import PoseFollower, add_mesh, node_safe
from laserpick.description.visuals import PARTS, Part, Shape, part_poses
from laserpick.robot.interface import RobotState
from laserpick.transforms import quat_from_matrix

__all__ = ["ROBOT_ROOT", "RobotNodes", "part_meshes", "shape_mesh"]

ROBOT_ROOT = "/laserpick/robot"
#: The parts' frames are worked out again once a joint turned this far (rad) or the gripper
#: opened or closed this far (m) from where they were last worked out: a link 1 m long
#: moves its end 0.1 mm, under the step that is sent (`POSE_STEP_M`).
JOINT_STEP = 1e-4


def shape_mesh(shape: Shape) -> trimesh.Trimesh:
    """The triangle mesh of a shape in its part's frame (m). Sharp edges are split so that
    the browser's computed normals shade boxes flat and cylinders smooth."""
    radius = shape.size[0]
    if shape.kind == "box":
        mesh = trimesh.creation.box(extents=2 * np.asarray(shape.size)).smooth_shaded
    elif shape.kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=radius)
    elif shape.kind == "capsule":
        mesh = trimesh.creation.capsule(height=2 * shape.size[1], radius=radius, count=[16, 16])
    elif shape.kind == "cylinder":
        mesh = trimesh.creation.cylinder(radius=radius, height=2 * shape.size[1], sections=24)
        mesh = mesh.smooth_shaded
    else:
        raise ValueError(f"shape {shape.name!r} has kind {shape.kind!r}, which is not drawn")
    mesh.apply_transform(shape.pose)
    return mesh


def part_meshes(part: Part) -> list[tuple[tuple[float, ...], trimesh.Trimesh]]:
    """A part's shapes merged into one mesh per colour: (rgba, mesh) in the part's frame."""
    by_colour: dict[tuple[float, ...], list[trimesh.Trimesh]] = {}
    for shape in part.shapes:
        by_colour.setdefault(tuple(shape.rgba), []).append(shape_mesh(shape))
    return [
        (rgba, meshes[0] if len(meshes) == 1 else trimesh.util.concatenate(meshes))
        for rgba, meshes in by_colour.items()
    ]


@functools.cache
def _robot_meshes() -> tuple[list[tuple[tuple[float, ...], trimesh.Trimesh]], ...]:
    return tuple(part_meshes(part) for part in PARTS)


def _root_pose(base_pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position (3,) and wxyz (4,) in `world` of `base` at odometry (x, y, yaw)."""
    x, y, yaw = (float(v) for v in base_pose)
    return np.array([x, y, 0.0]), np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def _part_frames(q: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Positions (parts, 3) m and wxyz (parts, 4) of the parts' frames in `base`."""
    T = part_poses(q, width)
    return T[:, :3, 3], np.array([quat_from_matrix(R) for R in T[:, :3, :3]])


class RobotNodes:
    """The robot's frames and meshes in a viser scene, following `RobotState`s."""

    def __init__(self, scene: viser.SceneApi, state: RobotState, *, lite: bool) -> None:
        self._q, self._width = np.asarray(state.joints.q, dtype=float), float(state.gripper.width)
        self._parts_p, self._parts_q = _part_frames(self._q, self._width)
        root_p, root_q = _root_pose(state.base_pose)
        position = np.vstack([root_p, self._parts_p])
        wxyz = np.vstack([root_q, self._parts_q])
        root = scene.add_frame(ROBOT_ROOT, show_axes=False, position=position[0], wxyz=wxyz[0])
        self._frames: dict[str, viser.FrameHandle] = {}
        for k, (part, meshes) in enumerate(zip(PARTS, _robot_meshes(), strict=True)):
            name = f"{ROBOT_ROOT}/{node_safe(part.name)}"
            pose = {"position": position[k + 1], "wxyz": wxyz[k + 1]}
            self._frames[part.name] = scene.add_frame(name, show_axes=False, **pose)
            for j, (rgba, mesh) in enumerate(meshes):
                add_mesh(scene, f"{name}/m{j}", rgba, mesh.vertices, mesh.faces, lite=lite)
        self.root = root
        self._follower = PoseFollower([root, *self._frames.values()], position, wxyz)

    @property
    def parts(self) -> list[str]:
        """The parts drawn, by name (`description.visuals.PARTS`)."""
        return list(self._frames)

    def frame(self, part: str) -> viser.FrameHandle:
        """The frame of a part, posed in `base` (KeyError if there is no such part)."""
        return self._frames[part]

    def update(self, state: RobotState, *, force: bool = False) -> int:
        """Move the frames to `state`; how many poses were sent (see `PoseFollower`)."""
        root_p, root_q = _root_pose(state.base_pose)
        q, width = np.asarray(state.joints.q, dtype=float), float(state.gripper.width)
        if np.max(np.abs(q - self._q)) > JOINT_STEP or abs(width - self._width) > JOINT_STEP:
            self._q, self._width = q, width
            self._parts_p, self._parts_q = _part_frames(q, width)
        position = np.vstack([root_p, self._parts_p])
        wxyz = np.vstack([root_q, self._parts_q])
        return self._follower.send(position, wxyz, force=force)

    def remove(self) -> None:
        """Take the robot out of the scene."""
        self.root.remove()  # its parts and their meshes go with it
