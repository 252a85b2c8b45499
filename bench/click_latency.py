"""Click-to-highlight latency of the 3D console (target: 250 ms or less).

A real `laserpick serve` on `isolation`, and its page at `/` in headless Chromium, the 3D view
in the page's frame at the detail the page chooses (`--detail`; "auto" is half on this
machine, which draws WebGL without a GPU). For each object: click on it in the 3D view
(aim), click again on the same spot (confirm), and time from the confirming click's
pointerdown in the browser to the frame that draws the highlight: the first WebGL draw of
as many points as the lit cloud the 3D view sent (its `highlight` event on the events
stream says how many). A hook on `drawArrays` in the view's frame stamps every point draw.
Also printed: the time to the lit cloud sent (or, when the highlight was sent ahead of the
confirm, hidden, to the message that shows it). Both clocks are this machine's wall clock.
Between trials the mark is cancelled. `--pause S` waits S seconds between the aiming click
taking effect and the confirming click, as a person does who looks at the dot before
confirming it; at 0 (the default) the confirming click lands while the browser is still
drawing the aim.

    MUJOCO_GL=egl .venv/bin/python bench/click_latency.py [--rounds 2] [--pause S]
        [--detail auto|full|half] [--no-browser]

`--no-browser` measures the server alone, in this process: the session, the 3D view's drawing
and its viser server without a browser, from a click-confirmed mark (`Session.confirm` with
the object's centre as the point, aimed there as a click aims) to the lit cloud sent.

It prints each trial and the median, p90 and max. The browser renders WebGL in software
(SwiftShader), so a frame takes longer here than on a machine with a GPU.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from playwright.sync_api import sync_playwright

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

from serve_process import ServeProcess  # noqa: E402

from laserpick.client import Client  # noqa: E402
from laserpick.console import headless_chromium  # noqa: E402
from laserpick.console.viewer import default_view_pixel  # noqa: E402

# The wall-clock time (ms since the epoch) of every pointerdown, the interval between
# animation frames (emptied once the view has loaded: the trials' frames are the ones that
# tell how busy the view's thread is when a click comes), and the time and size of every
# WebGL draw of points.
PROBE = """
window.__lp = { downs: [], frames: [], draws: [] };
for (const C of [window.WebGLRenderingContext, window.WebGL2RenderingContext]) {
  if (!C) continue;
  const draw = C.prototype.drawArrays;
  C.prototype.drawArrays = function (mode, first, count) {
    if (mode === 0 && window.__lp.draws.length < 50000)  // gl.POINTS
      window.__lp.draws.push([performance.timeOrigin + performance.now(), count]);
    return draw.call(this, mode, first, count);
  };
}
document.addEventListener(
  "pointerdown", (e) => window.__lp.downs.push(performance.timeOrigin + e.timeStamp), true);
let last = null;
const tick = (t) => {
  if (last !== null && window.__lp.frames.length < 100000) window.__lp.frames.push(t - last);
  last = t;
  requestAnimationFrame(tick);
};
requestAnimationFrame(tick);
"""


def detail_setting(detail: str) -> str:
    """A script that gives the page's remembered settings this 3D view detail."""
    return f"""
try {{
  localStorage.setItem("laserpick.settings.operator", JSON.stringify({{ viewDetail: "{detail}" }}));
}} catch {{}}
"""


def open_view(browser: Any, server: ServeProcess, detail: str, probe: str) -> tuple[Any, Any]:
    """The page at `/` in a new 1280 x 800 tab of `browser`, its 3D view at `detail`, once the
    view has loaded and its scene faded in; `probe` runs in every frame before the page's
    own scripts. Returns the page and the 3D view's frame."""
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.add_init_script(probe + detail_setting(detail))
    page.goto(server.url)
    page.frame_locator("iframe#view").get_by_role("button", name="Detect").wait_for(timeout=30_000)
    frame = page.locator("iframe#view").element_handle().content_frame()
    time.sleep(6.0)  # the scene fades in
    return page, frame


@dataclass
class Latencies:
    """What the browser trials measured (ms)."""

    drawn: list[float] = field(default_factory=list)  #: click to the frame drawing the highlight
    sent: list[float] = field(default_factory=list)  #: click to the lit cloud (or its message) sent
    #: from the click's arrival in the server
    server_share: list[float] = field(default_factory=list)
    frames: list[float] = field(default_factory=list)  #: the browser's animation frame intervals
    lost: int = 0  #: confirming clicks the view did not take as one


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=2, help="passes over the six objects")
    parser.add_argument("--no-browser", action="store_true", help="the server's share alone")
    parser.add_argument(
        "--pause",
        type=float,
        default=0.0,
        help="seconds between the aiming click taking effect and the confirming click (a"
        " person looks at the dot first); 0: at once",
    )
    parser.add_argument(
        "--detail",
        choices=("auto", "full", "half"),
        default="auto",
        help="the page's 3D view detail setting (auto: half without a GPU)",
    )
    return parser.parse_args()


