"""The browser page at `/` (laserpick/static/), in Debian's headless Chromium against a live
`laserpick serve` (conftest's `page_stack`, shared with test_page_switch_and_pad.py).

1. The page loads, embeds the 3D view, and the view renders (test-artifacts/page.png); the
   mug marked by arrow keys and Detect shows lit, with its grasps (page-grasps.png). The
   page takes the laser's nudge limit from the server's /health. Its scripts (page.js and
   the modules of page/) are served as JavaScript, and the package ships every file of it.
2. Every control has an accessible name (Chromium's own computation) and a target of 44 px
   or more.
3. A keyboard-only pick: Tab, Space and arrow keys aim the laser at the mug (the presses are
   computed from ground truth, as a person would look), then Detect, Next, Previous, Auto
   and Go; the mug ends in the basket.

Switch scanning, the gamepad, Esc and driving: test_page_switch_and_pad.py.
"""

from __future__ import annotations

import time
import tomllib
from urllib.parse import parse_qs, urlsplit

import pytest
from page_driver import (
    ARTIFACTS,
    REPO,
    STATIC,
    aim_by_keys,
    close_page,
    direct_get,
    finish_pick,
    fresh_scene,
    mug,
    observer,
    open_page,
    page_script_files,
    page_scripts,
    tab_to,
    wait_state,
)
from screenshots import pixel_stats
from serve_process import ServeProcess

pytest.importorskip("playwright.sync_api")


@pytest.fixture
def server(page_stack) -> ServeProcess:
    return page_stack.server


@pytest.fixture
def browser(page_stack) -> object:
    return page_stack.browser


@pytest.fixture
def page(browser, server: ServeProcess):
    p = open_page(browser, server)
    yield p
    close_page(p)


# --- 1. the page and its 3D view ---------------------------------------------------------


def test_page_loads_and_the_3d_view_renders(browser, server: ServeProcess) -> None:
    fresh_scene(server)  # idle, the mug on the table, whichever page test ran before
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


#: The page's module of shared state (laserpick/static/page/shared.js), imported in the page
#: from the address the page's own modules import it from.
_SHARED_MODULE = "import(new URL('static/page/shared.js', document.baseURI).href)"


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
    # The laser's nudge limit is the server's (GET /health), not one of the page's own: the
    # value the page nudges with, read from its module (a module is one instance per address,
    # so this is the page's own, which its newest frame shows).
    health = observer(server).get("/health")
    nudge_limit, has_frame = page.evaluate(
        _SHARED_MODULE + ".then(({ shared }) => [shared.maxNudge, shared.latest !== null])"
    )
    assert has_frame and nudge_limit == health.get("max_nudge")

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


def test_the_page_s_scripts_are_javascript_and_shipped(server: ServeProcess) -> None:
    """Every script the page runs comes with a JavaScript type (a browser runs no module
    script of another), and they are every .js of static/ but the 3D view's. pyproject's
    package data names every file of static/, page/ too: the container's `pip install .`
    ships only those."""
    assert page_scripts(direct_get(server)) == page_script_files()
    data = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    package = STATIC.parent
    shipped = {p for g in data["package-data"]["laserpick"] for p in package.glob(g)}
    missing = {p for p in STATIC.rglob("*") if p.is_file()} - shipped
    assert not missing, sorted(str(p.relative_to(package)) for p in missing)


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
