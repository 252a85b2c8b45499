"""The browser page at `/` (laserpick/static/), in Debian's headless Chromium against a live
`laserpick serve` started for this module.

1. The page loads, embeds the 3D view, and the view renders (test-artifacts/page.png); the
   mug marked by arrow keys and Detect shows lit, with its grasps (page-grasps.png).
2. Every control has an accessible name (Chromium's own computation) and a target of 44 px
   or more.
3. A keyboard-only pick: Tab, Space and arrow keys aim the laser at the mug (the presses are
   computed from ground truth, as a person would look), then Detect, Next, Previous, Auto
   and Go; the mug ends in the basket.
4. A one-switch scanning pick: the scanning settings are set and remembered across a
   reload, then the switch (Space) is pressed when the highlight reaches the wanted group or
   item, at the scan period; the mug ends in the basket.
5. Esc is STOP from anywhere; Reset stop by keyboard; the gamepad aims the laser, drives only
   with its dead-man held, and B cancels; a held arrow in the Drive group drives.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest
from basket import judge_drop, lost_in_carry
from screenshots import pixel_stats
from serve_process import ServeProcess

from laserpick.client import ApiError, Client
from laserpick.console import headless_chromium
from laserpick.description import dims

REPO = Path(__file__).resolve().parents[1]
ARTIFACTS = REPO / "test-artifacts"
STEP = 0.05  #: rad: the page's default laser step (arrow, button)
FINE = 0.01  #: rad: Shift+arrow
VIEWPORT = {"width": 1280, "height": 800}

sync_api = pytest.importorskip("playwright.sync_api")


# --- fixtures ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServeProcess]:
    if not Path(headless_chromium.CHROMIUM).exists():
        pytest.skip("no Chromium at /usr/bin/chromium")
    # No shadows: software WebGL draws twice as fast, leaving the CPU to the simulation.
    proc = ServeProcess(tmp_path_factory.mktemp("page"), extra_args=("--lite-view",))
    try:
        proc.start()
        yield proc
    finally:
        proc.close()


@pytest.fixture(scope="module")
def browser(server: ServeProcess) -> Iterator[object]:
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


@pytest.fixture
def page(browser, server: ServeProcess):
    p = open_page(browser, server)
    yield p
    close_page(p)


# --- helpers -------------------------------------------------------------------------------


def observer(server: ServeProcess) -> Client:
    return Client(server.url, name="test observer")


def mug(server: ServeProcess) -> dict:
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
    pointer's convention (laserpick/robot/laser.py): yaw about +z from +x, positive left;
    pitch above the horizontal, positive up; from dims.LASER_ORIGIN."""
    v = [t - o for t, o in zip(target, dims.LASER_ORIGIN, strict=True)]
    yaw = math.atan2(v[1], v[0])
    pitch = math.atan2(v[2], math.hypot(v[0], v[1]))
    return yaw - state["laser"]["yaw"], pitch - state["laser"]["pitch"]


def focused(page, role: str, name: str) -> bool:
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
    """Wait for the pick and drop to end at rest, and judge where the mug went."""
    state = wait_state(server, lambda s: s["state"] == "executing" or s["busy"], 20)
    state = wait_state(server, lambda s: s["state"] == "idle" and not s["busy"], 180)
    lost = lost_in_carry(state["failure"])
    assert state["failure"] is None or lost, state["failure"]
    print(f"pick done {time.monotonic() - started:.1f} s after Go")
    judge_drop(mug(server), lost)


# --- 1. the page and its 3D view ---------------------------------------------------------


def test_page_loads_and_the_3d_view_renders(browser, server: ServeProcess) -> None:
    page = open_page(browser, server, view=True)
    try:
        _renders(page, server)
    finally:
        close_page(page)


def wait_rendered(page) -> None:
    """Until the 3D view in the page shows a scene (software WebGL fades it in over seconds):
    many colours twice running, then the end of the fade, for a screenshot a person can
    read. AssertionError if it stays blank."""
    good, colours, t0 = 0, 0, time.monotonic()
    while time.monotonic() - t0 < 60 and good < 2:
        time.sleep(1.0)
        png = page.locator("iframe#view").screenshot()
        colours = pixel_stats(page, png)["colours"]
        good = good + 1 if colours >= 6 else 0
    assert colours >= 6, f"the 3D view looks blank ({colours} colours)"
    print(f"3D view rendered after {time.monotonic() - t0:.1f} s")
    time.sleep(3.0)


