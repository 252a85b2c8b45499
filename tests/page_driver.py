"""Driving the browser page at `/` as a person would, for the page's tests: a `laserpick
serve` and Debian's headless Chromium (conftest's `page_stack` keeps one of each for all the
page tests), pages opened in fresh profiles, keys pressed toward a target, the state awaited
through the API.
"""

from __future__ import annotations

import math
import re
import time
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from urllib.parse import urljoin

from basket import assert_in_basket
from serve_process import ServeProcess

from laserpick.client import ApiError, Client
from laserpick.console import headless_chromium
from laserpick.description import dims

REPO = Path(__file__).resolve().parents[1]
ARTIFACTS = REPO / "test-artifacts"
STATIC = REPO / "laserpick" / "static"
STEP = 0.05  #: rad: the page's default laser step (arrow, button)
FINE = 0.01  #: rad: Shift+arrow
VIEWPORT = {"width": 1280, "height": 800}


def serve_for_pages(tmp: Path) -> Iterator[ServeProcess]:
    """A `laserpick serve` for the page tests, closed after them. No shadows: software
    WebGL draws twice as fast, leaving the CPU to the simulation."""
    proc = ServeProcess(tmp, extra_args=("--lite-view",))
    try:
        proc.start()
        yield proc
    finally:
        proc.close()


def chromium(sync_api) -> Iterator[object]:
    """Headless Chromium through Playwright's sync API, closed after use."""
    with sync_api.sync_playwright() as p:
        b = headless_chromium.launch(p)
        try:
            yield b
        finally:
            b.close()


#: The page's remembered settings with the 3D view hidden (its own setting): the tests that
#: are not about the view leave the CPU to the simulation (software WebGL shares it).
_NO_VIEW = """
if (!localStorage.getItem("laserpick.settings.operator")) {
  localStorage.setItem("laserpick.settings.operator", JSON.stringify({ showView: false }));
}
"""


def open_page(browser, server: ServeProcess, init_script: str = "", *, view: bool = False):
    """A fresh page on `/` (in a fresh browser profile), once its first state frame arrived;
    errors in its script are collected in `page.errors`."""
    context = browser.new_context(viewport=VIEWPORT)
    if init_script or not view:
        context.add_init_script(init_script + ("" if view else _NO_VIEW))
    page = context.new_page()
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(server.url + "/")
    page.wait_for_function(
        "!['connecting', 'offline'].includes(document.getElementById('state-badge').textContent)",
        timeout=20_000,
    )
    return page


def close_page(page) -> None:
    """Close like a person closing the tab (pagehide gives the lease back)."""
    errors = page.errors
    page.close(run_before_unload=True)
    page.context.close()
    assert not errors, f"the page's script failed: {errors}"


#: The MIME types of JavaScript: a browser runs no module script of another type (nor, under
#: `X-Content-Type-Options: nosniff`, any script).
JS_TYPES = ("text/javascript", "application/javascript")

#: A GET: a path to the answer's status, lower-cased headers and body.
Get = Callable[[str], tuple[int, dict[str, str], bytes]]


def direct_get(server: ServeProcess) -> Get:
    """GET straight from `server` (an error status raises)."""

    def get(path: str) -> tuple[int, dict[str, str], bytes]:
        with urllib.request.urlopen(server.url + path, timeout=10) as r:
            return r.status, {k.lower(): v for k, v in r.headers.items()}, r.read()

    return get


def page_scripts(get: Get) -> set[str]:
    """The paths of every script the page at `/` runs: those index.html names and every
    module they import, each fetched with `get` and asserted served as JavaScript."""
    status, _, html = get("/")
    assert status == 200, html[:500]
    named = re.findall(r'<script\b[^>]*\bsrc="([^"]+)"', html.decode())
    todo = [urljoin("/", src) for src in named]
    found: set[str] = set()
    while todo:
        path = todo.pop()
        if path in found:
            continue
        found.add(path)
        status, headers, body = get(path)
        assert status == 200, f"{path}: {status}"
        kind = headers.get("content-type", "").split(";")[0].strip()
        assert kind in JS_TYPES, f"{path} is served as {kind!r}"
        imports = re.findall(r'^import\b[^"]*"([^"]+)"', body.decode(), re.MULTILINE)
        todo += [urljoin(path, spec) for spec in imports]
    return found


def page_script_files() -> set[str]:
    """The paths at which the app serves every .js file of laserpick/static/ but the 3D
    view's own (view.js, which the page at /view runs)."""
    return {
        "/static/" + p.relative_to(STATIC).as_posix()
        for p in STATIC.rglob("*.js")
        if p != STATIC / "view.js"
    }


def observer(server: ServeProcess) -> Client:
    """A client that only watches."""
    return Client(server.url, name="test observer")


