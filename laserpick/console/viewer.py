"""The viser 3D view of the live simulation.

`SceneViewer` turns the MuJoCo model into viser scene nodes once, then follows the simulation
by moving them. Every body that has visible geoms becomes ONE viser frame node
(`/laserpick/bodies/...` for moving bodies, `/laserpick/static/...` for bodies welded to the
world). The body's geoms are merged with trimesh into one mesh per colour and hang under that
frame with their geom-in-body transforms baked into the vertices. So a pose update is two small
messages (position, orientation) per moving body, sent together inside `server.atomic()`.

Frames and units: node poses are in `world` (z up), metres; quaternions are (w, x, y, z), the
order both MuJoCo and viser use.

Visible geoms are groups 0..3 (opaque, robot, transparent, specular; see
`laserpick.robot.sim.objects`). Group 5 (sites, markers) and anything above is not drawn. The
floor plane is drawn as a large thin box with a grid on top.

The update thread reads `Simulation.snapshot()` only; it never touches MjData.
"""

from __future__ import annotations

import logging
import math
import re
import threading
import time
from dataclasses import dataclass, field

import mujoco
import numpy as np
import trimesh
import viser

from laserpick.robot.sim.loop import Simulation, Snapshot

log = logging.getLogger(__name__)

#: Geom groups a person should see: opaque, robot, transparent, specular.
VISIBLE_GROUPS = frozenset({0, 1, 2, 3})
#: Half extent (m) of the drawn floor; MuJoCo planes are infinite or 30 m, far more than needed.
FLOOR_HALF_EXTENT = 6.0
#: Floor slab thickness (m); its top face is the plane.
FLOOR_THICKNESS = 0.02
#: Default camera in `base` (m): behind-left of the scooter and high enough to look over the
#: basket and sensor posts at the workspace in front of it. Placed for the scooter's pose.
CAMERA_POSITION_BASE = (1.95, 1.25, 1.45)
CAMERA_LOOK_AT_BASE = (1.45, -0.25, 0.45)
#: A moving body's pose is sent again once it is this far (m, rad) from the pose last sent.
#: Resting objects creep by micrometres and thousandths of a degree per step; sent at the
#: update rate, that kept the browser redrawing an idle scene (every frame, at about 150 ms
#: a frame in software WebGL) and a click waited behind those frames.
POSE_STEP_M = 0.0005
POSE_STEP_RAD = math.radians(0.25)
#: Vertical field of view of the default camera (rad).
CAMERA_FOV = math.radians(50.0)
#: MuJoCo's default geom rgba; a geom with this colour and a material takes the material's.
_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
_ROOT = "/laserpick"


@dataclass
class BodyNode:
    """One MuJoCo body drawn as one viser frame with its merged geom meshes as children."""

    body_id: int
    name: str  #: the MuJoCo body name
    node_name: str  #: the viser frame's scene-tree name
    moving: bool  #: False for bodies welded to the world: created once, never updated
    frame: viser.FrameHandle
    meshes: list[viser.MeshHandle] = field(default_factory=list)


@dataclass
class ViewerStats:
    """Counters of the update thread, for benchmarks and tests."""

    updates: int = 0  #: pose bursts sent
    started: float = 0.0  #: perf_counter() when the thread started (s)
    last_sim_time: float = -1.0  #: sim time (s) of the last snapshot sent

    def rate(self) -> float:
        """Mean pose-burst rate since start (Hz)."""
        elapsed = time.perf_counter() - self.started
        return self.updates / elapsed if self.started and elapsed > 0 else 0.0


# --- geometry -------------------------------------------------------------------------------------