def view_src(frame) -> tuple[str, str | None, str | None]:
    """The 3D view iframe's address: its path, and its fixedDpr and multisample settings."""
    src = urlsplit(frame.get_attribute("src"))
    query = parse_qs(src.query)
    return src.path, *(query.get(k, [None])[0] for k in ("fixedDpr", "multisample"))


def _renders(page, server: ServeProcess) -> None:
    frame = page.locator("iframe#view")
    assert frame.get_attribute("title"), "the 3D view's iframe needs a title"
    # This browser draws WebGL without a GPU: "auto" detail is half (a quarter of the pixels,
    # no multisampling), in our copy of viser's page, connected to the viser server.
    assert view_src(frame) == ("/view", "0.5", "0")
    assert parse_qs(urlsplit(frame.get_attribute("src")).query)["websocket"] == [
        "ws" + server.viser_url.removeprefix("http") + "/"
    ]
    assert "without a GPU" in page.locator("#view-detail-note").text_content()
    wait_rendered(page)
    assert (
        frame.element_handle()
        .content_frame()
        .evaluate(
            "document.querySelector('canvas').getContext('webgl2').getContextAttributes().antialias"
        )
        is False
    )
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "page.png"))

    # The panel follows the robot: state, the projector image, the latency figures.
    assert page.locator("#state-badge").text_content() == "idle"
    assert "Aim the laser" in page.locator("#status").text_content()
    assert page.locator("#projector").evaluate("img => img.complete && img.naturalWidth > 0")
    page.wait_for_function("/\\d+ ms/.test(document.getElementById('age').textContent)")
    assert page.get_by_role("button", name="STOP", exact=True).is_visible()

    # The mug marked by arrow keys and Detect: the lit target and the grasp outlines in the
    # view, the projector image and the grasp's factors in the panel. Then Cancel.
    page.locator("body").focus()
    aim_by_keys(page, server, mug(server)["center_base"], tab=False)
    tab_to(page, "Detect")
    page.keyboard.press("Enter")
    state = wait_state(server, lambda s: not s["busy"] and s["state"] != "aiming", 90)
    assert state["state"] == "grasps_ready", state["message"]
    page.wait_for_function("document.getElementById('grasp-info').textContent.includes('Cw')")
    time.sleep(3.0)  # the lit cloud and the outlines reach the 3D view
    page.screenshot(path=str(ARTIFACTS / "page-grasps.png"))
    tab_to(page, "Cancel")
    page.keyboard.press("Space")
    wait_state(server, lambda s: s["state"] == "idle", 10)

    # Full detail on request, remembered: the view reloads without the half-detail setting.
    page.locator("#settings > summary").click()
    page.get_by_label("3D view detail").select_option("full")
    assert view_src(frame) == ("/view", None, None)
    assert '"viewDetail":"full"' in page.evaluate(
        "localStorage.getItem('laserpick.settings.operator')"
    )


# --- 2. accessible names and target sizes -----------------------------------------------

_CONTROLS = "button, input, select, summary, a[href], iframe, textarea"