def mug(server: ServeProcess) -> dict:
    """The mug of the isolation scene, where the simulator has it (its /sim/objects entry)."""
    return next(o for o in observer(server).get("/sim/objects") if o["name"] == "mug_1")


def fresh_scene(server: ServeProcess) -> None:
    """The isolation scene as it starts (the referee's reset, through the API), once no page
    holds control any more."""
    client = Client(server.url, name="test referee")
    deadline = time.monotonic() + 10
    while True:
        try:
            client.take_control()
            break
        except ApiError as exc:
            if exc.status != 409 or time.monotonic() > deadline:
                raise
            time.sleep(0.3)
    try:
        client.wait_for(lambda s: not s["busy"], timeout=60)
        client.post("/scene", {"name": "isolation"})
    finally:
        client.release()


def aim_needed(state: dict, target: list[float]) -> tuple[float, float]:
    """(dyaw, dpitch) rad from where the laser points to `target` (m, base), with the
    pointer's convention (laserpick/robot/pointer.py): yaw about +z from +x, positive left;
    pitch above the horizontal, positive up; from dims.LASER_ORIGIN."""
    v = [t - o for t, o in zip(target, dims.LASER_ORIGIN, strict=True)]
    yaw = math.atan2(v[1], v[0])
    pitch = math.atan2(v[2], math.hypot(v[0], v[1]))
    return yaw - state["laser"]["yaw"], pitch - state["laser"]["pitch"]


def focused(page, role: str, name: str) -> bool:
    """Whether the control of `role` named `name` has the keyboard focus."""
    return page.get_by_role(role, name=name, exact=True).evaluate(
        "e => e === document.activeElement"
    )


def tab_to(page, name: str, role: str = "button", back: bool = False) -> int:
    """Press Tab (or Shift+Tab) until the control named `name` has the focus; the presses."""
    key = "Shift+Tab" if back else "Tab"
    for n in range(1, 60):
        page.keyboard.press(key)
        if focused(page, role, name):
            return n
    raise AssertionError(f"Tab never reached {role} {name!r}")


def wait_state(server: ServeProcess, pred: Callable[[dict], bool], timeout: float) -> dict:
    """The first state that satisfies `pred`, polled through the API within `timeout` s."""
    return observer(server).wait_for(pred, timeout=timeout, poll=0.2)


def aim_by_keys(page, server: ServeProcess, target: list[float], *, tab: bool) -> dict:
    """Aim the laser at `target` from the keyboard: coarse steps by Space on the laser's
    buttons, reached by Tab (tab=True), or by arrows; then fine steps by Shift+arrows, which
    nudge wherever the focus is (but the Drive group). The state once the laser is there."""
    dyaw, dpitch = aim_needed(observer(server).state(), target)
    n_yaw, n_pitch = round(dyaw / STEP), round(dpitch / STEP)
    coarse = (
        ("Left" if n_yaw > 0 else "Right", "ArrowLeft" if n_yaw > 0 else "ArrowRight", abs(n_yaw)),
        ("Up" if n_pitch > 0 else "Down", "ArrowUp" if n_pitch > 0 else "ArrowDown", abs(n_pitch)),
    )
    for button, arrow, n in coarse:
        if tab and n:
            tab_to(page, button)
        for _ in range(n):
            page.keyboard.press("Space" if tab else arrow)
            time.sleep(0.05)
    fine_yaw = round((dyaw - n_yaw * STEP) / FINE)
    fine_pitch = round((dpitch - n_pitch * STEP) / FINE)
    for key, n in (
        ("ArrowLeft" if fine_yaw > 0 else "ArrowRight", abs(fine_yaw)),
        ("ArrowUp" if fine_pitch > 0 else "ArrowDown", abs(fine_pitch)),
    ):
        for _ in range(n):
            page.keyboard.press(f"Shift+{key}")
            time.sleep(0.05)
    want = aim_needed({"laser": {"yaw": 0.0, "pitch": 0.0}}, target)
    return wait_state(
        server,
        lambda s: (
            abs(s["laser"]["yaw"] - want[0]) < 0.006 and abs(s["laser"]["pitch"] - want[1]) < 0.006
        ),
        10,
    )


def finish_pick(server: ServeProcess, started: float) -> None:
    """Wait for the pick and drop to end at rest, without a failure, and the mug in the basket."""
    state = wait_state(server, lambda s: s["state"] == "executing" or s["busy"], 20)
    state = wait_state(server, lambda s: s["state"] == "idle" and not s["busy"], 180)
    assert state["failure"] is None, state["failure"]
    print(f"pick done {time.monotonic() - started:.1f} s after Go")
    assert_in_basket(mug(server))
