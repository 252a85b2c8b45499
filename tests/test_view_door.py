"""The 3D view's door (`laserpick.console.view_door`): who may use the view's controls.

1. Real websocket handshakes to a real viser server, judged by the door: straight from
   loopback without a password, the station; behind a proxy (any forwarding header), or with
   a password set, a watcher, unless the client brings a token that holds the lease (the
   operator page's cookie); every command checks that token again. In a live session, a
   watcher's click changes nothing, not even the point the station's next click confirms.
2. Headless Chromium through the nginx site of deploy/, with the operator password set:
   `/viser/` without the password shows no controls; pressing everything it shows and
   clicking in the scene changes nothing (state, lease, laser, mode) and moves nothing (joint
   speeds, base pose). The operator page, once it took control with the password, gets the
   view's controls, and they act (a click aims the laser, Back drives) under its lease.
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pytest
import viser
from nginx_site import NGINX, Stack, site_stack
from page_driver import chromium
from serve_process import free_port
from test_console import wait_drawn
from websockets.sync.client import connect

from laserpick.client import Client
from laserpick.console import headless_chromium
from laserpick.console.default_camera import default_view_pixel
from laserpick.console.view_door import (
    LAPSED,
    WATCHING,
    Handshake,
    ViewDoor,
    Visitor,
    handshake_of,
)
from laserpick.server.lease import ControlLease
from laserpick.server.session import Conflict, TaskState


class DoorBench:
    """A viser server on loopback with a door at it; `visit` opens a real websocket."""

    def __init__(self) -> None:
        self.server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
        self.lease = ControlLease(timeout=30.0)
        self.door = ViewDoor(self.server, self.lease, password_set=False)
        self.visits = 0

    def visit(self, headers: dict[str, str] | None = None) -> tuple[int, Visitor]:
        """Open viser's websocket with `headers`, as viser's client does, and judge its
        handshake as the door does when the client arrives; its client id and the verdict.
        viser numbers the connections from 0."""
        url = f"ws://127.0.0.1:{self.server.get_port()}/"
        client_id, self.visits = self.visits, self.visits + 1
        with connect(
            url,
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            additional_headers=headers or {},
            open_timeout=10,
        ) as ws:
            ws.recv(timeout=10)  # the server has taken the connection in
            handshake = handshake_of(self.server, client_id)
            assert handshake is not None and handshake.peer == "127.0.0.1"
            for name, value in (headers or {}).items():
                assert handshake.headers[name.lower()] == value
            visitor = self.door.arrive(SimpleNamespace(client_id=client_id))
        return client_id, visitor


@pytest.fixture
def bench() -> Iterator[DoorBench]:
    b = DoorBench()
    try:
        yield b
    finally:
        b.server.stop()


def _as(client_id: int) -> SimpleNamespace:
    return SimpleNamespace(client_id=client_id)


def test_the_door_lets_in_loopback_without_a_password_and_no_one_else(bench: DoorBench) -> None:
    """Straight from loopback, no password: the station, which acts as the station (actor
    None). Through a proxy, whatever the header: a watcher, refused and told why."""
    _, visitor = bench.visit()
    assert visitor == Visitor(station=True, token=None) and visitor.controls
    for header in ("X-Forwarded-For", "X-Real-IP", "Forwarded"):
        cid, visitor = bench.visit({header: "203.0.113.7"})
        assert visitor == Visitor(station=False, token=None), header
        with pytest.raises(Conflict, match="only watches"):
            bench.door.actor(_as(cid), TaskState.IDLE)
    assert WATCHING.startswith("this 3D view only watches")
    # In-process callers (no client) are the station.
    assert bench.door.actor(None, TaskState.IDLE) is None


def test_with_a_password_only_the_lease_holder_s_token_lets_in(bench: DoorBench) -> None:
    """With a password, loopback is no pass. A cookie with the lease's token is, checked
    again at every command: once the lease passes on, the same client is refused."""
    bench.door.password_set = True
    _, visitor = bench.visit()
    assert visitor == Visitor(station=False, token=None) and not visitor.controls
    token = bench.lease.acquire("operator (browser page)", "console")
    _, visitor = bench.visit({"Cookie": "laserpick_lease=not-the-token"})
    assert not visitor.controls
    cid, visitor = bench.visit(
        {"Cookie": f"theme=dark; laserpick_lease={token}", "X-Forwarded-For": "203.0.113.7"}
    )
    assert visitor == Visitor(station=False, token=token)
    actor = bench.door.actor(_as(cid), TaskState.IDLE)
    assert actor is not None and (actor.source, actor.token) == ("console", token)
    bench.lease.release(token)
    bench.lease.acquire("switch adapter", "switch")
    with pytest.raises(Conflict) as refused:
        bench.door.actor(_as(cid), TaskState.IDLE)
    assert str(refused.value) == LAPSED
    # A client the door never judged (gone, or unknown) watches.
    with pytest.raises(Conflict, match="only watches"):
        bench.door.actor(_as(999), TaskState.IDLE)


def test_a_handshake_is_direct_only_from_loopback_without_forwarding() -> None:
    """The peer must be a loopback address (IPv4, IPv6, or IPv4 mapped into IPv6), and no
    proxy may have forwarded it; an unreadable handshake is a watcher's."""
    door = ViewDoor(None, ControlLease(timeout=30.0), password_set=False)  # type: ignore[arg-type]
    for peer in ("127.0.0.1", "127.3.4.5", "::1", "::ffff:127.0.0.1"):
        assert Handshake(peer, {}).direct_loopback, peer
    for peer in ("192.168.1.20", "::ffff:10.0.0.2", "2001:db8::1", "localhost", ""):
        assert not Handshake(peer, {}).direct_loopback, peer
    assert not Handshake("127.0.0.1", {"x-forwarded-for": "127.0.0.1"}).direct_loopback
    assert door.judge(None) == Visitor(station=False, token=None)
    assert Handshake("::1", {"cookie": 'a="b; laserpick_lease=tok'}).lease_token is None
    assert Handshake("::1", {"cookie": "laserpick_lease="}).lease_token is None


