"""The session in this process, on the simulated robot: what a click-confirmed mark reuses."""

from __future__ import annotations

import time

import numpy as np

from laserpick.bench.operator import Referee
from laserpick.robot.scenes import load_scene
from laserpick.robot.sim_robot import SimRobot
from laserpick.server.session import Actor, Session, TaskState


def test_a_click_confirmed_mark_is_perceived_in_the_cloud_it_was_aimed_in() -> None:
    """A confirming click perceives in the cloud of the capture made while aiming: it is not
    fused again, and the views are not sent a new whole cloud just as the target lights."""
    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=True))
    try:
        actor = Actor("console", session.lease.acquire("test", "console"))
        referee = Referee(session.robot)
        pts = referee.object_points(referee.instances()[0])
        centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
        session.aim_at(actor, centre, "base")
        aimed_in = session.cloud()  # the capture a first click makes
        session.confirm(actor, point=centre)
        deadline = time.monotonic() + 30.0
        while session.state in (TaskState.MARKED,) or session.busy:
            assert time.monotonic() < deadline, session.message
            time.sleep(0.05)
        assert session.state == TaskState.GRASPS_READY, session.message
        latest = session.latest_cloud
        assert latest is not None and latest[0] is aimed_in
        perception = session.task.perception
        assert perception is not None and perception.cloud is aimed_in
        assert perception.timings["fuse"] == 0.0
        assert np.linalg.norm(perception.mark.point - centre) < 1e-9
    finally:
        session.close()
