"""Recordings and the recorded robot: the format reads back what was written, a bad recording
is refused with where and what, and a recording served by `laserpick serve --recorded` takes
a mark to grasps ready through the API alone, in a process where `mujoco` is never imported."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from serve_process import REPO, free_port, stop_process

from laserpick import cli
from laserpick.client import Client
from laserpick.robot.interface import GripperState, JointState
from laserpick.robot.pointer import LaserState
from laserpick.robot.recorded import CANNOT_MOVE, RecordedRobot, fallback_projector
from laserpick.robot.recording import (
    Hint,
    RecordedCapture,
    Recording,
    RecordingError,
    capture_from,
    read_recording,
    write_recording,
)
from laserpick.types import DepthFrame, Trajectory

pytestmark = pytest.mark.timeout(300)

#: The isolation scene's object on which conftest's `isolation_recording` confirms the laser.
TARGET = "mug_1"


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("LASERPICK_OPERATOR_PASSWORD", None)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return env


@pytest.fixture
def recorded(isolation_recording: Path) -> Path:
    """`laserpick record` of the isolation scene with the laser confirmed on TARGET (made
    once for the session; the examples read it too)."""
    return isolation_recording


# --- the format ------------------------------------------------------------------------------


def test_a_recording_reads_back_as_it_was_captured(tmp_path):
    from laserpick.robot.sim.truth import capture

    c = capture("isolation")
    try:
        c.robot.laser.aim_at(np.array([1.6, -0.2, 0.5]))
        c.robot.laser.confirm()
        written = Recording(
            (capture_from(c.robot, Hint("table", np.array([1.6, -0.2, 0.46]))),),
            c.robot.projector(),
            "a test",
        )
    finally:
        c.close()
    back = read_recording(write_recording(tmp_path / "rec", written))
    assert back.source == "a test" and back.cameras == written.cameras and len(back.cameras) == 5
    old, new = written.captures[0], back.captures[0]
    for a, b in zip(old.frames, new.frames, strict=True):
        assert a.camera == b.camera and a.stamp == b.stamp
        assert b.depth.dtype == np.float32 and b.ir.dtype == np.uint8
        for field in ("depth", "ir", "K", "T_base_cam"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), (a.camera, field)
    assert np.array_equal(old.joints.q, new.joints.q) and old.joints.stamp == new.joints.stamp
    assert old.gripper == new.gripper and np.array_equal(old.base_pose, new.base_pose)
    assert new.laser == old.laser and new.laser.confirmed
    assert new.hint.object == "table" and np.array_equal(new.hint.top_base, [1.6, -0.2, 0.46])
    for field in ("K", "T_base_proj", "width", "height"):
        assert np.array_equal(getattr(back.projector, field), getattr(written.projector, field))


def test_record_confirms_the_laser_on_the_object(recorded):
    rec = read_recording(recorded)
    cap = rec.captures[0]
    assert "isolation" in rec.source and len(rec.captures) == 1
    assert cap.laser is not None and cap.laser.on and cap.laser.confirmed
    assert cap.hint is not None and cap.hint.object == TARGET
    assert rec.projector is not None


def test_record_refuses_an_unknown_object_or_a_used_directory(recorded, tmp_path, capsys):
    args = ["record", str(tmp_path / "new"), "--scene", "isolation", "--aim-at-object", "nope"]
    assert cli.main(args) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert "no object 'nope'" in err and TARGET in err
    assert not (tmp_path / "new").exists()
    assert cli.main(["record", str(recorded), "--scene", "isolation"]) == cli.EXIT_USAGE
    assert "not an empty directory" in capsys.readouterr().err


def test_serve_refuses_a_directory_that_is_no_recording(tmp_path, capsys):
    assert cli.main(["serve", "--recorded", str(tmp_path)]) == cli.EXIT_USAGE
    assert "meta.json: missing" in capsys.readouterr().err
    with pytest.raises(SystemExit):  # a scene or a recording, not both
        cli.main(["serve", "--scene", "kitchen", "--recorded", str(tmp_path)])


def _tiny(captures: int = 2) -> Recording:
    """Two 4 x 6 cameras, `captures` captures: enough to break in every way."""
    K = np.array([[5.0, 0.0, 3.0], [0.0, 5.0, 2.0], [0.0, 0.0, 1.0]])
    out = []
    for i in range(captures):
        frames = tuple(
            DepthFrame(
                np.full((4, 6), 1.0 + i, np.float32),
                np.full((4, 6), 10 * i + j, np.uint8),
                K,
                np.eye(4),
                cam,
                float(i),
            )
            for j, cam in enumerate(("cam_a", "cam_b"))
        )
        out.append(
            RecordedCapture(
                frames,
                JointState(np.full(6, 0.1 * i), np.zeros(6), float(i)),
                GripperState(0.085, 0.0, False, False),
                np.array([0.5 * i, 0.0, 0.0]),
                float(i),
                LaserState(True, True, 0.1, -0.3) if i else None,
            )
        )
    return Recording(tuple(out), None, "tiny")


def _meta(root: Path, change: Callable[[dict], object]) -> None:
    meta = json.loads((root / "meta.json").read_text())
    change(meta)
    (root / "meta.json").write_text(json.dumps(meta))  # NaN is written as the token NaN


def _frame(path: str, array: np.ndarray) -> Callable[[Path], None]:
    return lambda root: np.save(root / path, array)


def _cam(i: int, cam: str) -> Callable[[dict], dict]:
    return lambda m: m["captures"][i]["frames"][cam]


BREAKAGES: dict[str, tuple[Callable[[Path], object], str, str]] = {
    "no meta.json": (lambda r: (r / "meta.json").unlink(), "meta.json", "missing"),
    "meta.json not JSON": (
        lambda r: (r / "meta.json").write_text("{"),
        "meta.json",
        "not valid JSON",
    ),
    "another format": (
        lambda r: _meta(r, lambda m: m.update(format="rosbag")),
        "format",
        "laserpick-recording",
    ),
    "a newer version": (lambda r: _meta(r, lambda m: m.update(version=2)), "version", "1"),
    "millimetres": (
        lambda r: _meta(r, lambda m: m["units"].update(length="mm")),
        "units.length",
        "'m'",
    ),
    "a missing array": (
        lambda r: (r / "capture-001" / "cam_b.ir.npy").unlink(),
        "capture-001/cam_b.ir.npy",
        "missing",
    ),
    "float64 depth": (
        _frame("capture-000/cam_a.depth.npy", np.ones((4, 6))),
        "capture-000/cam_a.depth.npy",
        "float32",
    ),
    "NaN depth": (
        _frame("capture-000/cam_a.depth.npy", np.full((4, 6), np.nan, np.float32)),
        "capture-000/cam_a.depth.npy",
        "NaN",
    ),
    "IR of another size": (
        _frame("capture-000/cam_b.ir.npy", np.zeros((3, 6), np.uint8)),
        "capture-000/cam_b.ir.npy",
        "differs from the depth",
    ),
    "NaN in K": (
        lambda r: _meta(r, lambda m: _cam(0, "cam_a")(m)["K"][0].__setitem__(0, float("nan"))),
        "captures[0].frames.cam_a.K",
        "NaN",
    ),
    "K not a pinhole": (
        lambda r: _meta(r, lambda m: _cam(1, "cam_a")(m)["K"].__setitem__(2, [0, 0, 2])),
        "captures[1].frames.cam_a.K",
        "last row",
    ),
    "T stretched": (
        lambda r: _meta(r, lambda m: _cam(1, "cam_b")(m)["T_base_cam"][0].__setitem__(0, 2.0)),
        "captures[1].frames.cam_b.T_base_cam",
        "rotation",
    ),
    "five joints": (
        lambda r: _meta(r, lambda m: m["captures"][0]["joints"].update(q=[0.0] * 5)),
        "captures[0].joints.q",
        "(6,)",
    ),
    "gripper without closed": (
        lambda r: _meta(r, lambda m: m["captures"][0]["gripper"].pop("closed")),
        "captures[0].gripper.closed",
        "missing",
    ),
    "an unlisted camera": (
        lambda r: _meta(r, lambda m: m["captures"][0]["frames"].update(cam_c={})),
        "captures[0].frames.cam_c",
        "not among",
    ),
    "a dir outside": (
        lambda r: _meta(r, lambda m: m["captures"][1].update(dir="..")),
        "captures[1].dir",
        "plain file name",
    ),
}


@pytest.mark.parametrize("breakage", sorted(BREAKAGES))
def test_a_broken_recording_says_where_and_what(tmp_path, breakage):
    root = write_recording(tmp_path / "rec", _tiny())
    read_recording(root)  # whole, it reads
    breaking, where, what = BREAKAGES[breakage]
    breaking(root)
    with pytest.raises(RecordingError) as err:
        read_recording(root)
    found = dict(err.value.problems)
    assert where in found, err.value.problems
    assert what in found[where]
    assert str(root) in str(err.value)


def test_every_problem_is_listed_not_just_the_first(tmp_path):
    root = write_recording(tmp_path / "rec", _tiny())
    (root / "capture-000" / "cam_a.depth.npy").unlink()
    np.save(root / "capture-001" / "cam_b.ir.npy", np.zeros((4, 6), np.int16))
    with pytest.raises(RecordingError) as err:
        read_recording(root)
    assert [w for w, _ in err.value.problems] == [
        "capture-000/cam_a.depth.npy",
        "capture-001/cam_b.ir.npy",
    ]


def test_the_writer_checks_before_it_writes(tmp_path):
    rec = _tiny(1)
    frame = rec.captures[0].frames[1]
    K = frame.K.copy()
    K[1, 1] = np.nan
    bad_frames = (
        rec.captures[0].frames[0],
        DepthFrame(frame.depth, frame.ir, K, frame.T_base_cam, "cam_b", 0.0),
    )
    bad = Recording((dataclasses.replace(rec.captures[0], frames=bad_frames),))
    with pytest.raises(RecordingError, match=r"captures\[0\]\.frames\.cam_b\.K: contains NaN"):
        write_recording(tmp_path / "bad", bad)
    assert not (tmp_path / "bad" / "meta.json").exists()
    write_recording(tmp_path / "good", rec)
    with pytest.raises(FileExistsError):
        write_recording(tmp_path / "good", rec)


# --- the recorded robot ----------------------------------------------------------------------


def test_the_recorded_robot_serves_its_captures_and_cannot_move(tmp_path):
    robot = RecordedRobot(write_recording(tmp_path / "rec", _tiny()))
    frames = robot.capture()
    assert [f.camera for f in frames] == ["cam_a", "cam_b"] and robot.realtime
    frames[0].depth[:] = 9.0  # a copy: the recording is unchanged
    assert np.all(robot.capture()[0].depth == 1.0)
    assert robot.joint_state().q[0] == 0.0 and robot.base_pose()[0] == 0.0
    assert robot.next_capture() == 1 and robot.next_capture() == 1
    assert robot.capture()[1].ir[0, 0] == 11 and robot.base_pose()[0] == 0.5
    assert robot.joint_state().q[0] == pytest.approx(0.1) and robot.state().stamp == 1.0
    with pytest.raises(IndexError):
        robot.use_capture(2)

    q = robot.joint_state().q
    handle = robot.execute(Trajectory(np.array([0.0, 1.0]), np.array([q, q + 0.1])))
    assert handle.done() and robot.wait(handle, 0.0) == "failed"
    assert handle.message == CANNOT_MOVE
    robot.gripper(True), robot.drive(0.3, 0.0), robot.halt()
    state = robot.state()
    assert not state.gripper.closed and not state.moving and not state.estopped
    robot.stop()
    assert robot.state().estopped
    robot.reset_stop()
    assert not robot.state().estopped

    robot.laser.aim_at(np.array([1.5, 0.0, 0.5]))
    assert robot.laser.confirm().confirmed and len(robot.laser.beams_base()) == 2
    robot.close()


def test_a_recording_without_a_projector_gets_the_scooters():
    from laserpick.robot.sim.robot import SimRobot

    sim = SimRobot(None, realtime=False)
    try:
        want = sim.projector()
    finally:
        sim.close()
    got = fallback_projector()
    assert np.allclose(got.K, want.K) and np.allclose(got.T_base_proj, want.T_base_proj)
    assert (got.width, got.height) == (want.width, want.height)


def test_reading_a_recording_never_loads_the_simulator(recorded):
    code = f"""
        import sys
        from laserpick.robot.recorded import RecordedRobot
        robot = RecordedRobot({str(recorded)!r})
        assert len(robot.capture()) == 5
        print("mujoco" in sys.modules, "laserpick.robot.sim" in sys.modules)
        """
    out = _python(code)
    assert out.split() == ["False", "False"], out


# --- served ----------------------------------------------------------------------------------


def _python(code: str, timeout: float = 240) -> str:
    res = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=REPO,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert res.returncode == 0, res.stdout + res.stderr[-4000:]
    return res.stdout.strip().splitlines()[-1]


@pytest.fixture
def recorded_server(recorded: Path, tmp_path: Path) -> Iterator[str]:
    """`laserpick serve --recorded` as a real process; its URL."""
    port = free_port()
    stderr = (tmp_path / "serve.stderr").open("w")
    proc = subprocess.Popen(
        [
            *[sys.executable, "-m", "laserpick.cli", "serve", "--recorded", str(recorded)],
            *["--port", str(port), "--journal", str(tmp_path / "journal.sqlite3")],
        ],
        cwd=REPO,
        env=_env(),
        stdout=subprocess.PIPE,
        stderr=stderr,
        text=True,
    )
    try:
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith("laserpick: console at "):
                break
        else:
            stderr.flush()
            pytest.fail(
                "serve --recorded never came up:\n" + (tmp_path / "serve.stderr").read_text()
            )
        yield f"http://127.0.0.1:{port}"
    finally:
        stop_process(proc)
        stderr.close()


def test_a_served_recording_takes_a_mark_to_grasps_ready(recorded_server, recorded):
    top = read_recording(recorded).captures[0].hint.top_base
    with Client(recorded_server, name="test") as c:
        assert c.state()["state"] == "idle"
        c.post("/laser/aim", {"point": [float(v) for v in top]})
        c.post("/laser/confirm")
        state = c.wait_for(lambda s: not s["busy"] and s["state"] != "marked", timeout=120)
        assert state["state"] == "grasps_ready", state["message"]
        assert state["grasps"]["clusters"] >= 1
        assert np.linalg.norm(np.array(state["mark"]) - top) < 0.03
        c.post("/execute")
        state = c.wait_for(lambda s: not s["busy"] and s["state"] != "executing", timeout=60)
        assert state["failure"]["kind"] == "execute", state
        assert CANNOT_MOVE in state["failure"]["message"]


def test_in_process_a_recording_takes_a_mark_to_grasps_ready_without_mujoco(recorded):
    # The app on a RecordedRobot, served by uvicorn on a thread of this one process, driven
    # through the REST API; then whether anything in the process imported mujoco.
    code = f"""
        import json, sys, threading, time
        import uvicorn
        from laserpick.client import Client
        from laserpick.robot.recorded import RecordedRobot
        from laserpick.server.app import create_app
        from laserpick.server.session import Session

        robot = RecordedRobot({str(recorded)!r})
        top = [float(v) for v in robot.recording.captures[0].hint.top_base]
        session = Session(robot)
        config = uvicorn.Config(create_app(session), port={free_port()}, log_level="warning")
        server = uvicorn.Server(config)
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        while not server.started:
            time.sleep(0.05)
        with Client(f"http://127.0.0.1:{{config.port}}", name="test") as c:
            c.post("/laser/aim", {{"point": top}})
            c.post("/laser/confirm")
            state = c.wait_for(lambda s: not s["busy"] and s["state"] != "marked", 120)
        server.should_exit = True
        thread.join(10)
        session.close()
        grasps = state["grasps"]["clusters"] if state["grasps"] else 0
        print(json.dumps([state["state"], grasps, "mujoco" in sys.modules]))
        """
    state, clusters, mujoco = json.loads(_python(code))
    assert state == "grasps_ready" and clusters >= 1
    assert mujoco is False, "the server's process imported mujoco"