def main() -> int:
    args = parse_args()
    if args.no_browser:
        return server_only(args.rounds)
    out = Latencies()
    with tempfile.TemporaryDirectory() as tmp:
        server = ServeProcess(Path(tmp), extra_args=("--lite-view",)).start()
        # The bench holds the operator station's lease; the 3D view's clicks act under it.
        api = Client(server.url, name="latency bench", source="console")
        try:
            api.take_control()
            objects = [o for o in api.get("/sim/objects") if not o["in_basket"]]
            with sync_playwright() as p:
                browser = headless_chromium.launch(p)
                page, frame = open_view(browser, server, args.detail, PROBE)
                frame.evaluate("window.__lp.frames = []")  # the trials', not the loading's
                print(f"3D view: {frame.url}")
                box = page.frame_locator("iframe#view").locator("canvas").first.bounding_box()
                for _ in range(args.rounds):
                    for obj in objects:
                        click_trial(api, page, frame, box, obj, args.pause, out)
                out.frames = frame.evaluate("window.__lp.frames")
                browser.close()
        finally:
            api.release()
            server.close()
    if not out.drawn:
        print("no highlight was seen drawn")
        return 1
    print_latencies(out)
    return 0


def click_trial(
    api: Client, page: Any, frame: Any, box: dict, obj: dict, pause: float, out: Latencies
) -> None:
    """Click on `obj` in the 3D view (aim), wait `pause` s, click again (confirm), and add
    the times to the highlight sent and drawn to `out`; the mark is cancelled after."""
    x, y = default_view_pixel(obj["center_base"], box["width"], box["height"])
    x, y = box["x"] + x, box["y"] + y
    page.mouse.click(x, y)
    api.wait_for(lambda s: s["state"] == "aiming" and not s["busy"], 20)
    time.sleep(pause)
    seen = len(api.events)
    page.mouse.click(x, y)
    # The click reaches the server on its own path: wait until it has taken it (the mark is
    # confirmed), then until the work is done.
    try:
        api.wait_for(lambda s: s["state"] != "aiming" or s["busy"], 10)
    except TimeoutError:
        out.lost += 1
        print(f"{obj['name']:>18}: the confirming click was not taken")
        api.post("/cancel")
        return
    state = api.wait_for(lambda s: not s["busy"], 60)
    time.sleep(0.5)
    clicked = frame.evaluate("window.__lp.downs")[-1] / 1000.0
    shown = [e for e in api.events[seen:] if e["name"] == "highlight" and e["t"] > clicked]
    if not shown:
        print(f"{obj['name']:>18}: no highlight ({state['message']})")
        api.post("/cancel")
        return
    lit = shown[0]
    draws = frame.evaluate("window.__lp.draws")
    first = [t for t, n in draws if n == lit["points"] and t > clicked * 1e3]
    out.sent.append(1000.0 * (lit["t"] - clicked))
    share = 1000.0 * (lit.get("since_click") or float("nan"))
    out.server_share.append(share)
    drew = f"{first[0] - clicked * 1e3:6.0f} ms" if first else "   not seen"
    if first:
        out.drawn.append(first[0] - clicked * 1e3)
    print(
        f"{obj['name']:>18}: drawn {drew}; sent {out.sent[-1]:4.0f} ms, of which"
        f" the server {share:4.0f} ms  ({state['state']})"
    )
    api.post("/cancel")


def print_latencies(out: Latencies) -> None:
    drawn, sent, frames = out.drawn, out.sent, out.frames
    print(
        f"\nclick-to-highlight over {len(drawn)} of {len(sent)} marks, to the frame that draws"
        f" it: median {statistics.median(drawn):.0f} ms, p90 {np.percentile(drawn, 90):.0f} ms,"
        f" max {max(drawn):.0f} ms (target 250). To it sent: median"
        f" {statistics.median(sent):.0f} ms; the server's share (click arrived to sent): median"
        f" {statistics.median(out.server_share):.0f} ms; the browser's frame interval: median"
        f" {statistics.median(frames):.0f} ms, p90 {np.percentile(frames, 90):.0f} ms (software"
        f" WebGL); confirming clicks not taken:"
        f" {out.lost}"
    )


def server_only(rounds: int) -> int:
    """Click-confirmed mark to lit cloud sent, in-process, with no browser on the machine."""
    import threading

    import viser

    from laserpick.bench.referee import Referee
    from laserpick.console.operator_console import OperatorConsole
    from laserpick.robot.sim.robot import SimRobot
    from laserpick.robot.sim.scenes import load_scene
    from laserpick.server.session import Actor, Session

    session = Session(SimRobot(load_scene("isolation"), realtime=True))
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    console = OperatorConsole(session, server)
    console.start()
    shown = threading.Event()
    session.on_event(lambda e: shown.set() if e["name"] == "highlight" else None)
    actor = Actor("console", session.lease.acquire("latency bench", "console"))
    referee = Referee(session.robot)
    samples: list[float] = []
    try:
        time.sleep(2.0)
        for _ in range(rounds):
            for name in referee.instances():
                pts = referee.object_points(name)
                centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
                session.cloud()  # the capture a first click makes while aiming
                session.aim_at(actor, centre, "base", foresee=True)  # as a click aims
                time.sleep(0.5)
                shown.clear()
                t0 = time.monotonic()
                session.confirm(actor, point=centre)
                if shown.wait(5.0):
                    samples.append(1000.0 * (time.monotonic() - t0))
                    print(f"{name:>18}: {samples[-1]:6.0f} ms")
                else:
                    print(f"{name:>18}: no highlight ({session.message})")
                while session.busy:
                    time.sleep(0.1)
                session.cancel(actor)
    finally:
        console.stop()
        session.close()
        server.stop()
    if not samples:
        return 1
    print(
        f"\nconfirm-to-highlight, server alone, over {len(samples)} marks: median"
        f" {statistics.median(samples):.0f} ms, p90 {np.percentile(samples, 90):.0f} ms,"
        f" max {max(samples):.0f} ms (target 250)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