def geom_mesh(model: mujoco.MjModel, g: int) -> trimesh.Trimesh | None:
    """The triangle mesh of geom `g` in its own frame (m), or None for unsupported types.

    Planes become a slab whose top face is the plane (see `FLOOR_HALF_EXTENT`); heightfields
    are skipped. Sharp edges are split (`smooth_shaded`) so that the browser's computed vertex
    normals shade boxes flat and cylinders smooth.
    """
    kind = int(model.geom_type[g])
    size = np.asarray(model.geom_size[g], dtype=float)
    G = mujoco.mjtGeom
    if kind == G.mjGEOM_PLANE:
        hx = size[0] if size[0] > 0 else FLOOR_HALF_EXTENT
        hy = size[1] if size[1] > 0 else FLOOR_HALF_EXTENT
        hx, hy = min(hx, FLOOR_HALF_EXTENT), min(hy, FLOOR_HALF_EXTENT)
        mesh = trimesh.creation.box(extents=[2 * hx, 2 * hy, FLOOR_THICKNESS])
        mesh.apply_translation([0.0, 0.0, -FLOOR_THICKNESS / 2])
        return mesh
    if kind == G.mjGEOM_BOX:
        return trimesh.creation.box(extents=2 * size).smooth_shaded
    if kind == G.mjGEOM_SPHERE:
        return trimesh.creation.icosphere(subdivisions=2, radius=size[0])
    if kind == G.mjGEOM_ELLIPSOID:
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
        mesh.apply_scale(size)
        return mesh
    if kind == G.mjGEOM_CAPSULE:
        return trimesh.creation.capsule(height=2 * size[1], radius=size[0], count=[16, 16])
    if kind == G.mjGEOM_CYLINDER:
        mesh = trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=24)
        return mesh.smooth_shaded
    if kind == G.mjGEOM_MESH:
        mid = int(model.geom_dataid[g])
        v0, nv = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
        f0, nf = int(model.mesh_faceadr[mid]), int(model.mesh_facenum[mid])
        verts = np.array(model.mesh_vert[v0 : v0 + nv], dtype=float)
        faces = np.array(model.mesh_face[f0 : f0 + nf], dtype=np.int64)
        return trimesh.Trimesh(verts, faces, process=False).smooth_shaded
    log.warning("viewer: geom %d has type %d, which is not drawn", g, kind)
    return None


def geom_rgba(model: mujoco.MjModel, g: int) -> tuple[float, float, float, float]:
    """The colour a geom is drawn in: its rgba, or its material's when it has the default."""
    rgba = tuple(float(c) for c in model.geom_rgba[g])
    mat = int(model.geom_matid[g])
    if mat >= 0 and np.allclose(rgba, _DEFAULT_RGBA):
        rgba = tuple(float(c) for c in model.mat_rgba[mat])
    return rgba  # type: ignore[return-value]


def _geom_transform(model: mujoco.MjModel, g: int) -> np.ndarray:
    """4x4 pose of geom `g` in its body's frame."""
    T = np.eye(4)
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, model.geom_quat[g])
    T[:3, :3] = R.reshape(3, 3)
    T[:3, 3] = model.geom_pos[g]
    return T


def body_meshes(
    model: mujoco.MjModel, body: int
) -> list[tuple[tuple[float, float, float, float], trimesh.Trimesh]]:
    """The visible geoms of `body` merged into one mesh per rgba, in the body's frame."""
    by_colour: dict[tuple[float, ...], list[trimesh.Trimesh]] = {}
    for g in range(model.ngeom):
        if int(model.geom_bodyid[g]) != body or int(model.geom_group[g]) not in VISIBLE_GROUPS:
            continue
        rgba = geom_rgba(model, g)
        if rgba[3] <= 0.0:
            continue
        mesh = geom_mesh(model, g)
        if mesh is None:
            continue
        mesh.apply_transform(_geom_transform(model, g))
        by_colour.setdefault(tuple(round(c, 4) for c in rgba), []).append(mesh)
    out = []
    for rgba, parts in by_colour.items():
        merged = parts[0] if len(parts) == 1 else trimesh.util.concatenate(parts)
        out.append((rgba, merged))  # type: ignore[arg-type]
    return out  # type: ignore[return-value]