def test_every_control_has_an_accessible_name_and_a_large_target(page) -> None:
    # Show the scanning Back items and the settings, so that they are checked too.
    page.get_by_text("Settings: switch access").click()
    page.get_by_role("combobox", name="Scanning", exact=True).select_option("step")
    cdp = page.context.new_cdp_session(page)
    root = cdp.send("DOM.getDocument", {"depth": -1})["root"]["nodeId"]
    ids = cdp.send("DOM.querySelectorAll", {"nodeId": root, "selector": _CONTROLS})["nodeIds"]
    assert len(ids) > 30
    unnamed, checked = [], 0
    for node_id in ids:
        ax = cdp.send(
            "Accessibility.getPartialAXTree", {"nodeId": node_id, "fetchRelatives": False}
        )
        node = ax["nodes"][0]
        if node.get("ignored"):  # hidden: not reachable, so it needs no name now
            continue
        checked += 1
        name = (node.get("name") or {}).get("value", "").strip()
        if not name:
            html = cdp.send("DOM.getOuterHTML", {"nodeId": node_id})["outerHTML"]
            unnamed.append(html[:120])
    assert not unnamed, f"controls without an accessible name: {unnamed}"
    assert checked > 30

    # Targets of 44 px or more (a checkbox's target is its label).
    small = page.evaluate(
        """() => [...document.querySelectorAll('button, select, input, summary')]
          .filter(e => e.getClientRects().length && e.type !== 'hidden')
          .map(e => [e.type === 'checkbox' ? e.closest('label') : e, e])
          .map(([t, e]) => [t.getBoundingClientRect(), e.id || e.textContent.trim()])
          .filter(([r]) => r.width < 44 || r.height < 44)
          .map(([r, n]) => `${n}: ${Math.round(r.width)}x${Math.round(r.height)}`)"""
    )
    assert not small, f"targets under 44 px: {small}"
    page.get_by_role("combobox", name="Scanning", exact=True).select_option("off")


# --- 3. a keyboard-only pick -------------------------------------------------------------


def test_keyboard_only_pick(browser, server: ServeProcess) -> None:
    fresh_scene(server)  # the laser level and straight ahead, the mug on the table
    page = open_page(browser, server)
    try:
        t0 = time.monotonic()
        state = aim_by_keys(page, server, mug(server)["center_base"], tab=True)
        assert state["state"] == "aiming" and state["lease"]["source"] == "console"

        tab_to(page, "Detect")
        page.keyboard.press("Enter")
        state = wait_state(server, lambda s: not s["busy"] and s["state"] != "aiming", 90)
        assert state["state"] == "grasps_ready", state["message"]
        page.wait_for_function(
            "document.getElementById('status').textContent.includes('cluster 1 of')"
        )
        print(f"grasps ready {time.monotonic() - t0:.1f} s after the first key")

        # Next shows another cluster and makes the choice manual (Go picks what is shown);
        # Previous comes back; Auto gives the choice back to the system.
        clusters = state["grasps"]["clusters"]
        tab_to(page, "Next")
        page.keyboard.press("Space")
        second = 1 if clusters > 1 else 0
        wait_state(
            server, lambda s: s["selection"] == "manual" and s["grasps"]["cluster"] == second, 5
        )
        tab_to(page, "Previous", back=True)
        page.keyboard.press("Space")
        wait_state(server, lambda s: s["grasps"]["cluster"] == 0, 5)
        tab_to(page, "Auto")
        page.keyboard.press("Enter")
        wait_state(server, lambda s: s["selection"] == "auto", 5)

        tab_to(page, "Go", back=True)
        t_go = time.monotonic()
        page.keyboard.press("Space")
        finish_pick(server, t_go)
        page.wait_for_function(
            "document.getElementById('status').textContent.includes('basket')", timeout=5000
        )
        print(f"keyboard pick: {time.monotonic() - t0:.1f} s")
    finally:
        close_page(page)


# --- 4. a one-switch scanning pick -------------------------------------------------------


class Switch:
    """A person with one switch (Space) who watches the highlight: presses when it reaches
    the wanted entry, soon after it arrived (never as it is about to move on), and presses
    again on the same item once per scan period to repeat it."""

    def __init__(self, page, period: float) -> None:
        self.page, self.period = page, period
        self.shown, self.since = "", time.monotonic()
        self.presses = 0

    def look(self) -> str:
        text = self.page.locator("#scan-status").text_content() or ""
        shown = text.removeprefix("Scanning: ") if text.startswith("Scanning: ") else ""
        if shown != self.shown:
            self.shown, self.since = shown, time.monotonic()
        return text

    def press(self) -> None:
        """Down, held past the acceptance time (0.1 s by default), up."""
        self.page.keyboard.down("Space")
        time.sleep(0.15)
        self.page.keyboard.up("Space")
        self.presses += 1
        self.since = time.monotonic()  # the highlight stays a whole period after a release

    def select(self, name: str, timeout: float = 60) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            text = self.look()
            if not self.shown and "press" in text:  # paused (or not started): start it
                self.press()
            elif self.shown == name and time.monotonic() - self.since < 0.5 * self.period:
                self.press()
                return
            time.sleep(0.03)
        raise AssertionError(f"the highlight never reached {name!r} (last: {self.shown!r})")

    def repeat(self, name: str, times: int) -> None:
        for _ in range(times):
            time.sleep(0.4 * self.period)  # after the release time, well inside the period
            self.look()
            assert self.shown == name, f"the highlight left {name!r} for {self.shown!r}"
            self.press()


