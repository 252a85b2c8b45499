"""The viser console and the `laserpick serve` command.

1. `laserpick serve` in a real subprocess, its 3D view opened in headless Chromium: the scene
   renders, a click on an object aims and a second confirms the mark, the lit target and the
   grasp outlines show, STOP latches the e-stop, and SIGTERM ends the server cleanly. The
   screenshot: test-artifacts/console.png.
2. The viewer draws the robot from its description and state, and the simulator's world as
   a layer (headless sim, one update by hand); the laser's beams end on the cloud.
3. Bad scene names and non-loopback hosts are refused with exit code 2 and a reason.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from screenshots import pixel_stats
from serve_process import ServeProcess

from laserpick.client import Client
from laserpick.console import SceneViewer, headless_chromium
from laserpick.console.default_camera import default_view_pixel
from laserpick.console.scene_nodes import POSE_STEP_M
from laserpick.robot.sim import SimRobot, load_scene
from laserpick.robot.sim.world_view import SimWorld
from laserpick.transforms import matrix_from_quat

REPO = Path(__file__).resolve().parents[1]
ARTIFACTS = REPO / "test-artifacts"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["MUJOCO_GL"] = "egl"
    env.pop("LASERPICK_OPERATOR_PASSWORD", None)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _laserpick(*args: str) -> list[str]:
    """The `laserpick` command, run as a module so it works without an installed script."""
    return [sys.executable, "-m", "laserpick.cli", *args]


def test_console_renders_aims_by_click_shows_the_lit_target_and_stops(tmp_path: Path) -> None:
    """The 3D view of a live server in headless Chromium: it renders; a click on the mug aims
    the laser there and a second click confirms the mark (the state's mark lands on the
    mug); the lit target glows and the candidates are drawn; the panel's STOP latches the
    e-stop; SIGTERM ends the server cleanly."""
    playwright = pytest.importorskip("playwright.sync_api")
    if not Path(headless_chromium.CHROMIUM).exists():
        pytest.skip("no Chromium at /usr/bin/chromium")
    server = ServeProcess(tmp_path, extra_args=("--lite-view",))  # SwiftShader: 3x faster
    try:
        server.start()
        ARTIFACTS.mkdir(exist_ok=True)
        api = Client(server.url, name="observer")
        mug = next(o for o in api.get("/sim/objects") if o["name"] == "mug_1")
        with playwright.sync_playwright() as p:
            browser = headless_chromium.launch(p)
            try:
                # Software WebGL renders a frame in about a second: keep the view small.
                page = browser.new_page(viewport={"width": 900, "height": 600})
                page.goto(server.viser_url)
                page.get_by_role("button", name="Detect").wait_for(timeout=30_000)
                wait_drawn(page)

                box = page.locator("canvas").first.bounding_box()
                x, y = default_view_pixel(mug["center_base"], box["width"], box["height"])
                page.mouse.click(box["x"] + x, box["y"] + y)
                state = api.wait_for(lambda s: s["laser"]["on"], timeout=20)
                assert state["state"] == "aiming"
                page.mouse.click(box["x"] + x, box["y"] + y)  # the same spot: confirm
                state = api.wait_for(lambda s: not s["busy"] and s["mark"], timeout=60)
                assert state["state"] == "grasps_ready", state["message"]
                mark = np.array(state["mark"])
                # On the mug: within its 5 cm radius of its axis, between its base and top.
                off = np.linalg.norm(mark[:2] - np.array(mug["position_world"][:2]))
                assert off < 0.06 and mug["position_world"][2] < mark[2] < mug["top_base"] + 0.01

                time.sleep(3.0)  # the lit cloud and the outlines reach the browser
                png = page.screenshot(path=str(ARTIFACTS / "console.png"))
                stats = pixel_stats(page, png)
                assert stats["lit"] > 0.0005, f"no lit target on screen: {stats}"
                assert stats["green"] > 0.00005, f"no grasp outline on screen: {stats}"

                page.get_by_role("button", name="STOP", exact=True).click()
                assert api.wait_for(lambda s: s["estopped"], timeout=10)["estopped"]
            finally:
                browser.close()
        assert server.proc.poll() is None, "server died while the browser was connected"
        assert_sigterm_ends(server)
    finally:
        server.close()


def wait_drawn(page) -> None:
    """Until the view shows many colours twice running (the scene fades in)."""
    stats: dict = {}
    good, t0 = 0, time.monotonic()
    while time.monotonic() - t0 < 45 and good < 2:
        time.sleep(1.0)
        stats = pixel_stats(page, page.screenshot())
        good = good + 1 if stats["colours"] >= 6 else 0
    assert stats["colours"] >= 6, f"the view looks blank: {stats}"


def assert_sigterm_ends(server: ServeProcess) -> None:
    """SIGTERM ends the server within 10 s, with exit code 0, saying it shuts down."""
    t0 = time.monotonic()
    server.proc.send_signal(signal.SIGTERM)
    rc = server.proc.wait(timeout=15)
    assert rc == 0, server.log()
    assert time.monotonic() - t0 < 10.0
    time.sleep(0.2)  # let the reader thread take the last lines
    assert any("shutting down" in line for line in server.output)


@pytest.fixture
def view_server() -> Iterator[object]:
    """A viser server on a free port, stopped after the test."""
    viser = pytest.importorskip("viser")
    server = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
    try:
        yield server
    finally:
        server.stop()


def test_viewer_draws_the_robot_from_its_state_and_the_world_from_the_sim_layer(
    view_server,
) -> None:
    """The robot is drawn from its description and `Robot.state()`: its parts sit where the
    simulator has its bodies, and follow the scooter as it drives. The world (floor,
    furniture, objects) comes from the simulator's layer."""
    robot = SimRobot(load_scene("isolation"), realtime=False)
    try:
        viewer = SceneViewer(robot, view_server, world=SimWorld(robot.sim))
        parts, world = viewer.robot_nodes, viewer.world_nodes
        assert {"scooter", "ur5/link1", "gripper", "finger_left"} <= set(parts.parts)
        assert "world" in world.still and "surface/table" in world.still
        for name in robot.sim.info.object_bodies:
            assert f"obj/{name}" in world.moving
        assert not {"scooter", "ur5/link1", "gripper"} & {*world.moving, *world.still}

        root, link3 = parts.root, parts.frame("ur5/link3")
        x0 = float(root.position[0])
        assert not viewer.update(), "no burst without new robot time"
        # Reverse at 0.5 m/s for a second (the dead-man is 0.5 s, so re-issue it), then send
        # one update. Reverse: driving forward, the arm's base meets the table's edge.
        for _ in range(4):
            robot.drive(-0.5, 0.0, 0.5)
            robot.sleep(0.25)
        assert viewer.update()
        snap = robot.sim.snapshot()
        x, y, yaw = snap.base_pose
        np.testing.assert_allclose(root.position, [x, y, 0.0], atol=1e-9)
        np.testing.assert_allclose(root.wxyz, [np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)], atol=1e-9)
        assert -0.6 < float(root.position[0]) - x0 < -0.15
        # A link's frame (in `base`, under the root) is where the simulator has its body
        # (whose pose lags its joints by the step the arm's servo still moves it: 30 um).
        b = robot.sim.info.scooter_body
        R = matrix_from_quat(snap.xquat[b])
        link = robot.sim.model.body("ur5/link3").id
        in_base = R.T @ (snap.xpos[link] - snap.xpos[b])
        np.testing.assert_allclose(link3.position, in_base, atol=1e-4)
        assert viewer.stats.updates == 1
        viewer.close()
    finally:
        robot.close()


