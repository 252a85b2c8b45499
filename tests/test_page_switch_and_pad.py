"""The browser page at `/` with one switch and with a gamepad, in Debian's headless Chromium
against a live `laserpick serve` (conftest's `page_stack`, shared with test_page.py).

1. A one-switch scanning pick: the scanning settings are set and remembered across a
   reload, then the switch (Space) is pressed when the highlight reaches the wanted group or
   item, at the scan period; the mug ends in the basket.
2. Esc is STOP from anywhere; Reset stop by keyboard; the gamepad aims the laser, drives only
   with its dead-man held, and B cancels; a held arrow in the Drive group drives.
3. The page says why the scooter stopped itself, and takes it down once it backed away.
"""

from __future__ import annotations

import time

import pytest
from page_driver import (
    STEP,
    aim_needed,
    close_page,
    finish_pick,
    fresh_scene,
    mug,
    observer,
    open_page,
    tab_to,
    wait_state,
)
from serve_process import ServeProcess

from laserpick.client import Client
from laserpick.description import dims

pytest.importorskip("playwright.sync_api")


@pytest.fixture
def server(page_stack) -> ServeProcess:
    return page_stack.server


@pytest.fixture
def browser(page_stack) -> object:
    return page_stack.browser


# --- 1. a one-switch scanning pick -------------------------------------------------------


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

    def select(self, name: str, timeout: float = 60, within: str | None = None) -> None:
        """Press on `name` when the highlight reaches it; within: the group it is in, which
        is entered again when the highlight comes round to it (a press the page took for
        the next entry, on a loaded machine, leaves the person outside the group)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            text = self.look()
            fresh = time.monotonic() - self.since < 0.5 * self.period
            if not self.shown and "press" in text:  # paused (or not started): start it
                self.press()
            elif self.shown == name and fresh:
                self.press()
                return
            elif within is not None and self.shown == within and fresh:
                self.press()
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
        sw.select("Next", within="Grasps group")
        wait_state(server, lambda s: s["selection"] == "manual", 5)
        sw.select("Auto", within="Grasps group")
        wait_state(server, lambda s: s["selection"] == "auto", 5)
        t_go = go(sw, server)
        finish_pick(server, t_go)
        print(f"scanning pick: {sw.presses} presses, {time.monotonic() - t0:.1f} s")
    finally:
        close_page(page)


def go(sw: Switch, server: ServeProcess, tries: int = 3) -> float:
    """Press on Go, and again, as a person would, where the pick has not started some scan
    periods later (on a loaded machine the page may take a press for the entry after Go).
    The time (monotonic s) of the press that started it."""
    for _ in range(tries):
        sw.select("Go", within="Grasps group")
        pressed = time.monotonic()
        try:
            wait_state(server, lambda s: s["state"] == "executing" or s["busy"], 8 * sw.period)
            return pressed
        except TimeoutError:
            continue
    raise AssertionError(f"the pick did not start after {tries} presses on Go")


# --- 2. STOP, driving and the gamepad ----------------------------------------------------

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
        # would add its 0.5 s at full speed: 15 cm more.
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