def test_one_switch_scanning_pick(browser, server: ServeProcess) -> None:
    fresh_scene(server)
    period = 0.7
    page = open_page(browser, server)
    try:
        # A carer sets the scanning up; the settings are remembered for this user.
        page.get_by_text("Settings: switch access").click()
        page.get_by_role("combobox", name="Scanning", exact=True).select_option("auto")
        page.get_by_role("spinbutton", name="Scan period (s)").fill(str(period))
        page.get_by_role("spinbutton", name="Scan period (s)").press("Tab")
        page.reload()
        page.wait_for_function("document.getElementById('state-badge').textContent === 'idle'")
        assert page.locator("#scan-mode").input_value() == "auto"
        assert page.locator("#scan-period").input_value() == str(period)
        page.locator("body").focus()

        t0 = time.monotonic()
        target = mug(server)["center_base"]
        dyaw, dpitch = aim_needed(observer(server).state(), target)
        sw = Switch(page, period)
        sw.select("Laser group")
        for name, n in (
            ("Left" if dyaw > 0 else "Right", round(abs(dyaw) / STEP)),
            ("Up" if dpitch > 0 else "Down", round(abs(dpitch) / STEP)),
        ):
            if n:
                sw.select(name)
                sw.repeat(name, n - 1)
        want = aim_needed({"laser": {"yaw": 0.0, "pitch": 0.0}}, target)
        wait_state(
            server,
            lambda s: (
                abs(s["laser"]["yaw"] - want[0]) < STEP / 2 + 1e-3
                and abs(s["laser"]["pitch"] - want[1]) < STEP / 2 + 1e-3
            ),
            10,
        )
        sw.select("Detect")
        state = wait_state(server, lambda s: not s["busy"] and s["state"] != "aiming", 90)
        assert state["state"] == "grasps_ready", state["message"]
        sw.select("Grasps group")
        sw.select("Next")
        wait_state(server, lambda s: s["selection"] == "manual", 5)
        sw.select("Auto")
        wait_state(server, lambda s: s["selection"] == "auto", 5)
        sw.select("Go")
        t_go = time.monotonic()
        finish_pick(server, t_go)
        print(f"scanning pick: {sw.presses} presses, {time.monotonic() - t0:.1f} s")
    finally:
        close_page(page)


# --- 5. STOP, driving and the gamepad ----------------------------------------------------

# A standard-mapping gamepad the test moves by hand (navigator.getGamepads is replaced
# before the page's script runs; the page polls it while it is "connected").
_FAKE_PAD = """
window.__pad = {
  id: "test pad", index: 0, connected: true, mapping: "standard", timestamp: 0,
  axes: [0, 0, 0, 0],
  buttons: Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 })),
};
navigator.getGamepads = () => [window.__pad];
"""


def _pad(page, axes: list[float] | None = None, **buttons: bool) -> None:
    page.evaluate(
        """([axes, buttons]) => {
          if (axes) window.__pad.axes = axes;
          for (const [i, v] of Object.entries(buttons)) {
            window.__pad.buttons[+i] = { pressed: v, touched: v, value: v ? 1 : 0 };
          }
        }""",
        [axes, {k.removeprefix("b"): v for k, v in buttons.items()}],
    )


def _at_rest(api: Client, timeout: float = 5.0) -> float:
    """The base's x (m) once two readings 0.25 s apart agree within 2 mm."""
    deadline = time.monotonic() + timeout
    x = api.state()["base_pose"][0]
    while True:
        time.sleep(0.25)
        x, last = api.state()["base_pose"][0], x
        if abs(x - last) < 0.002:
            return x
        assert time.monotonic() < deadline, "still driving"