def test_viewer_sends_no_creep_and_redraws_a_new_robot_with_or_without_a_world(
    view_server,
) -> None:
    """A resting body's creep is not sent (each pose sent makes the browser draw a frame,
    and a click waits behind it): under POSE_STEP_M from the pose last sent, the node keeps
    that pose; past it, it follows. A new robot (scene reset) is drawn at its start pose; a
    robot without a world layer is drawn alone, with no run state in the status line."""
    robot = SimRobot(load_scene("isolation"), realtime=False)
    robot2 = SimRobot(load_scene("isolation"), realtime=False)
    try:
        viewer = SceneViewer(robot, view_server, world=SimWorld(robot.sim))
        root = viewer.robot_nodes.root
        state = robot.state()
        shown = np.array(root.position)
        creep = state.base_pose + np.array([0.0, 0.4 * POSE_STEP_M, 0.0])
        viewer.update(replace(state, base_pose=creep, stamp=state.stamp + 0.1))
        np.testing.assert_allclose(root.position, shown, atol=1e-9)
        creep = creep + np.array([0.0, 2.0 * POSE_STEP_M, 0.0])
        viewer.update(replace(state, base_pose=creep, stamp=state.stamp + 0.2))
        np.testing.assert_allclose(root.position[:2], creep[:2], atol=1e-6)

        viewer.set_robot(robot2, SimWorld(robot2.sim))
        np.testing.assert_allclose(viewer.robot_nodes.root.position, shown, atol=1e-9)
        status = viewer.status_text()
        assert "time" in status and "running" in status and "e-stop clear" in status
        viewer.set_robot(robot2)
        assert viewer.world_nodes is None and "running" not in viewer.status_text()
        assert viewer.robot_nodes is not None
        viewer.close()
    finally:
        robot.close()
        robot2.close()


