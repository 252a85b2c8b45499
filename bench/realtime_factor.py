"""Real-time factor of the live simulation under the console's full load.

Runs what `laserpick serve` runs, plus the sensors:

* a real-time `Simulation` on a scene (default `isolation`),
* the viser server and `SceneViewer` on a free port, with ONE real client: the page opened in
  headless Chromium (a client that renders the scene updates, not a websocket that drops them),
* a capture thread that renders all five depth cameras (`DepthCameras`) every 0.5 s.

After `--warmup` seconds (the browser compiles its shaders), it measures for `--seconds` and
prints sim seconds, wall seconds, the real-time factor (sim seconds per wall second), the
capture rate achieved and the mean viewer update rate.

    MUJOCO_GL=egl .venv/bin/python -m bench.realtime_factor [--seconds 30] [--check]

`--check` exits 1 if the RTF is below 1.0 less `--tolerance` (default 0.01: the loop is paced
to the wall clock, so it cannot beat 1.0); without it the exit code is 0 whatever the RTF.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is imported anywhere

try:
    import laserpick  # noqa: F401
except ImportError:  # run as a script from a checkout without `pip install -e .`
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import viser

from laserpick.console import headless_chromium
from laserpick.console.viewer import SceneViewer
from laserpick.robot.sim.loop import Simulation
from laserpick.robot.sim.robot import SimRobot
from laserpick.robot.sim.scenes import load_scene
from laserpick.robot.sim.sensors import DepthCameras
from laserpick.robot.sim.world_view import SimWorld
from laserpick.settings import get_settings


@dataclass
class CaptureStats:
    """What the capture thread did. Times in wall seconds (perf_counter)."""

    captures: int = 0  #: capture rounds (five frames each)
    frames: int = 0
    busy: float = 0.0  #: total time spent capturing (s)
    durations: list[float] = field(default_factory=list)
    error: BaseException | None = None


def capture_loop(sim: Simulation, period: float, stop: threading.Event, out: CaptureStats) -> None:
    """Every `period` s, capture all five cameras at the latest snapshot's qpos.

    The DepthCameras (and its GL context) is created and used in this thread only.
    """
    try:
        cams = DepthCameras(sim.model)
        try:
            next_t = time.perf_counter()
            while not stop.is_set():
                t0 = time.perf_counter()
                snap = sim.snapshot()
                frames = cams.capture(snap.qpos, snap.time)
                dt = time.perf_counter() - t0
                out.captures += 1
                out.frames += len(frames)
                out.busy += dt
                out.durations.append(dt)
                next_t += period
                delay = next_t - time.perf_counter()
                if delay > 0:
                    stop.wait(delay)
                else:
                    next_t = time.perf_counter()  # overran: start the next one now
        finally:
            cams.close()
    except BaseException as exc:  # reported by the main thread
        out.error = exc


@dataclass
class Window:
    """What the measured window saw: sim and wall seconds, the sim's own last real-time
    factor, the viewer's updates and the capture rounds in it, and the browser clients."""

    sim_s: float
    wall_s: float
    last_rtf: float
    updates: int
    captures: int
    clients: int
    viewer_hz: float  #: the viewer's target update rate


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=30.0, help="measured wall time (s)")
    parser.add_argument("--warmup", type=float, default=10.0, help="unmeasured start (s)")
    parser.add_argument("--scene", default="isolation")
    parser.add_argument(
        "--capture-hz",
        type=float,
        default=get_settings().sensor.capture_rate_hz,
        help="rounds of five-camera captures per second",
    )
    parser.add_argument("--viewport", default="960x600", help="browser viewport, WxH pixels")
    parser.add_argument("--check", action="store_true", help="exit 1 if RTF < 1.0 - tolerance")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        help="slack for --check: a loop paced to the wall clock cannot beat 1.0, and snapshot "
        "times come in 20 ms chunks (default 0.01)",
    )
    return parser.parse_args(argv)


def measure(args: argparse.Namespace, width: int, height: int, cap: CaptureStats) -> Window | int:
    """Run the simulation, the viewer with one browser client and the capture thread; after
    the warm-up, measure for `args.seconds`. An exit code where the browser never connected."""
    from playwright.sync_api import sync_playwright

    robot = SimRobot(load_scene(args.scene), realtime=True)  # its loop starts here
    sim = robot.sim
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    viewer = SceneViewer(robot, server, world=SimWorld(sim))
    stop = threading.Event()
    capture = threading.Thread(
        target=capture_loop,
        args=(sim, 1.0 / args.capture_hz, stop, cap),
        name="capture",
        daemon=True,
    )
    url = f"http://127.0.0.1:{server.get_port()}"
    try:
        sim.start()
        viewer.start()
        with sync_playwright() as p:
            browser = headless_chromium.launch(p)
            try:
                page = browser.new_page(viewport={"width": width, "height": height})
                page.goto(url)
                deadline = time.perf_counter() + 30
                while not server.get_clients() and time.perf_counter() < deadline:
                    time.sleep(0.1)
                if not server.get_clients():
                    print("realtime_factor: the browser never connected", file=sys.stderr)
                    return 2
                capture.start()
                time.sleep(args.warmup)

                snap0, wall0 = sim.snapshot(), time.perf_counter()
                updates0, captures0 = viewer.stats.updates, cap.captures
                time.sleep(args.seconds)
                snap1, wall1 = sim.snapshot(), time.perf_counter()
                updates1, captures1 = viewer.stats.updates, cap.captures
                clients = len(server.get_clients())
            finally:
                browser.close()
    finally:
        stop.set()
        viewer.stop()
        if capture.is_alive():
            capture.join(timeout=10)
        robot.close()
        server.stop()
    return Window(
        snap1.time - snap0.time,
        wall1 - wall0,
        snap1.rtf,
        updates1 - updates0,
        captures1 - captures0,
        clients,
        viewer.rate_hz,
    )


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    width, height = (int(v) for v in args.viewport.lower().split("x"))
    cap = CaptureStats()
    window = measure(args, width, height, cap)
    if isinstance(window, int):
        return window
    if cap.error is not None:
        print(f"realtime_factor: capture failed: {cap.error!r}", file=sys.stderr)
        return 2

    sim_s, wall_s = window.sim_s, window.wall_s
    rtf = sim_s / wall_s
    mean_cap = sum(cap.durations) / len(cap.durations) if cap.durations else float("nan")
    print(f"scene            {args.scene}  (browser {width}x{height}, {window.clients} client)")
    print(f"sim seconds      {sim_s:8.2f}")
    print(f"wall seconds     {wall_s:8.2f}")
    print(f"RTF              {rtf:8.4f}   (sim's own last 0.5 s window: {window.last_rtf:.3f})")
    print(
        f"capture rate     {window.captures / wall_s:8.2f} rounds/s of 5 frames "
        f"(target {args.capture_hz:g}; mean round {mean_cap * 1000:.0f} ms)"
    )
    print(f"viewer updates   {window.updates / wall_s:8.2f} Hz (target {window.viewer_hz:g})")
    if args.check and rtf < 1.0 - args.tolerance:
        print(f"realtime_factor: RTF {rtf:.4f} < 1.0 - {args.tolerance:g}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
