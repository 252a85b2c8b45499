"""The server never dies of its environment: MuJoCo's OpenGL backend is chosen before MuJoCo
loads (or the CLI refuses to start with one sentence), and cameras that fail end the job with
a typed failure while the server, the arm's controller and the journal go on."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from serve_process import REPO, ServeProcess

from laserpick.client import ApiError, Client
from laserpick.robot.gl_backend import GLBackendError, pick_backend
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.robot.sim.truth import SimTruth
from laserpick.server.journal import Journal
from laserpick.server.session import Actor, CamerasUnavailable, Session, TaskState

pytestmark = pytest.mark.timeout(300)

#: Clear what the environment says about rendering, so that the server must choose.
UNSET = {"MUJOCO_GL": None, "PYOPENGL_PLATFORM": None}


def one_sentence(text: str) -> bool:
    body = text.strip()
    return body.endswith(".") and ". " not in body[:-1] and "\n" not in body


# --- the choice -----------------------------------------------------------------------------


def test_with_no_backend_rendering_the_error_names_what_to_install_or_set() -> None:
    tried: list[str] = []

    def fails(backend: str) -> bool:
        tried.append(backend)
        return False

    with pytest.raises(GLBackendError) as err:
        pick_backend({}, probe=fails)
    assert tried == ["egl", "osmesa"]
    message = str(err.value)
    assert one_sentence(message), message
    for named in ("libegl1", "libegl-mesa0", "libosmesa6", "MUJOCO_GL"):
        assert named in message


def test_egl_is_tried_first_and_osmesa_when_egl_fails() -> None:
    assert pick_backend({}, probe=lambda backend: True) == "egl"
    assert pick_backend({}, probe=lambda backend: backend == "osmesa") == "osmesa"


def test_a_backend_the_user_set_is_checked_not_probed() -> None:
    def never(backend: str) -> bool:
        raise AssertionError("a backend the user set is not probed")

    assert pick_backend({"MUJOCO_GL": "glfw", "DISPLAY": ":0"}, probe=never) == "glfw"
    for wanted in ("nonsense", "glfw", "disable"):
        with pytest.raises(GLBackendError) as err:
            pick_backend({"MUJOCO_GL": wanted}, probe=never)
        message = str(err.value)
        assert one_sentence(message) and "MUJOCO_GL" in message and repr(wanted) in message


def test_a_failed_gl_setup_is_not_tried_again_in_the_process() -> None:
    """GLFW with no display: MuJoCo's render context fails, and a second attempt would abort
    the process (same thread) or hang it (another thread). Each attempt raises instead."""
    code = textwrap.dedent(
        """
        import threading
        import mujoco
        from laserpick.robot.sim.sensors import RenderingUnavailable, SegmentationRenderer
        model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
        def attempt():
            try:
                SegmentationRenderer(model, 8, 8)
            except RenderingUnavailable as exc:
                print("refused:", exc)
        attempt()
        attempt()
        other = threading.Thread(target=attempt)
        other.start()
        other.join(60)
        print("alive")
        """
    )
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.update(MUJOCO_GL="glfw", PYTHONPATH=str(REPO))
    env.pop("PYOPENGL_PLATFORM", None)
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-2000:]
    refusals = [line for line in done.stdout.splitlines() if line.startswith("refused:")]
    assert len(refusals) == 3 and "the cameras cannot render" in refusals[0], done.stdout
    assert done.stdout.strip().endswith("alive")


# --- `laserpick serve` ------------------------------------------------------------------------


def test_serve_with_mujoco_gl_unset_chooses_a_backend_and_perceives(tmp_path: Path) -> None:
    server = ServeProcess(tmp_path, env=UNSET)
    try:
        server.start()
        with Client(server.url, name="test") as c:
            mug = next(o for o in c.get("/sim/objects") if o["name"] == "mug_1")
            c.post("/laser/aim", {"point": mug["center_base"]})
            c.post("/laser/confirm")
            state = c.settled(90)
            assert state["state"] == "grasps_ready", state["message"]
    finally:
        server.close()


def test_serve_with_an_unusable_mujoco_gl_refuses_to_start(tmp_path: Path) -> None:
    server = ServeProcess(tmp_path, env={"MUJOCO_GL": "nonsense"})
    try:
        code = server.proc.wait(60)
    finally:
        server.close()
    stderr = server.stderr_path.read_text()
    assert code == 2, server.log()
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1, stderr
    sentence = stderr.strip().removeprefix("laserpick: ")
    assert one_sentence(sentence) and "MUJOCO_GL is 'nonsense'" in sentence, stderr
    assert not any("console at" in line for line in server.output)
    assert not server.journal.exists()  # refused before opening anything, the port included


def test_cameras_that_cannot_render_fail_each_confirm_and_the_server_goes_on(
    tmp_path: Path,
) -> None:
    """EGL asked for, but with no EGL vendor library to load: the server starts, and every
    confirm fails with a typed failure; the process, the API and the journal go on."""
    broken = {"MUJOCO_GL": "egl", "__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "none.json")}
    server = ServeProcess(tmp_path, env=broken)
    try:
        server.start()
        with Client(server.url, name="test") as c:
            mug = next(o for o in c.get("/sim/objects") if o["name"] == "mug_1")
            failures = []
            for _ in range(2):
                c.post("/laser/aim", {"point": mug["center_base"]})
                c.post("/laser/confirm")
                state = c.settled(60)
                if state["state"] == "grasps_ready":
                    pytest.skip("EGL renders here without a vendor library (no libglvnd)")
                assert state["state"] == "idle", state["message"]
                failures.append(state["failure"])
            assert all(f["kind"] == "execute" for f in failures), failures
            assert all("the cameras cannot render" in f["message"] for f in failures), failures
            for read in (  # reads that need a new capture say why they have none
                lambda: c.get("/cloud"),
                lambda: c.post(
                    "/laser/aim", {"ray": {"origin": [0, 0, 1], "direction": [1, 0, 0]}}
                ),
            ):
                with pytest.raises(ApiError) as refused:
                    read()
                assert refused.value.status == 503, refused.value
                assert "the cameras cannot render" in str(refused.value.detail)
            t0 = c.state()["sim_time"]
            time.sleep(0.5)
            assert c.state()["sim_time"] > t0  # the arm's controller still runs
            assert c.health()["status"] == "ok"
            rows = c.get("/journal", format="json")
        assert server.proc.poll() is None, server.log()
    finally:
        server.close()
    perceived = [r for r in rows if r["action"] == "perceiving"]
    assert [(r["outcome"], r["failure"]) for r in perceived] == [("failed", "execute")] * 2


# --- the session ------------------------------------------------------------------------------


#: A click's ray (origin, direction; m, `base`) from above the scooter, looking forward.
RAY = (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))


class CamerasUnplugged(SimRobot):
    """The simulated robot, with cameras that raise on every capture."""

    def capture(self):
        raise RuntimeError("the camera cable is unplugged")


def test_a_capture_that_raises_fails_the_job_and_the_session_goes_on(tmp_path: Path) -> None:
    journal = Journal(tmp_path / "journal.sqlite3", session="cameras")
    session = Session(CamerasUnplugged(load_scene("isolation", seed=1)), journal=journal)
    try:
        actor = Actor("rest", session.lease.acquire("test", "rest"))
        truth = SimTruth(session.robot)
        pts = truth.object_points(truth.instances()[0])
        session.aim_at(actor, (pts.min(axis=0) + pts.max(axis=0)) / 2, "base")
        session.confirm(actor)
        deadline = time.monotonic() + 30.0
        while session.busy:
            assert time.monotonic() < deadline, session.message
            time.sleep(0.02)
        assert session.state == TaskState.IDLE
        assert session.failure is not None and session.failure.kind == "execute"
        assert "the camera cable is unplugged" in session.failure.message
        assert session.status_model().failure is not None  # the session still answers
        t0 = session.robot.state().stamp
        time.sleep(0.3)
        assert session.robot.state().stamp > t0  # the arm's controller still runs
        assert not np.any(np.abs(session.robot.joint_state().qd) > 0.01)  # at rest
        rows = [e for e in journal.events() if e["action"] == "perceiving"]
        assert [(r["outcome"], r["failure"]) for r in rows] == [("failed", "execute")]
        assert "the camera cable is unplugged" in rows[0]["message"]
        for read in (session.cloud, lambda: session.aim_ray(actor, *RAY, "base")):
            with pytest.raises(CamerasUnavailable, match="the camera cable is unplugged"):
                read()
    finally:
        session.close()
        journal.close()
