"""The viser console and the `laserpick serve` command.

1. `laserpick serve` in a real subprocess, its 3D view opened in headless Chromium: the scene
   renders, a click on an object aims and a second confirms the mark, the lit target and the
   grasp outlines show, STOP latches the e-stop, and SIGTERM ends the server cleanly. The
   screenshot: test-artifacts/console.png.
2. The viewer's moving-body nodes follow the simulation (headless sim, one update by hand).
3. Bad scene names and non-loopback hosts are refused with exit code 2 and a reason.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from screenshots import pixel_stats
from serve_process import ServeProcess

from laserpick.client import Client
from laserpick.console import headless_chromium
from laserpick.console.viewer import default_view_pixel

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
                # The scene fades in: poll until the view shows many colours twice running.
                stats: dict = {}
                good, t0 = 0, time.monotonic()
                while time.monotonic() - t0 < 45 and good < 2:
                    time.sleep(1.0)
                    stats = pixel_stats(page, page.screenshot())
                    good = good + 1 if stats["colours"] >= 6 else 0
                assert stats["colours"] >= 6, f"the view looks blank: {stats}"

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

        t0 = time.monotonic()
        server.proc.send_signal(signal.SIGTERM)
        rc = server.proc.wait(timeout=15)
        assert rc == 0, server.log()
        assert time.monotonic() - t0 < 10.0
        time.sleep(0.2)  # let the reader thread take the last lines
        assert any("shutting down" in line for line in server.output)
    finally:
        server.close()


def test_viewer_nodes_follow_the_sim() -> None:
    viser = pytest.importorskip("viser")
    from laserpick.console.viewer import SceneViewer
    from laserpick.robot.sim.loop import Simulation
    from laserpick.robot.sim.scenes import load_scene

    sim = Simulation(load_scene("isolation"), realtime=False)
    server = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
    try:
        viewer = SceneViewer(sim, server)
        assert "scooter" in viewer.moving_bodies
        assert "ur5/link1" in viewer.moving_bodies
        assert "finger_left" in viewer.moving_bodies
        assert "world" in viewer.static_bodies
        assert not set(viewer.moving_bodies) & set(viewer.static_bodies)
        # The flange carries only a site (group 5): nothing to draw.
        assert "ur5/flange" not in viewer.moving_bodies
        info = sim.info
        for name in info.object_bodies:
            assert f"obj/{name}" in viewer.moving_bodies

        scooter = viewer.body_handle("scooter")
        link1 = viewer.body_handle("ur5/link1")
        x0 = float(scooter.position[0])
        link1_0 = np.array(link1.position)
        assert not viewer.update(), "no burst without new sim time"

        # Reverse at 0.5 m/s for a second of sim time (the dead-man is 0.5 s, so re-issue
        # it), then send one update. Reverse: driving forward, the arm's base meets the
        # isolation table's edge after about 0.1 m.
        for _ in range(4):
            sim.drive(-0.5, 0.0, 0.5)
            sim.settle(0.25)
        assert viewer.update()
        snap = sim.snapshot()
        b = info.scooter_body
        np.testing.assert_allclose(scooter.position, snap.xpos[b], atol=1e-6)
        np.testing.assert_allclose(np.abs(scooter.wxyz @ snap.xquat[b]), 1.0, atol=1e-6)
        moved = float(scooter.position[0]) - x0
        assert -0.6 < moved < -0.15, f"scooter node moved {moved:.3f} m"
        # The arm rides along.
        assert np.linalg.norm(np.array(link1.position) - link1_0) > 0.1
        assert viewer.stats.updates == 1

        # A resting body's creep is not sent (each pose sent makes the browser draw a frame,
        # and a click waits behind it): under POSE_STEP_M from the pose last sent, the node
        # keeps that pose; past it, it follows.
        from laserpick.console.viewer import POSE_STEP_M

        shown = np.array(scooter.position)
        creep = snap.xpos.copy()
        creep[b, 1] += 0.4 * POSE_STEP_M
        viewer.update(replace(snap, xpos=creep, time=snap.time + 0.1))
        np.testing.assert_allclose(scooter.position, shown, atol=1e-9)
        creep[b, 1] += 2.0 * POSE_STEP_M
        viewer.update(replace(snap, xpos=creep, time=snap.time + 0.2))
        np.testing.assert_allclose(scooter.position, creep[b], atol=1e-6)

        # A new simulation (scene reset) rebuilds the nodes at the start pose.
        sim2 = Simulation(load_scene("isolation"), realtime=False)
        viewer.set_simulation(sim2)
        assert abs(float(viewer.body_handle("scooter").position[0]) - x0) < 1e-6
        status = viewer.status_text()
        assert "sim time" in status and "e-stop clear" in status
        viewer.close()
    finally:
        server.stop()


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
    from laserpick.console.operator_console import lit_by, projector_pixels
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