def test_a_watcher_s_click_leaves_the_operator_s_aim_alone(bench: DoorBench) -> None:
    """In the view of a live session: a watcher's click on the point the station aimed at is
    refused with the reason and changes nothing, so the station's second click there still
    confirms the mark."""
    import numpy as np

    from laserpick.console.operator_console import OperatorConsole, to_world
    from laserpick.robot.sim.robot import SimRobot
    from laserpick.robot.sim.scenes import load_scene
    from laserpick.robot.sim.truth import SimTruth
    from laserpick.server.session import Session

    session = Session(SimRobot(load_scene("isolation", seed=1), realtime=True))
    console = OperatorConsole(session, bench.server)
    said: list[str] = []
    watcher = SimpleNamespace(client_id=7, add_notification=lambda _t, body, **_: said.append(body))
    console.door.arrive(watcher)  # no such connection: a watcher
    try:
        truth = SimTruth(session.robot)
        pts = truth.object_points(truth.instances()[0])
        centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
        centre[2] = pts[:, 2].max() - 0.01  # on its top, as a camera above sees it
        origin = to_world(np.array([0.2, 0.0, 1.6]), session.robot.base_pose())

        def click(at_base: np.ndarray, client: object) -> None:
            direction = to_world(at_base, session.robot.base_pose()) - origin
            event = SimpleNamespace(ray_origin=origin, ray_direction=direction, client=client)
            console.on_click(event)

        click(centre, watcher)
        assert session.state == TaskState.IDLE and not session.lease.info().held
        assert said == [WATCHING]
        click(centre, None)  # the station (in-process): aims, taking the lease as "3D view"
        assert session.state == TaskState.AIMING and session.lease.info().holder == "3D view"
        aimed = console.aimed_at
        click(aimed, watcher)
        assert said == [WATCHING, WATCHING] and console.aimed_at is aimed
        assert session.state == TaskState.AIMING
        click(aimed, None)
        assert console.aimed_at is None and session.state != TaskState.AIMING
    finally:
        console.stop()
        session.close()


# --- 2. Chromium through the nginx site, with the operator password set --------------------

PASSWORD = "correct horse battery staple"
#: Every control the view's panel has, by its label.
CONTROL_LABELS = (
    *("Detect", "Previous", "Next", "Next candidate", "Go", "Cancel", "STOP", "Reset stop"),
    *("Forward", "Back", "Left", "Right", "Show cloud", "Mode", "Selection", "Strategy"),
)
#: ARIA roles of what a person can press, type in or choose in viser's page.
PRESSABLE = ("button", "checkbox", "combobox", "switch", "slider", "textbox", "tab", "menuitem")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Stack]:
    if not os.access(NGINX, os.X_OK) or shutil.which("openssl") is None:
        pytest.skip("needs nginx and the openssl CLI (scripts/bootstrap.sh)")
    with site_stack(
        tmp_path_factory.mktemp("viewdoor"),
        env={"LASERPICK_OPERATOR_PASSWORD": PASSWORD},
        extra_args=("--lite-view", "--viser-url", "/viser/"),  # as deploy/'s unit runs it
    ) as stack:
        yield stack


