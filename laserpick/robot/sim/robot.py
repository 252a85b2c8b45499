"""`SimRobot`: the simulated scooter robot behind the `Robot` interface.

It joins the simulation loop, the five depth cameras and the laser pointer. Frames are
rendered on one dedicated capture thread (an EGL context belongs to the thread that made it)
from a snapshot of the state, so capturing never blocks the physics.
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.gl_backend import choose_gl_backend
from laserpick.robot.interface import GripperState, JointState, MotionHandle, RobotState
from laserpick.robot.sim.laser import SimLaser
from laserpick.robot.sim.loop import Simulation, Snapshot
from laserpick.robot.sim.model import camera_rotation
from laserpick.robot.sim.scenes import Scene
from laserpick.robot.sim.sensors import CAM_TO_OPTICAL, DepthCameras
from laserpick.settings import Settings, get_settings
from laserpick.transforms import make_transform, pinhole_intrinsics
from laserpick.types import DepthFrame, Projector, Trajectory


class SimRobot:
    """A `Robot` backed by MuJoCo. `realtime=False` gives the deterministic headless mode.

    Built only where MuJoCo can render (`gl_backend.choose_gl_backend`, GLBackendError
    otherwise): its cameras are what the session perceives with."""

    def __init__(
        self, scene: Scene | None, *, realtime: bool = True, settings: Settings | None = None
    ) -> None:
        choose_gl_backend()
        self.settings = settings or get_settings()
        self.sim = Simulation(scene, realtime=realtime, settings=self.settings)
        self.laser = SimLaser(self.sim.model)
        self._laser_lock = threading.Lock()
        self._capture_pool = ThreadPoolExecutor(
            max_workers=1, thread_name_prefix="laserpick-capture"
        )
        self._local = threading.local()
        if realtime:
            self.sim.start()

    @property
    def model(self) -> mujoco.MjModel:
        return self.sim.model

    @property
    def realtime(self) -> bool:
        return self.sim.realtime

    def close(self) -> None:
        self.sim.close()
        self._capture_pool.submit(self._close_cameras).result()
        self._capture_pool.shutdown(wait=True)

    # --- sensing --------------------------------------------------------------------------------

    def capture(self) -> list[DepthFrame]:
        """All five frames at the latest snapshot, laser dots drawn where they are visible."""
        return self._capture_pool.submit(self._render, self.sim.snapshot(), False).result()[0]

    def capture_with_labels(self) -> tuple[list[DepthFrame], list[np.ndarray]]:
        """Frames plus per-pixel geom ids. Ground truth: for tests and bench scoring only."""
        return self._capture_pool.submit(self._render, self.sim.snapshot(), True).result()

    def reseed_sensors(self, seed: int | np.random.SeedSequence) -> None:
        """Draw the cameras' noise from here on as from a fresh start with `seed` (the bench
        seeds each task's draws apart from the tasks before it)."""
        self._capture_pool.submit(lambda: self._thread_state()[0].reseed(seed)).result()

    def laser_hits(self, snap: Snapshot | None = None) -> list[np.ndarray]:
        """World points where the lit beams land now (simulator truth; for display and scoring)."""
        snap = snap or self.sim.snapshot()
        return self._capture_pool.submit(self._cast, snap).result()

    def projector(self) -> Projector:
        """The scooter's projector as a virtual camera in `base` (its calibration)."""
        R = camera_rotation(dims.PROJECTOR_PITCH_DOWN, dims.PROJECTOR_YAW) @ CAM_TO_OPTICAL
        K = pinhole_intrinsics(dims.PROJECTOR_WIDTH, dims.PROJECTOR_HEIGHT, dims.PROJECTOR_FOVY)
        T = make_transform(R, np.asarray(dims.PROJECTOR_POS, dtype=float))
        return Projector(K, T, dims.PROJECTOR_WIDTH, dims.PROJECTOR_HEIGHT)

    def joint_state(self) -> JointState:
        s = self.sim.snapshot()
        return JointState(q=s.arm_q.copy(), qd=s.arm_qd.copy(), stamp=s.time)

    def gripper_state(self) -> GripperState:
        s = self.sim.snapshot()
        return GripperState(
            width=s.gripper_width,
            force=s.gripper_force,
            closed=s.gripper_closed,
            holding=s.holding,
            moving=s.gripper_moving,
        )

    def base_pose(self) -> np.ndarray:
        return self.sim.snapshot().base_pose.copy()

    def state(self) -> RobotState:
        s = self.sim.snapshot()
        return RobotState(
            stamp=s.time,
            joints=JointState(q=s.arm_q.copy(), qd=s.arm_qd.copy(), stamp=s.time),
            gripper=GripperState(
                width=s.gripper_width,
                force=s.gripper_force,
                closed=s.gripper_closed,
                holding=s.holding,
                moving=s.gripper_moving,
            ),
            base_pose=s.base_pose.copy(),
            base_velocity=s.base_velocity.copy(),
            estopped=s.estopped,
            moving=s.moving,
            drive_stop=s.drive_stop,
            rtf=s.rtf,
            read_at=s.taken_at,
        )

    # --- acting -----------------------------------------------------------------------------------

    def execute(self, traj: Trajectory) -> MotionHandle:
        return self.sim.execute(traj)

    def wait(self, handle: MotionHandle, timeout: float) -> str:
        """Real time: wait on the handle. Headless: step the simulation until it ends."""
        if self.sim.realtime:
            return handle.wait(timeout)
        return self.sim.run_until(handle, timeout)

    def sleep(self, seconds: float) -> None:
        if self.sim.realtime:
            time.sleep(seconds)
        else:
            self.sim.settle(seconds)

    def move_tcp(self, T_base_tcp: np.ndarray, timeout: float = 10.0) -> MotionHandle:
        """Cartesian move of the TCP to a pose in `base` (mink IK)."""
        return self.sim.move_tcp(T_base_tcp, timeout)

    def gripper(self, close: bool) -> None:
        self.sim.gripper(close)

    def drive(self, v: float, w: float, duration: float = 0.5) -> None:
        self.sim.drive(v, w, duration)

    def halt(self) -> None:
        self.sim.halt()

    def deadman(self, until: float | None) -> None:
        self.sim.deadman(until)

    def stop(self) -> None:
        self.sim.stop()

    def reset_stop(self) -> None:
        self.sim.reset_stop()

    # --- the capture thread -----------------------------------------------------------------------

    def _thread_state(self) -> tuple[DepthCameras, mujoco.MjData]:
        if not hasattr(self._local, "cams"):
            self._local.cams = DepthCameras(self.sim.model, self.settings.sensor)
            self._local.data = mujoco.MjData(self.sim.model)
        return self._local.cams, self._local.data

    def _cast(self, snap: Snapshot) -> list[np.ndarray]:
        _, data = self._thread_state()
        data.qpos[:] = snap.qpos
        mujoco.mj_kinematics(self.sim.model, data)
        with self._laser_lock:
            hits = self.laser.cast(self.sim.model, data)
        return [h for h in hits if h is not None]

    def _render(self, snap: Snapshot, labels: bool):
        cams, _ = self._thread_state()
        hits = self._cast(snap)
        if labels:
            return cams.capture_with_labels(snap.qpos, snap.time, hits)
        return cams.capture(snap.qpos, snap.time, hits), None

    def _close_cameras(self) -> None:
        if hasattr(self._local, "cams"):
            self._local.cams.close()
