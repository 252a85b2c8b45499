"""How busy the 3D view keeps the browser while the laser moves, at each view detail.

A real `laserpick serve` on `isolation`, and its page at `/` in headless Chromium with the 3D
view at the detail given (the page's setting: auto, full or half). The laser is nudged back
and forth every 0.3 s for 20 nudges through the API; each nudge redraws the beam, and viser
then draws frames for a quarter of a second. The script prints the share of that time the
view's main thread spent in long tasks (over 50 ms: WebGL drawn in software, mostly), their
number and median length. This machine has no GPU: its browser draws WebGL with SwiftShader
on the two cores the simulation also runs on.

    MUJOCO_GL=egl .venv/bin/python bench/view_load.py [--detail full half]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
sys.path.insert(0, str(REPO / "bench"))

from click_latency import open_view  # noqa: E402
from serve_process import ServeProcess  # noqa: E402

from laserpick.client import Client  # noqa: E402
from laserpick.console import headless_chromium  # noqa: E402

NUDGES = 20
PERIOD = 0.3  #: s between nudges
STEP = 0.01  #: rad each nudge turns the laser

PROBE = """
window.__long = [];
new PerformanceObserver((list) => {
  for (const e of list.getEntries()) window.__long.push(e.duration);
}).observe({ entryTypes: ["longtask"] });
"""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--detail", nargs="+", choices=("auto", "full", "half"), default=["full", "half"]
    )
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        server = ServeProcess(Path(tmp), extra_args=("--lite-view",)).start()
        api = Client(server.url, name="view load bench", source="console")
        try:
            api.take_control()
            with sync_playwright() as p:
                browser = headless_chromium.launch(p)
                for detail in args.detail:
                    measure(browser, server, api, detail)
                browser.close()
        finally:
            api.release()
            server.close()
    return 0


def measure(browser, server: ServeProcess, api: Client, detail: str) -> None:
    page, frame = open_view(browser, server, detail, PROBE)
    frame.evaluate("window.__long = []")
    t0 = time.monotonic()
    for k in range(NUDGES):
        api.post("/laser/nudge", {"dyaw": STEP if k % 2 else -STEP, "dpitch": 0.0})
        time.sleep(PERIOD)
    span = time.monotonic() - t0
    long = frame.evaluate("window.__long")
    busy = sum(long) / 1000.0 / span
    median = statistics.median(long) if long else 0.0
    print(
        f"detail {detail:>4} ({frame.url}): long tasks {100 * busy:3.0f} % of the time,"
        f" {len(long)} of them, median {median:.0f} ms"
    )
    page.close()


if __name__ == "__main__":
    raise SystemExit(main())