@pytest.fixture(scope="module")
def browser() -> Iterator[object]:
    sync_api = pytest.importorskip("playwright.sync_api")
    if not Path(headless_chromium.CHROMIUM).exists():
        pytest.skip("no Chromium at /usr/bin/chromium")
    yield from chromium(sync_api)


def _still(api: Client) -> dict:
    """What must not change: the task, the lease, the laser, the settings, the marks."""
    s = api.state()
    keys = ("state", "busy", "lease", "laser", "estopped", "mode", "selection", "strategy")
    return {k: s[k] for k in (*keys, "mark", "place_mark")}


def _motion(api: Client, before: dict) -> tuple[float, float]:
    """The largest joint speed now (rad/s) and how far the base is from `before`'s (m)."""
    s = api.state()
    moved = max(abs(s["base_pose"][i] - before["base_pose"][i]) for i in (0, 1))
    return max(map(abs, s["joints"]["qd"])), moved


def _mug(api: Client) -> list[float]:
    return next(o for o in api.get("/sim/objects") if o["name"] == "mug_1")["center_base"]


def test_through_the_proxy_without_the_password_the_view_moves_nothing(site, browser) -> None:
    """A browser at /viser/ through nginx, without the password: a watcher. It sees the
    scene and no control; pressing everything it shows and clicking in the scene (on the
    mug twice: aim, then confirm) changes nothing and moves nothing; a click is refused
    with the reason."""
    api = Client(site.serve.url, name="test observer")  # the referee, straight to the API
    still, at_rest = _still(api), api.state()
    context = browser.new_context(viewport={"width": 900, "height": 600}, ignore_https_errors=True)
    page = context.new_page()
    try:
        page.goto(site.url + "/viser/")
        page.get_by_text("Watching only").wait_for(timeout=60_000)
        wait_drawn(page)
        for label in CONTROL_LABELS:
            assert page.get_by_label(label, exact=True).count() == 0, label
            assert page.get_by_role("button", name=label, exact=True).count() == 0, label
        pressed = []
        for role in PRESSABLE:
            for control in page.get_by_role(role).all():
                if control.is_visible() and control.is_enabled():
                    pressed.append(f"{role} {control.text_content()!r}")
                    control.click(timeout=5_000)
                    page.keyboard.press("Escape")  # close whatever it opened
        box = page.locator("canvas").first.bounding_box()
        x, y = default_view_pixel(_mug(api), box["width"], box["height"])
        for dx, dy in ((0, 0), (0, 0), (-120, 40), (150, -60)):
            page.mouse.click(box["x"] + x + dx, box["y"] + y + dy)
            time.sleep(0.5)
        page.get_by_text("only watches").first.wait_for(timeout=10_000)
        print("pressed:", pressed)
        for _ in range(10):
            assert _still(api) == still
            speed, moved = _motion(api, at_rest)
            assert speed < 0.01 and moved < 1e-3, (speed, moved)
            time.sleep(0.2)
    finally:
        context.close()


def test_the_operator_page_s_view_acts_under_its_lease(site, browser) -> None:
    """The page through nginx: its view watches until the page takes control with the
    password; then the view (reopened with the page's lease) shows the controls, and they
    act for the page: Back drives, a click aims the laser, and the lease stays the page's."""
    api = Client(site.serve.url, name="test observer")  # the referee, straight to the API
    start = api.state()
    context = browser.new_context(viewport={"width": 1280, "height": 800}, ignore_https_errors=True)
    page = context.new_page()
    try:
        page.goto(site.url + "/")
        view = page.frame_locator("iframe#view")
        view.get_by_text("Watching only").wait_for(timeout=60_000)
        page.locator("#take").click()
        page.locator("#password").fill(PASSWORD)
        page.locator("#take").click()
        holder = api.wait_for(lambda s: s["lease"]["held"], timeout=10)["lease"]["holder"]
        assert holder == "operator (browser page)"
        view.get_by_role("button", name="Back", exact=True).click(timeout=60_000)
        # Any motion back is the view's command obeyed, which is what this test is about: a
        # pad step drives 10 cm on an idle machine, and has ended after 1-6 mm on a starved
        # one (two busy loops beside the test), where the page's heartbeats came late and the
        # dead-man halted the step at its end in wall time, the simulation far behind.
        api.wait_for(lambda s: s["base_pose"][0] < start["base_pose"][0] - 5e-4, timeout=10)
        time.sleep(4.0)  # the scene fades in after the view reopened
        box = view.locator("canvas").first.bounding_box()
        x, y = default_view_pixel(_mug(api), box["width"], box["height"])
        page.mouse.click(box["x"] + x, box["y"] + y)
        state = api.wait_for(lambda s: s["laser"]["on"], timeout=20)
        assert state["state"] == "aiming" and state["lease"]["holder"] == holder
    finally:
        context.close()
