"""The viser 3D view of the robot and, when the robot offers one, the world around it.

`SceneViewer` draws the robot from its description and follows its reported state
(`robot_view.RobotNodes`, from `Robot.state()`), draws a grid on the floor for scale, and
draws the world layer a simulated robot offers (`world_layer.WorldNodes`): the room, the
furniture and the objects. A real robot offers none; what its sensors see is the fused cloud
that the operator console draws over this view. An update thread sends the moving nodes'
poses together, inside `server.atomic()`, and a status line.

Frames and units: node poses in `world` (z up), metres; quaternions (w, x, y, z), the order
viser uses.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass

import viser

from laserpick.console.default_camera import (
    CAMERA_FOV,
    CAMERA_LOOK_AT_BASE,
    CAMERA_POSITION_BASE,
    base_to_world,
    default_view_pixel,
)
from laserpick.console.robot_view import RobotNodes
from laserpick.console.world_layer import WorldLayer, WorldNodes
from laserpick.robot.interface import Robot, RobotState

__all__ = ["GRID_HALF_EXTENT", "SceneViewer", "ViewerStats", "default_view_pixel"]

log = logging.getLogger(__name__)

#: Half extent (m) of the floor grid around the `world` origin: 0.5 m cells, 1 m sections.
GRID_HALF_EXTENT = 6.0
#: Seconds between two refreshes of the status line.
STATUS_PERIOD = 0.25


@dataclass
class ViewerStats:
    """Counters of the update thread, for benchmarks and tests."""

    updates: int = 0  #: pose bursts sent
    started: float = 0.0  #: perf_counter() when the thread started (s)
    last_stamp: float = -1.0  #: robot time (s) of the last state sent

    def rate(self) -> float:
        """Mean pose-burst rate since start (Hz)."""
        elapsed = time.perf_counter() - self.started
        return self.updates / elapsed if self.started and elapsed > 0 else 0.0


class SceneViewer:
    """Draws a robot, and the world layer it may offer, in a viser server, and keeps the
    drawing in step with them.

    Usage::

        viewer = SceneViewer(robot, server, world=layer)  # world=None for a real robot
        viewer.start()   # update thread: poses at `rate_hz`, status text at ~4 Hz
        ...
        viewer.stop()

    `lite=True` draws for browsers without a GPU: no shadows, no environment lighting and
    flat toon shading. Headless Chromium's software WebGL (SwiftShader) then drew a frame of
    the isolation scene at 900 x 600 in about 60 ms instead of 200 ms, and every click waits
    for the frame in progress. The viewer has no controls: those of the 3D view are the
    operator console's, behind its door (`view_door`). The nodes are created in the
    constructor. `update()` pushes one pose burst by hand (tests, headless stepping);
    `set_robot()` swaps in a new robot and world (a scene reset).
    """

    def __init__(
        self,
        robot: Robot,
        server: viser.ViserServer,
        *,
        world: WorldLayer | None = None,
        rate_hz: float = 40.0,
        set_initial_camera: bool = True,
        lite: bool = False,
    ) -> None:
        if rate_hz <= 0:
            raise ValueError("rate_hz must be positive")
        self.server = server
        self.rate_hz = float(rate_hz)
        self.stats = ViewerStats()
        self._set_camera = set_initial_camera
        self._lite = lite
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._status: viser.GuiMarkdownHandle | None = None
        self._last_status = 0.0
        self._watched = False  #: a browser had the view open at the loop's last turn
        self.robot, self.world = robot, world
        self.robot_nodes: RobotNodes | None = None
        self.world_nodes: WorldNodes | None = None
        self._grid = self._build_grid()
        self._status = server.gui.add_markdown(self.status_text())
        self._build_scene()

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
            self._grid.remove()
            if self._status is not None:
                self._status.remove()
            self._status = None

    def set_robot(self, robot: Robot, world: WorldLayer | None = None) -> None:
        """Draw a different robot and world from now on (after a scene reset): rebuilds the
        nodes."""
        running = self._thread is not None
        self.stop()
        with self._lock:
            self._clear_scene()
            self.robot, self.world = robot, world
            self._build_scene()
        if running:
            self.start()

    def update(self, state: RobotState | None = None, *, force: bool = False) -> bool:
        """Send the moving nodes' poses for `state` (default: the robot's now) and the world's
        as one burst. Skips the burst when the robot's time has not advanced since the last
        one, unless `force`. Returns True if a burst was sent."""
        with self._lock:
            state = state if state is not None else self.robot.state()
            if not force and state.stamp == self.stats.last_stamp:
                return False
            assert self.robot_nodes is not None
            with self.server.atomic():
                self.robot_nodes.update(state, force=force)
                if self.world_nodes is not None:
                    self.world_nodes.update(force=force)
            self.stats.updates += 1
            self.stats.last_stamp = state.stamp
            return True

    def status_text(self, state: RobotState | None = None) -> str:
        """The status line: robot time (s), real-time factor, whether the world runs or is
        paused (when there is one), the e-stop, and why the scooter stopped itself, while it
        says so."""
        state = state if state is not None else self.robot.state()
        run = "" if self.world is None else " · paused" if self.world.paused else " · running"
        estop = "**E-STOP LATCHED**" if state.estopped else "e-stop clear"
        stop = f" · **{state.drive_stop}**" if state.drive_stop else ""
        return f"time {state.stamp:8.2f} s · RTF {state.rtf:4.2f}{run} · {estop}{stop}"

    # --- building -------------------------------------------------------------------------------

    def _build_grid(self) -> viser.SceneNodeHandle:
        """A grid just above the floor (z = 0 in `world`, where `base` stands) for scale."""
        return self.server.scene.add_grid(
            "/laserpick/grid",
            width=2 * GRID_HALF_EXTENT,
            height=2 * GRID_HALF_EXTENT,
            cell_size=0.5,
            section_size=1.0,
            cell_color=(175, 172, 165),
            section_color=(140, 137, 130),
            position=(0.0, 0.0, 0.001),
            shadow_opacity=0.0,
        )

    def _build_scene(self) -> None:
        scene = self.server.scene
        state = self.robot.state()
        if self.world is not None:
            self.world_nodes = WorldNodes(scene, self.world, lite=self._lite)
        self.robot_nodes = RobotNodes(scene, state, lite=self._lite)
        if self._lite:
            scene.configure_default_lights(enabled=True, cast_shadow=False)
            scene.configure_environment_map(None)
        if self._set_camera:
            cam = self.server.initial_camera
            cam.position = tuple(base_to_world(state.base_pose, CAMERA_POSITION_BASE))
            cam.look_at = tuple(base_to_world(state.base_pose, CAMERA_LOOK_AT_BASE))
            cam.up = (0.0, 0.0, 1.0)
            cam.fov = CAMERA_FOV
        self.stats.last_stamp = state.stamp

    def _clear_scene(self) -> None:
        if self.robot_nodes is not None:
            self.robot_nodes.remove()
            self.robot_nodes = None
        if self.world_nodes is not None:
            self.world_nodes.remove()
            self.world_nodes = None

    # --- the loop -------------------------------------------------------------------------------

    def _update_status(self, force: bool = False) -> None:
        now = time.perf_counter()
        if not force and now - self._last_status < STATUS_PERIOD:
            return
        self._last_status = now
        if self._status is not None:
            self._status.content = self.status_text()

    def _draw_if_watched(self) -> None:
        """Move the robot and the world while a browser has the view open; all of it at once
        when one has just opened it. Moving them for nobody took about a seventh of the
        server's interpreter time during a pick (py-spy --gil), time the event loop and the
        watchdog need. (The overlays are drawn regardless, ready ahead: they cost little
        when nothing changed.)"""
        watched = bool(self.server.get_clients())
        if watched:
            self.update(force=not self._watched)
            self._update_status(force=not self._watched)
        self._watched = watched

    def _loop(self) -> None:
        period = 1.0 / self.rate_hz
        next_t = time.perf_counter()
        while not self._stop.is_set():
            try:
                self._draw_if_watched()
            except Exception:  # the view must never take the process down
                log.exception("viewer update failed")
            next_t += period
            delay = next_t - time.perf_counter()
            if delay < -5 * period:
                next_t = time.perf_counter()  # fell behind: resync rather than burst
            elif delay > 0:
                self._stop.wait(delay)