def test_a_beam_ends_with_a_dot_where_it_meets_the_cloud() -> None:
    """The laser is drawn from what a real robot knows: its beams and the fused cloud. A beam
    ends at the first cloud point it passes, with a dot there, in `world`; with no cloud
    or no point on its way it is drawn 3 m long, without a dot."""
    from laserpick.console.laser_overlay import BEAM_LENGTH, beam_segments

    # A wall of points at x = 2 m in the cloud's `base`, captured with the scooter at the
    # origin; the scooter has since moved 0.5 m forward.
    ys, zs = np.meshgrid(np.arange(-1, 1, 0.005), np.arange(0, 1.5, 0.005))
    wall = np.c_[np.full(ys.size, 2.0), ys.ravel(), zs.ravel()].astype(np.float32)
    beams = [(np.array([0.5, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))]
    pose = np.array([0.5, 0.0, 0.0])
    segments, dots = beam_segments(beams, pose, (wall, np.zeros(3)))
    np.testing.assert_allclose(segments[0, 0], [1.0, 0.0, 1.0])
    assert len(dots) == 1 and abs(dots[0][0] - 2.0) < 1e-9 and abs(dots[0][2] - 1.0) < 0.01
    np.testing.assert_allclose(segments[0, 1], dots[0])
    segments, dots = beam_segments(beams, pose, None)
    assert not dots
    np.testing.assert_allclose(segments[0, 1], [1.0 + BEAM_LENGTH, 0.0, 1.0])
    away = [(np.array([0.5, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0]))]
    assert not beam_segments(away, pose, (wall, np.zeros(3)))[1]


def test_bad_scene_exits_2_naming_it() -> None:
    out = subprocess.run(
        _laserpick("serve", "--scene", "does-not-exist", "--viser-port", str(_free_port())),
        cwd=REPO,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 2, out.stdout + out.stderr
    assert "does-not-exist" in out.stderr
    assert "console at" not in out.stdout


def test_non_loopback_host_needs_the_password() -> None:
    out = subprocess.run(
        _laserpick("serve", "--host", "0.0.0.0", "--viser-port", str(_free_port())),
        cwd=REPO,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode != 0
    assert "LASERPICK_OPERATOR_PASSWORD" in out.stderr
    assert "loopback" in out.stderr
    assert "console at" not in out.stdout


def test_lit_points_are_looked_up_by_their_projector_pixel() -> None:
    """The lit points are those whose projector pixel (computed once per cloud) the image
    lights: a point on the axis of a lit pixel is lit, one beside it, one behind the lens or
    one outside the image is not."""
    from laserpick.console import lit_by, projector_pixels
    from laserpick.pipeline.projector import projector_intrinsics
    from laserpick.types import Projector

    w, h = 64, 48
    K = projector_intrinsics(w, h, 0.64, 0.48, 0.32, 0.24, 1.0)  # 100 px per metre at 1 m
    projector = Projector(K, np.eye(4), w, h)  # the optical frame is `base` here

    def at(u: float, v: float, z: float = 1.0) -> list[float]:
        return [(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z]

    points = np.array([at(10, 20), at(11, 20), at(10, 20, z=-1.0), at(80, 20), at(10, 20, 2.0)])
    pixels = projector_pixels(projector, points)
    assert list(pixels) == [20 * w + 10, 20 * w + 11, -1, -1, 20 * w + 10]
    image = np.zeros((h, w), np.uint8)
    image[20, 10] = 255
    assert list(lit_by(image, pixels)) == [True, False, False, False, True]