def test_esc_stops_and_the_gamepad_and_keys_drive(browser, server: ServeProcess) -> None:
    page = open_page(browser, server, init_script=_FAKE_PAD)
    try:
        api = observer(server)
        if api.state()["state"] != "idle":
            fresh_scene(server)
        yaw0 = api.state()["laser"]["yaw"]
        # The stick, without the dead-man, turns the laser left (at a rate).
        _pad(page, [-1.0, 0.0, 0.0, 0.0])
        page.wait_for_timeout(600)
        _pad(page, [0.0, 0.0, 0.0, 0.0])
        state = wait_state(server, lambda s: s["laser"]["yaw"] > yaw0 + 0.1, 5)
        assert state["state"] == "aiming" and state["base_pose"][0] == pytest.approx(0, abs=0.01)
        # With the dead-man (RB) held, the stick drives instead: back (the table is ahead).
        x0 = state["base_pose"][0]
        _pad(page, [0.0, 1.0, 0.0, 0.0], b5=True)
        page.wait_for_timeout(1000)
        _pad(page, [0.0, 0.0, 0.0, 0.0], b5=False)
        x_release = api.state()["base_pose"][0]
        assert x_release < x0 - 0.05, "the dead-man and the stick did not drive"
        # Let go at the page's 0.3 m/s, the base brakes over v^2/2a (7.5 cm); the release's
        # way to the server adds a little. A drive that overtook the stop sent on release
        # (it happened) would add its 0.5 s at full speed: 15 cm more.
        braking = 0.3**2 / (2 * dims.BASE_A_MAX)
        coasted = x_release - _at_rest(api)
        assert coasted < braking + 0.075, f"went on {coasted * 100:.1f} cm after the release"
        # B cancels: the laser goes off.
        _pad(page, b1=True)
        wait_state(server, lambda s: s["state"] == "idle" and not s["laser"]["on"], 5)
        _pad(page, b1=False)

        # A held arrow drives while the focus is in the Drive group; a click is one step.
        tab_to(page, "Back")
        x0 = api.state()["base_pose"][0]
        page.keyboard.down("ArrowDown")
        page.wait_for_timeout(1200)
        page.keyboard.up("ArrowDown")
        wait_state(server, lambda s: s["base_pose"][0] < x0 - 0.1, 5)

        # Esc is STOP, from a select in the Mode group or from nowhere in particular.
        tab_to(page, "Task", role="combobox")
        page.keyboard.press("Escape")
        assert wait_state(server, lambda s: s["estopped"], 5)["estopped"]
        page.wait_for_function("document.getElementById('alert').textContent.includes('STOP')")
        tab_to(page, "Reset stop", back=True)
        page.keyboard.press("Enter")
        wait_state(server, lambda s: not s["estopped"], 5)
        page.locator("body").focus()
        page.keyboard.press("Escape")
        assert wait_state(server, lambda s: s["estopped"], 5)["estopped"]
        tab_to(page, "Reset stop")
        page.keyboard.press("Space")
        wait_state(server, lambda s: not s["estopped"], 5)
    finally:
        close_page(page)


def test_the_page_says_why_the_scooter_stopped(browser, server: ServeProcess) -> None:
    """Driven forward, the stowed arm's base meets the isolation table 10 cm on and the
    scooter stops itself: the page's status line says so (read out, and alerted once), with
    what met what, and takes it down once the scooter has backed away."""
    fresh_scene(server)
    page = open_page(browser, server)
    said = "document.getElementById('status').textContent.includes('The scooter stopped')"
    try:
        api = observer(server)
        tab_to(page, "Forward")
        page.keyboard.down("ArrowUp")
        try:
            state = wait_state(server, lambda s: s["drive_stop"] is not None, 10)
        finally:
            page.keyboard.up("ArrowUp")
        assert "met surface/table" in state["drive_stop"]
        page.wait_for_function(said)
        tab_to(page, "Back")
        x0 = api.state()["base_pose"][0]
        page.keyboard.down("ArrowDown")
        page.wait_for_timeout(1200)
        page.keyboard.up("ArrowDown")
        state = wait_state(server, lambda s: s["drive_stop"] is None, 5)
        assert state["base_pose"][0] < x0 - 0.1
        page.wait_for_function(f"!{said}")
    finally:
        close_page(page)
        fresh_scene(server)