def _node_name(model: mujoco.MjModel, body: int, moving: bool) -> str:
    """A viser scene-tree name for a body. '/' in MuJoCo names would nest nodes, so it goes."""
    raw = model.body(body).name or f"body{body}"
    safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", raw)
    return f"{_ROOT}/{'bodies' if moving else 'static'}/{body:03d}_{safe}"


def is_moving(model: mujoco.MjModel, body: int) -> bool:
    """True if the body can move in `world`: it is not welded to the world body, or is mocap."""
    return int(model.body_weldid[body]) != 0 or int(model.body_mocapid[body]) >= 0


# --- the viewer -----------------------------------------------------------------------------------


def _base_to_world(base_pose: np.ndarray, p: tuple[float, float, float]) -> np.ndarray:
    """A point given in `base` in `world`, for the scooter at (x, y, yaw)."""
    x, y, yaw = (float(v) for v in base_pose)
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([x + c * p[0] - s * p[1], y + s * p[0] + c * p[1], p[2]])


class SceneViewer:
    """Draws a `Simulation` in a viser server and keeps the drawing in step with it.

    Usage::

        viewer = SceneViewer(sim, server)
        viewer.start()   # update thread: poses at `rate_hz`, status text at ~4 Hz
        ...
        viewer.stop()

    `lite=True` draws for browsers without a GPU: no shadows, no environment lighting and
    flat toon shading. Headless Chromium's software WebGL (SwiftShader) then drew a frame of
    the isolation scene at 900 x 600 in about 60 ms instead of 200 ms on this machine (when
    measured; it varies with the machine's load several fold), and every click waits for the
    frame in progress. `controls=False` leaves out the Pause/Resume
    button (a view-only console, for a port that is reachable from other hosts). The nodes are
    created in the constructor. `update()` pushes one pose burst by hand (tests, headless
    stepping); `set_simulation()` swaps in a new Simulation (a scene reset).
    """

    def __init__(
        self,
        sim: Simulation,
        server: viser.ViserServer,
        *,
        rate_hz: float = 40.0,
        set_initial_camera: bool = True,
        controls: bool = True,
        lite: bool = False,
    ) -> None:
        if rate_hz <= 0:
            raise ValueError("rate_hz must be positive")
        self.server = server
        self.rate_hz = float(rate_hz)
        self.stats = ViewerStats()
        self._set_camera = set_initial_camera
        self._controls = controls
        self._lite = lite
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._bodies: dict[str, BodyNode] = {}
        self._moving: list[BodyNode] = []
        self._sent_pos = np.zeros((0, 3))  #: the moving bodies' poses last sent (m, `world`)
        self._sent_quat = np.zeros((0, 4))
        self._decor: list[viser.SceneNodeHandle] = []
        self._status: viser.GuiMarkdownHandle | None = None
        self._pause: viser.GuiButtonHandle | None = None
        self._last_status = 0.0
        self.sim = sim
        self._build_gui()
        self._build_scene(sim)

    # --- public ----------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the update thread (idempotent)."""
        if self._thread is not None:
            return
        self._stop.clear()
        self.stats = ViewerStats(started=time.perf_counter())
        self._thread = threading.Thread(target=self._loop, name="laserpick-viewer", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the update thread and wait for it (the nodes stay in the scene)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None

    def close(self) -> None:
        """Stop, and remove every node and GUI element this viewer made."""
        self.stop()
        with self._lock:
            self._clear_scene()
            for handle in (self._status, self._pause):
                if handle is not None:
                    handle.remove()
            self._status = self._pause = None

    def set_simulation(self, sim: Simulation) -> None:
        """Draw a different Simulation from now on (after a scene reset). Rebuilds all nodes."""
        running = self._thread is not None
        self.stop()
        with self._lock:
            self._clear_scene()
            self.sim = sim
            self._build_scene(sim)
            self._refresh_pause_label()
        if running:
            self.start()

    def body_handle(self, name: str) -> viser.FrameHandle:
        """The viser frame drawing the MuJoCo body `name` (KeyError if it is not drawn)."""
        return self._bodies[name].frame

    @property
    def moving_bodies(self) -> list[str]:
        """Names of the bodies whose poses the update thread follows."""
        return [b.name for b in self._moving]

    @property
    def static_bodies(self) -> list[str]:
        """Names of the bodies drawn once at their start pose."""
        return [b.name for b in self._bodies.values() if not b.moving]

    def update(self, snap: Snapshot | None = None, *, force: bool = False) -> bool:
        """Send the moving bodies' poses from `snap` (default: the latest) as one burst.

        Skips the burst when the sim time has not advanced since the last one, unless `force`.
        Returns True if a burst was sent.
        """
        with self._lock:
            snap = snap if snap is not None else self.sim.snapshot()
            if not force and snap.time == self.stats.last_sim_time:
                return False
            ids = [node.body_id for node in self._moving]
            xpos, xquat = snap.xpos[ids], snap.xquat[ids]
            moved = np.ones(len(ids), bool) if force else self._moved(xpos, xquat)
            with self.server.atomic():
                for k in np.flatnonzero(moved):
                    self._moving[k].frame.position = xpos[k]
                    self._moving[k].frame.wxyz = xquat[k]
            self._sent_pos[moved] = xpos[moved]
            self._sent_quat[moved] = xquat[moved]
            self.stats.updates += 1
            self.stats.last_sim_time = snap.time
            return True

    def _moved(self, xpos: np.ndarray, xquat: np.ndarray) -> np.ndarray:
        """Which moving bodies are POSE_STEP_M or POSE_STEP_RAD from the pose last sent."""
        shift = np.linalg.norm(xpos - self._sent_pos, axis=1)
        dot = np.clip(np.abs(np.sum(xquat * self._sent_quat, axis=1)), 0.0, 1.0)
        return (shift > POSE_STEP_M) | (2.0 * np.arccos(dot) > POSE_STEP_RAD)

    def status_text(self, snap: Snapshot | None = None) -> str:
        """The status line: sim time (s), real-time factor, run state and e-stop state, and
        why the scooter stopped itself, while it says so."""
        snap = snap if snap is not None else self.sim.snapshot()
        state = "paused" if self.sim.paused else "running"
        estop = "**E-STOP LATCHED**" if snap.estopped else "e-stop clear"
        stop = f" · **{snap.drive_stop}**" if snap.drive_stop else ""
        return f"sim time {snap.time:8.2f} s · RTF {snap.rtf:4.2f} · {state} · {estop}{stop}"

    # --- building -------------------------------------------------------------------------------

    def _build_gui(self) -> None:
        gui = self.server.gui
        self._status = gui.add_markdown(self.status_text())
        if not self._controls:
            return
        self._pause = gui.add_button("Pause", icon=viser.Icon.PLAYER_PAUSE)

        @self._pause.on_click
        def _(_: viser.GuiEvent) -> None:
            if self.sim.paused:
                self.sim.resume()
            else:
                self.sim.pause()
            self._refresh_pause_label()
            self._update_status(force=True)

    def _refresh_pause_label(self) -> None:
        if self._pause is None:
            return
        paused = self.sim.paused
        self._pause.label = "Resume" if paused else "Pause"
        self._pause.icon = viser.Icon.PLAYER_PLAY if paused else viser.Icon.PLAYER_PAUSE

    def _build_scene(self, sim: Simulation) -> None:
        model = sim.model
        snap = sim.snapshot()
        scene = self.server.scene
        for body in range(model.nbody):
            parts = body_meshes(model, body)
            if not parts:
                continue
            moving = is_moving(model, body)
            name = _node_name(model, body, moving)
            frame = scene.add_frame(
                name, show_axes=False, position=snap.xpos[body], wxyz=snap.xquat[body]
            )
            node = BodyNode(body, model.body(body).name, name, moving, frame)
            for k, (rgba, mesh) in enumerate(parts):
                opacity = None if rgba[3] >= 0.999 else float(rgba[3])
                node.meshes.append(
                    scene.add_mesh_simple(
                        f"{name}/m{k}",
                        vertices=np.asarray(mesh.vertices, dtype=np.float32),
                        faces=np.asarray(mesh.faces, dtype=np.uint32),
                        color=tuple(round(255 * c) for c in rgba[:3]),
                        opacity=opacity,
                        side="double" if opacity is not None else "front",
                        material="toon3" if self._lite else "standard",
                        cast_shadow=opacity is None and not self._lite,
                        receive_shadow=False if self._lite else 0.3 if body == 0 else True,
                    )
                )
            self._bodies[node.name] = node
            if moving:
                self._moving.append(node)
        ids = [node.body_id for node in self._moving]
        self._sent_pos, self._sent_quat = snap.xpos[ids].copy(), snap.xquat[ids].copy()
        if self._lite:
            scene.configure_default_lights(enabled=True, cast_shadow=False)
            scene.configure_environment_map(None)
        # A grid just above the floor for scale: 0.5 m cells, 1 m sections.
        if any(int(model.geom_type[g]) == mujoco.mjtGeom.mjGEOM_PLANE for g in range(model.ngeom)):
            self._decor.append(
                scene.add_grid(
                    f"{_ROOT}/grid",
                    width=2 * FLOOR_HALF_EXTENT,
                    height=2 * FLOOR_HALF_EXTENT,
                    cell_size=0.5,
                    section_size=1.0,
                    cell_color=(175, 172, 165),
                    section_color=(140, 137, 130),
                    position=(0.0, 0.0, 0.001),
                    shadow_opacity=0.0,
                )
            )
        if self._set_camera:
            cam = self.server.initial_camera
            cam.position = tuple(_base_to_world(snap.base_pose, CAMERA_POSITION_BASE))
            cam.look_at = tuple(_base_to_world(snap.base_pose, CAMERA_LOOK_AT_BASE))
            cam.up = (0.0, 0.0, 1.0)
            cam.fov = CAMERA_FOV
        self.stats.last_sim_time = snap.time

    def _clear_scene(self) -> None:
        for node in self._bodies.values():
            node.frame.remove()  # removes the child meshes with it
        for handle in self._decor:
            handle.remove()
        self._bodies.clear()
        self._moving.clear()
        self._decor.clear()
        self._sent_pos, self._sent_quat = np.zeros((0, 3)), np.zeros((0, 4))

    # --- the loop -------------------------------------------------------------------------------

    def _update_status(self, force: bool = False) -> None:
        now = time.perf_counter()
        if not force and now - self._last_status < 0.25:
            return
        self._last_status = now
        if self._status is not None:
            self._status.content = self.status_text()

    def _loop(self) -> None:
        period = 1.0 / self.rate_hz
        next_t = time.perf_counter()
        while not self._stop.is_set():
            try:
                self.update()
                self._update_status()
            except Exception:  # the view must never take the process down
                log.exception("viewer update failed")
            next_t += period
            delay = next_t - time.perf_counter()
            if delay < -5 * period:
                next_t = time.perf_counter()  # fell behind: resync rather than burst
            elif delay > 0:
                self._stop.wait(delay)


def default_view_pixel(point_base: np.ndarray, width: float, height: float) -> tuple[float, float]:
    """Where a point (m, `base`) appears in the default camera's view of `width` x `height`
    px (a pinhole with the vertical field of view CAMERA_FOV, as three.js draws it): (x, y)
    px from the top-left. For scripted clicks in tests and benchmarks."""
    eye, at = np.array(CAMERA_POSITION_BASE), np.array(CAMERA_LOOK_AT_BASE)
    forward = (at - eye) / np.linalg.norm(at - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(point_base, dtype=float) - eye
    x, y, z = d @ right, d @ up, d @ forward
    t = math.tan(CAMERA_FOV / 2)
    return (0.5 + 0.5 * x / (z * t * width / height)) * width, (0.5 - 0.5 * y / (z * t)) * height
