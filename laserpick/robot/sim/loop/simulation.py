"""The MuJoCo loop: one thread owns MjData and steps it; everyone else sends commands or reads
snapshots.

Real-time mode steps at `settings.sim.rate_hz` against the wall clock, in chunks of 20 ms, and
can be paused. Headless mode has no thread: the caller steps it as fast as it can, and the
result depends only on the commands and the seed.

Commands (`execute`, `move_tcp`, `gripper`, `drive`, `stop`, ...) may come from any thread.
They are queued and applied by the sim thread before its next physics step, so the e-stop acts
within one step (2 ms at 500 Hz). Nothing a command does can raise inside the loop: a command
that fails marks its handle failed and the loop steps on.

The dead-man (`deadman`) is checked by the sim thread at every physics step, against the wall
time (`time.monotonic()`) that step stands for, so it trips within one step of its deadline
whatever the threads that arm it are doing.
"""

from __future__ import annotations

import logging
import math
import queue
import threading
import time
from collections.abc import Callable

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.interface import DEADMAN_STOP, MotionHandle, MotionStatus
from laserpick.robot.sim.arm_control import CartesianController, TrajectoryTracker
from laserpick.robot.sim.loop.contacts import (
    Contact,
    arm_contacts,
    contact_stop,
    contacts_on,
    felt_force,
)
from laserpick.robot.sim.loop.drive import BaseDrive
from laserpick.robot.sim.loop.gripper import GripperDrive
from laserpick.robot.sim.loop.snapshot import Snapshot, take_snapshot
from laserpick.robot.sim.model import ModelInfo, build_arm_model, build_sim_model
from laserpick.robot.sim.scenes import Scene
from laserpick.settings import Settings, get_settings
from laserpick.types import Trajectory

log = logging.getLogger(__name__)

#: Physics steps per real-time chunk: 10 steps = 20 ms at 500 Hz.
_CHUNK_STEPS = 10


