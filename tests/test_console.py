"""The viser console and the `laserpick serve` command.

1. `laserpick serve` in a real subprocess, opened in headless Chromium: the scene renders
   (the scooter's red shell is on screen among several other colours), the Pause button
   pauses it, and SIGTERM ends the server cleanly. The screenshot: test-artifacts/console.png.
2. The viewer's moving-body nodes follow the simulation (headless sim, one update by hand).
3. Bad scene names and non-loopback hosts are refused with exit code 2 and a reason.
"""

from __future__ import annotations

import base64
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from laserpick.console import headless_chromium

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


# Colour statistics of a PNG, computed in the browser (no image library needed here):
# pixels of the scooter's red shell, and the number of distinct colours (4 bits per channel)
# that cover at least 0.2 % of the image.
_PNG_STATS_JS = """
async (b64) => {
  const img = new Image();
  img.src = "data:image/png;base64," + b64;
  await img.decode();
  const c = document.createElement("canvas");
  c.width = img.width; c.height = img.height;
  const ctx = c.getContext("2d");
  ctx.drawImage(img, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const n = c.width * c.height;
  const bins = new Map();
  let red = 0;
  for (let i = 0; i < d.length; i += 4) {
    const r = d[i], g = d[i + 1], b = d[i + 2];
    if (r > 120 && r - g > 80 && r - b > 80 && Math.abs(g - b) < 40) red++;
    const k = ((r >> 4) << 8) | ((g >> 4) << 4) | (b >> 4);
    bins.set(k, (bins.get(k) || 0) + 1);
  }
  let colours = 0;
  for (const v of bins.values()) if (v >= 0.002 * n) colours++;
  return { red: red / n, colours: colours, width: c.width, height: c.height };
}
"""


class _Server:
    """`laserpick serve` in a subprocess, with its output collected by a reader thread."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen(
            _laserpick("serve", *args),
            cwd=REPO,
            env=_env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,
        )
        self.lines: queue.Queue[str] = queue.Queue()
        self.output: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.output.append(line)
            self.lines.put(line)

    def wait_for_url(self, timeout: float) -> str:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=0.2)
            except queue.Empty:
                if self.proc.poll() is not None:
                    break
                continue
            if line.startswith("laserpick: console at "):
                return line.split(" at ", 1)[1].strip()
        raise AssertionError("no console URL printed:\n" + "".join(self.output))

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5)


def test_serve_renders_in_chromium_and_stops_cleanly() -> None:
    playwright = pytest.importorskip("playwright.sync_api")
    if not Path(headless_chromium.CHROMIUM).exists():
        pytest.skip("no Chromium at /usr/bin/chromium")
    viser_port, api_port = _free_port(), _free_port()
    server = _Server(
        "--scene",
        "isolation",
        "--viser-port",
        str(viser_port),
        "--port",
        str(api_port),
        "--no-shadows",  # SwiftShader draws twice as fast without them
    )
    try:
        url = server.wait_for_url(timeout=60)
        assert url == f"http://127.0.0.1:{viser_port}"
        ARTIFACTS.mkdir(exist_ok=True)
        shot_path = ARTIFACTS / "console.png"
        with playwright.sync_playwright() as p:
            browser = headless_chromium.launch(p)
            try:
                # Software WebGL renders a frame in about a second: keep the view small.
                page = browser.new_page(viewport={"width": 800, "height": 500})
                page.goto(url)
                page.get_by_text("sim time", exact=False).first.wait_for(timeout=30_000)
                # The scene fades in and the camera settles: poll until the red scooter
                # covers a meaningful share of the view in two shots running.
                stats: dict = {}
                good = 0
                t0 = time.monotonic()
                while time.monotonic() - t0 < 45 and good < 2:
                    time.sleep(1.0)
                    png = page.screenshot(path=str(shot_path))
                    stats = page.evaluate(_PNG_STATS_JS, base64.b64encode(png).decode())
                    print(f"{time.monotonic() - t0:5.1f} s: {stats}")
                    good = good + 1 if stats["red"] > 0.02 else 0
                # The Pause button pauses the sim; the status line says so.
                page.get_by_role("button", name="Pause").click()
                page.get_by_role("button", name="Resume").wait_for(timeout=10_000)
                page.get_by_text("paused", exact=False).first.wait_for(timeout=10_000)
            finally:
                browser.close()
        assert stats.get("red", 0) > 0.02, f"scooter red barely visible: {stats}"
        assert stats["colours"] >= 6, f"the view looks blank: {stats}"
        assert server.proc.poll() is None, "server died while the browser was connected"

        t0 = time.monotonic()
        server.proc.send_signal(signal.SIGTERM)
        rc = server.proc.wait(timeout=10)
        assert rc == 0, "".join(server.output)
        assert time.monotonic() - t0 < 5.0
        time.sleep(0.2)  # let the reader thread take the last lines
        assert any("shutting down" in line for line in server.output)
    finally:
        server.kill()


def test_viewer_nodes_follow_the_sim() -> None:
    viser = pytest.importorskip("viser")
    from laserpick.console.viewer import SceneViewer
    from laserpick.robot.scenes import load_scene
    from laserpick.robot.sim import Simulation

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
