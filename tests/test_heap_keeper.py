"""The session's heap keeper (`laserpick.server.session.heap_keeper`): what a job freed goes
back to the system once the robot is at rest, never while anything moves."""

from __future__ import annotations

import threading
import time
from types import SimpleNamespace

import numpy as np

from laserpick.robot.interface import GripperState, JointState, RobotState
from laserpick.server.session import heap_keeper
from laserpick.server.session.heap_keeper import HeapKeeper, at_rest


def reading(*, moving: bool = False, qd: float = 0.0, base: float = 0.0) -> RobotState:
    return RobotState(
        stamp=0.0,
        joints=JointState(q=np.zeros(6), qd=np.full(6, qd), stamp=0.0),
        gripper=GripperState(width=0.08, force=0.0, closed=False, holding=False),
        base_pose=np.zeros(3),
        base_velocity=np.array([base, 0.0]),
        estopped=False,
        moving=moving,
        drive_stop="",
        rtf=1.0,
        read_at=0.0,
    )


def test_at_rest_only_when_no_motion_runs_and_nothing_turns_or_rolls() -> None:
    assert at_rest(reading())
    assert not at_rest(reading(moving=True))
    assert not at_rest(reading(qd=0.02))  # a halted arm still slowing down
    assert not at_rest(reading(base=0.05))


class Keeper(HeapKeeper):
    """A keeper over a robot whose reading the test sets, with no worker (never busy)."""

    def __init__(self) -> None:
        self.robot = SimpleNamespace(realtime=True, state=lambda: self.now)
        self.now = reading(moving=True, qd=0.5)
        self._job = None
        self._closing = threading.Event()
        self._job_freed = threading.Event()


def wait_for(predicate, timeout: float = 5.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.01)
    return False


def test_the_memory_a_job_freed_goes_back_once_the_arm_has_stopped(monkeypatch) -> None:
    released: list[RobotState] = []
    keeper = Keeper()
    monkeypatch.setattr(heap_keeper, "HEAP_TICK", 0.01)
    monkeypatch.setattr(heap_keeper, "release_free_memory", lambda: released.append(keeper.now))
    keeper._start_heap_keeper()
    try:
        keeper._job_freed.set()  # a halted job ended with the arm still slowing
        time.sleep(0.2)
        assert released == []
        keeper.now = reading()  # the arm has come to rest
        assert wait_for(lambda: released)
        assert at_rest(released[0]) and not keeper._job_freed.is_set()
        time.sleep(0.1)
        assert len(released) == 1  # once a job, not every tick
    finally:
        keeper._closing.set()
        keeper._stop_heap_keeper()


def test_no_keeper_beside_a_simulation_the_caller_steps() -> None:
    keeper = Keeper()
    keeper.robot.realtime = False
    keeper._start_heap_keeper()
    assert keeper._heap_keeper is None