class Simulation:
    """Owner of MjModel/MjData and the control laws that drive them."""

    def __init__(
        self,
        scene: Scene | None,
        *,
        realtime: bool = True,
        settings: Settings | None = None,
    ) -> None:
        self.settings = settings or get_settings()
        self.scene = scene
        self.realtime = realtime
        self.model = build_sim_model(scene)
        self.data = mujoco.MjData(self.model)
        self.info = ModelInfo.of(self.model)
        # Which geoms are the arm's (gripper and pads included), and which the pads: masks
        # over the model's geoms, as the contact checks of every control tick use them.
        self._arm_geoms = np.zeros(self.model.ngeom, bool)
        self._arm_geoms[self.info.arm_geoms] = True
        self._pad_geoms = np.zeros(self.model.ngeom, bool)
        self._pad_geoms[self.info.pad_geoms] = True
        self._grip = GripperDrive(kp=float(self.model.actuator_gainprm[self.info.gripper_ctrl, 0]))
        self.arm_model = build_arm_model()
        self._cartesian = CartesianController(self.arm_model)
        self.dt = float(self.model.opt.timestep)
        self._control_every = max(
            1, round(self.settings.sim.rate_hz / self.settings.sim.control_rate_hz)
        )
        self._lock = threading.RLock()
        self._inbox: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._running = threading.Event()
        self._paused = threading.Event()
        self._snapshot_listeners: list[Callable[[Snapshot], None]] = []
        self._rtf = 0.0
        #: The wall clock against sim time: (time.monotonic() s, data.time s) at one instant.
        self._clock: tuple[float, float] | None = None
        self._deadman_until: float | None = None  #: owned by the sim thread
        self.deadman_tripped = False
        self.reset()

    # --- lifecycle ------------------------------------------------------------------------------

    def reset(self) -> None:
        """Back to the scene's start: scooter at its start pose, arm home, gripper open."""
        with self._lock:
            m, d, info = self.model, self.data, self.info
            mujoco.mj_resetData(m, d)
            if self.scene is not None:
                x, y, yaw = self.scene.scooter_pose
                d.qpos[info.base_qpos] = [x, y, yaw]
            d.qpos[info.arm_qpos] = dims.UR5_HOME_Q
            d.qpos[info.finger_qpos] = dims.GRIPPER_STROKE / 2
            self._q_set = dims.UR5_HOME_Q.copy()
            d.ctrl[info.arm_ctrl] = self._q_set
            self._grip.reset()
            d.ctrl[info.gripper_ctrl] = self._grip.setpoint
            self._motion: TrajectoryTracker | CartesianController | None = None
            self._handle: MotionHandle | None = None
            self._cartesian.target = None
            self._cart_tol = (0.001, math.radians(0.5))
            self._cart_deadline = 0.0
            self._drive = BaseDrive(m, d, info)
            self.estopped = False
            self._steps = 0
            mujoco.mj_forward(m, d)
            self._publish()

    def start(self) -> None:
        """Start the real-time loop thread."""
        if not self.realtime:
            raise RuntimeError("a headless simulation is stepped by its caller; use step()")
        if self._thread is not None:
            return
        self._running.set()
        self._thread = threading.Thread(target=self._loop, name="laserpick-sim", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop the loop thread (if any) and wait for it."""
        self._running.clear()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None

    def pause(self) -> None:
        self._paused.set()

    def resume(self) -> None:
        self._paused.clear()

    @property
    def paused(self) -> bool:
        return self._paused.is_set()

    def on_snapshot(self, fn: Callable[[Snapshot], None]) -> None:
        """Call `fn(snapshot)` from the sim thread after each published chunk. Keep it quick."""
        self._snapshot_listeners.append(fn)

    # --- reading --------------------------------------------------------------------------------

    def snapshot(self) -> Snapshot:
        """The latest published state (a new object each chunk; never mutated)."""
        return self._snap

    # --- commands (any thread) -------------------------------------------------------------------

    def execute(self, traj: Trajectory) -> MotionHandle:
        """Track a joint trajectory from now. Refused while e-stopped."""
        handle = MotionHandle("trajectory")

        def apply() -> None:
            if self._refuse_when_stopped(handle):
                return
            start = self.data.qpos[self.info.arm_qpos]
            if np.max(np.abs(traj.q[0] - start)) > 0.05:
                handle.finish("failed", "trajectory does not start at the current joint angles")
                return
            self._replace_motion(TrajectoryTracker(traj, self.data.time), handle)

        self._post(apply)
        return handle

    def move_tcp(self, T_base_tcp: np.ndarray, timeout: float = 10.0) -> MotionHandle:
        """Move the TCP to a pose in `base` with mink IK; fails after `timeout` sim seconds."""
        handle = MotionHandle("cartesian")
        target = np.array(T_base_tcp, dtype=float)

        def apply() -> None:
            if self._refuse_when_stopped(handle):
                return
            try:
                self._cartesian.set_target(target)
            except ValueError as exc:
                handle.finish("failed", str(exc))
                return
            self._cart_deadline = self.data.time + timeout
            self._replace_motion(self._cartesian, handle)

        self._post(apply)
        return handle

    def gripper(self, close: bool) -> None:
        """Close (to the force limit) or open fully. Opening is allowed under e-stop."""

        def apply() -> None:
            if close and (self.estopped or self.deadman_tripped):
                return
            self._grip.command(close, self._finger())

        self._post(apply)

    def drive(self, v: float, w: float, duration: float = 0.5) -> None:
        """Drive the base at v (m/s) and w (rad/s) for at most `duration` s (a dead-man).

        Values are clamped to the base limits in `dims`; the ramp respects its acceleration
        limits. Refused while e-stopped.
        """
        if not (math.isfinite(v) and math.isfinite(w) and math.isfinite(duration)):
            raise ValueError("drive command must be finite")
        v = float(np.clip(v, -dims.BASE_V_MAX, dims.BASE_V_MAX))
        w = float(np.clip(w, -dims.BASE_W_MAX, dims.BASE_W_MAX))
        duration = float(np.clip(duration, 0.0, 0.5))

        def apply() -> None:
            if self.estopped or self.deadman_tripped:
                return
            self._drive.drive(v, w, duration)

        self._post(apply)

    def halt(self) -> None:
        """Stop arm and base motion now, without latching (cancel, watchdog)."""
        self._post(lambda: self._halt("stopped", "halted"))

    def deadman(self, until: float | None) -> None:
        """Halt arm and base once the wall clock (`time.monotonic()`, s) passes `until`, and
        refuse motion from then until disarmed with None. Only the real-time loop has a wall
        clock: headless, it is never due."""

        def apply() -> None:
            self._deadman_until = until
            if until is None:
                self.deadman_tripped = False

        self._post(apply)

    def stop(self) -> None:
        """E-stop: halt arm and base within one step and refuse motion until `reset_stop`."""

        def apply() -> None:
            self.estopped = True
            self._halt("stopped", "e-stop")

        self._post(apply)

    def reset_stop(self) -> None:
        """Release a latched e-stop."""

        def apply() -> None:
            self.estopped = False

        self._post(apply)

    def call(self, fn: Callable[[mujoco.MjModel, mujoco.MjData], object]) -> object:
        """Run `fn(model, data)` in the sim thread between steps and return its result."""
        box: list[object] = []
        err: list[BaseException] = []
        done = threading.Event()

        def apply() -> None:
            try:
                box.append(fn(self.model, self.data))
            except BaseException as exc:  # handed back to the caller, never raised in the loop
                err.append(exc)
            done.set()

        self._post(apply)
        if self._thread is not None and not done.wait(5.0):
            raise TimeoutError("the simulation thread did not run the call within 5 s")
        if err:
            raise err[0]
        return box[0] if box else None

    # --- headless stepping -----------------------------------------------------------------------

    def step(self, n: int = 1) -> None:
        """Advance n physics steps in the calling thread (headless mode, or a paused loop)."""
        if self._thread is not None and not self.paused:
            raise RuntimeError("the real-time loop is running; pause it before stepping by hand")
        with self._lock:
            for _ in range(n):
                self._step_once()
            self._publish()

    def run_until(self, handle: MotionHandle, max_seconds: float) -> MotionStatus:
        """Headless: step until `handle` finishes or `max_seconds` of sim time pass."""
        end = self.data.time + max_seconds
        while not handle.done() and self.data.time < end:
            self.step(_CHUNK_STEPS)
        return handle.status

    def settle(self, seconds: float) -> None:
        """Headless: step for `seconds` of sim time."""
        self.step(max(1, round(seconds / self.dt)))

    # --- the loop ------------------------------------------------------------------------

    def _post(self, fn: Callable[[], None]) -> None:
        if self._thread is None:
            with self._lock:
                fn()
        else:
            self._inbox.put(fn)

    def _loop(self) -> None:
        chunk_sim = _CHUNK_STEPS * self.dt
        wall0, sim0 = time.monotonic(), self.data.time
        rtf_wall, rtf_sim = wall0, sim0
        while self._running.is_set():
            self._clock = (wall0, sim0)
            if self._paused.is_set():
                self._drain()
                self._deadman_check()
                time.sleep(0.01)
                wall0, sim0 = time.monotonic(), self.data.time
                continue
            with self._lock:
                for _ in range(_CHUNK_STEPS):
                    self._step_once()
                self._publish()
            now = time.monotonic()
            if now - rtf_wall >= 0.5:
                self._rtf = (self.data.time - rtf_sim) / (now - rtf_wall)
                rtf_wall, rtf_sim = now, self.data.time
            lag = (wall0 + (self.data.time - sim0)) - now
            if lag > 0:
                time.sleep(lag)
            elif lag < -10 * chunk_sim:
                # Fell behind (a slow machine, a debugger): catch up from here, not in a burst.
                wall0, sim0 = now, self.data.time

    def _stands_for(self) -> float:
        """The wall time (`time.monotonic()` s) the state now stands for: in real time its
        place on the loop's clock (a chunk is computed ahead of the clock, or behind it on a
        slow machine); headless, now."""
        if self._clock is None:
            return time.monotonic()
        wall0, sim0 = self._clock
        return wall0 + (self.data.time - sim0)

    def _deadman_check(self) -> None:
        """Trip the dead-man once this step stands for a time past its deadline, or is
        computed after it (a loop behind the clock)."""
        until = self._deadman_until
        if until is None or self.deadman_tripped or self._clock is None:
            return
        if max(time.monotonic(), self._stands_for()) >= until:
            self.deadman_tripped = True
            self._drive.halted(DEADMAN_STOP)
            self._halt("stopped", DEADMAN_STOP)

    def _drain(self) -> None:
        while True:
            try:
                fn = self._inbox.get_nowait()
            except queue.Empty:
                return
            try:
                fn()
            except Exception:  # a bad command must never take the loop down
                log.exception("command failed in the sim thread")

    def _step_once(self) -> None:
        self._drain()
        self._deadman_check()
        if self._steps % self._control_every == 0:
            self._control_tick()
        mujoco.mj_step(self.model, self.data)
        self._steps += 1

    def _control_tick(self) -> None:
        d, info = self.data, self.info
        dt = self._control_every * self.dt
        motion, handle = self._motion, self._handle
        if motion is not None and handle is not None:
            try:
                if isinstance(motion, TrajectoryTracker):
                    self._q_set = motion.setpoint(d.time)
                    for event in motion.due_events(d.time):
                        self._grip.command(event.action == "close", self._finger())
                    if self._stop_on_contact(motion.traj.guard_force):
                        return
                    if motion.finished(d.time):
                        self._end_motion("done")
                else:
                    if self._stop_on_contact(None):
                        return
                    q = d.qpos[info.arm_qpos].copy()
                    self._q_set = motion.step(self._q_set, dt)
                    pos_err, rot_err = motion.error(q)
                    if pos_err < self._cart_tol[0] and rot_err < self._cart_tol[1]:
                        self._end_motion("done")
                    elif d.time > self._cart_deadline:
                        self._end_motion(
                            "failed", f"TCP target not reached ({pos_err * 1000:.1f} mm off)"
                        )
            except Exception as exc:
                log.exception("arm control failed")
                self._halt("failed", f"arm control failed: {exc}")
        d.ctrl[info.arm_ctrl] = self._q_set
        d.ctrl[info.gripper_ctrl] = self._grip.tick(dt)
        self._drive.tick(dt, self._motion is None, self.arm_contacts)

    def _replace_motion(
        self, motion: TrajectoryTracker | CartesianController, handle: MotionHandle
    ) -> None:
        if self._handle is not None:
            self._handle.finish("stopped", "replaced by a new motion")
        self._motion, self._handle = motion, handle
        self._q_set = self.data.qpos[self.info.arm_qpos].copy()

    def _end_motion(self, status: MotionStatus, message: str = "") -> None:
        if self._handle is not None:
            self._handle.finish(status, message)
        self._motion, self._handle = None, None

    def _stop_on_contact(self, guard_force: float | None) -> bool:
        """Halt the motion, failed, where the contacts on the arm trip its guard (N) or the
        protective stop (`contacts.contact_stop`); whether it did."""
        reason = contact_stop(self.model, self.arm_contacts(), guard_force)
        if reason is None:
            return False
        self._halt("failed", reason)
        return True

    def _halt(self, status: MotionStatus, message: str) -> None:
        """Hold the arm where it is and stop the base, at once."""
        d, info = self.data, self.info
        self._end_motion(status, message)
        self._q_set = d.qpos[info.arm_qpos].copy()
        d.ctrl[info.arm_ctrl] = self._q_set
        # The UR5's brakes and the scooter's motor brake: motion stops this step.
        d.qvel[info.arm_dof] = 0.0
        self._drive.stop()

    def _refuse_when_stopped(self, handle: MotionHandle) -> bool:
        if self.estopped:
            handle.finish("failed", "e-stop is latched; reset it first")
            return True
        if self.deadman_tripped:
            handle.finish("failed", DEADMAN_STOP)
            return True
        return False

    # --- contacts (sim thread, or through `call`) ---------------------------------------------

    def contacts(self, geoms: np.ndarray, *, from_outside: bool = False) -> list[Contact]:
        """The contacts now on `geoms` (a mask over the model's geoms), as
        `contacts.contacts_on` gives them."""
        return contacts_on(self.model, self.data, geoms, from_outside=from_outside)

    def arm_contacts(self) -> list[Contact]:
        """The contacts from outside on the arm, the gripper and what a closed gripper holds
        (`contacts.arm_contacts`)."""
        return arm_contacts(
            self.model, self.data, self._arm_geoms, self._pad_geoms, self._grip.closed
        )

    def felt(self, contacts: list[Contact]) -> float:
        """What the UR5's force estimate reads of `contacts` (N; `contacts.felt_force`)."""
        return felt_force(self.model, contacts)

    def _finger(self) -> float:
        """Where the driven finger stands (m, its travel from the hand's centre)."""
        return float(self.data.qpos[self.info.finger_qpos[0]])

    def _gripper_force(self) -> float:
        """Force (N) on the pads: what the gripper's own current sensing reports."""
        return sum(c.normal for c in self.contacts(self._pad_geoms))

    def _publish(self) -> None:
        snap = take_snapshot(
            self.data,
            self.info,
            gripper_force=self._gripper_force(),
            gripper_closed=self._grip.closed,
            gripper_moving=self._grip.moving(self._finger()),
            estopped=self.estopped,
            moving=self._handle is not None,
            drive_stop=self._drive.stop_reason,
            rtf=self._rtf,
            taken_at=time.time() + (self._stands_for() - time.monotonic()),
        )
        self._snap = snap
        for fn in self._snapshot_listeners:
            try:
                fn(snap)
            except Exception:
                log.exception("snapshot listener failed")
