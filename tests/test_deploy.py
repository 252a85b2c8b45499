"""The deployment room: deploy/nginx/laserpick.conf in front of a real `laserpick serve`
(tests/nginx_site.py runs the real nginx with the committed site, rewritten only for ports
and the certificate).

Through nginx, over HTTPS verified against that certificate:
1. plain HTTP answers 301 to https;
2. `/` (the console page) and `/api/v1/health` (JSON) come from the app, with the security
   headers added; every script of the page (page.js and its modules) comes as JavaScript;
3. the `/api/v1/events` websocket upgrades, says hello, and streams state frames at its pace
   (no proxy buffering), with a heartbeat sent along the way;
4. `/viser/` serves viser's client page (byte for byte what viser serves directly), and
   viser's websocket upgrades with its `viser-v<version>` subprotocol at `/viser` (where
   viser's client connects from a page at /viser/) and at `/viser/`, and delivers messages;
5. `laserpick.client.Client` holds control over https, its heartbeats keeping the lease,
   and hears every state frame;
6. headless Chromium at `/viser/` is a watcher of the 3D view, with no controls, even with
   no password set (tests/test_view_door.py presses them with the password set).
"""

from __future__ import annotations

import asyncio
import http.client
import json
import time
import urllib.request
from collections.abc import Iterator

import pytest
from nginx_site import NEEDS_NGINX, Stack, site_stack
from page_driver import page_script_files, page_scripts

# The asyncio client, not websockets.sync: the sync client reads its TLS socket on a thread of
# its own while the caller writes, and one OpenSSL session must not be used from two threads
# (under load about 1 handshake in 75 was lost that way; with the asyncio client, none of 400).
from websockets.asyncio.client import connect as wss_connect

pytestmark = [*NEEDS_NGINX, pytest.mark.timeout(240)]


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Stack]:
    with site_stack(tmp_path_factory.mktemp("deploy")) as s:
        yield s


def test_http_redirects_to_https(stack: Stack) -> None:
    conn = http.client.HTTPConnection("127.0.0.1", stack.http_port, timeout=10)
    try:
        conn.request("GET", "/api/v1/health?x=1")
        resp = conn.getresponse()
        resp.read()
    finally:
        conn.close()
    assert resp.status == 301
    assert resp.getheader("Location") == "https://127.0.0.1/api/v1/health?x=1"


def test_page_and_health_through_the_proxy(stack: Stack) -> None:
    status, headers, body = stack.get("/api/v1/health")
    assert status == 200, body[:500]
    assert headers["content-type"].startswith("application/json")
    assert isinstance(json.loads(body), dict)
    # The security headers ride on every response.
    assert headers["strict-transport-security"].startswith("max-age=")
    assert headers["x-content-type-options"] == "nosniff"
    assert headers["x-frame-options"] == "SAMEORIGIN"
    assert "server" not in headers or "/" not in headers["server"]  # server_tokens off

    status, headers, body = stack.get("/")
    assert status == 200, body[:500]
    assert headers["content-type"].startswith("text/html")


def test_the_page_s_scripts_through_the_proxy(stack: Stack) -> None:
    # A browser runs a module script only when it comes as JavaScript (and nosniff holds the
    # others to that too): the proxy passes the app's types through.
    assert page_scripts(stack.get) == page_script_files()


def test_events_websocket_streams_state_through_the_proxy(stack: Stack) -> None:
    async def stream() -> float:
        url = f"wss://127.0.0.1:{stack.https_port}/api/v1/events"
        async with wss_connect(url, ssl=stack.tls, open_timeout=10, close_timeout=2) as ws:
            hello = json.loads(await asyncio.wait_for(ws.recv(), 10))
            assert hello["type"] == "hello", hello
            t0 = time.monotonic()
            states = 0
            while states < 15:
                msg = json.loads(await asyncio.wait_for(ws.recv(), 5))
                if msg["type"] == "state":
                    states += 1
                    if states == 5:
                        await ws.send(json.dumps({"type": "heartbeat"}))
            return time.monotonic() - t0

    elapsed = asyncio.run(stream())
    # 15 frames at 30 Hz is half a second; a buffering proxy would hold them back in bulk.
    assert elapsed < 4.0, f"15 state frames took {elapsed:.1f} s through the proxy"


def test_a_client_over_https_holds_control_and_hears_every_frame(
    stack: Stack, monkeypatch: pytest.MonkeyPatch
) -> None:
    """laserpick.client.Client (what adapters on other machines use) through nginx: its
    heartbeats keep the lease and no state frame is lost, on a TLS session its events
    thread both reads and writes."""
    from laserpick.client import Client

    # Trust the test's certificate: ssl's default context reads SSL_CERT_FILE, requests
    # reads REQUESTS_CA_BUNDLE.
    monkeypatch.setenv("SSL_CERT_FILE", str(stack.ca))
    monkeypatch.setenv("REQUESTS_CA_BUNDLE", str(stack.ca))
    url = f"https://127.0.0.1:{stack.https_port}"
    with Client(url, name="tls adapter", timeout=10) as client:
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            lease = client.state()["lease"]
            assert lease["held"] and lease["holder"] == "tls adapter", lease
            time.sleep(0.25)
        frames, gaps = client.frames, client.gaps
    # 3 s of 30 Hz frames; a lost one shows as a gap in `seq`.
    assert frames >= 45 and gaps == 0, f"{frames} frames, {gaps} lost"
    status, _, body = stack.get("/api/v1/state")
    assert status == 200 and not json.loads(body)["lease"]["held"], "release did not reach"


def test_viser_page_through_the_proxy(stack: Stack) -> None:
    status, headers, body = stack.get("/viser/")
    assert status == 200
    assert headers["content-type"].startswith("text/html")
    assert b"<title>Viser</title>" in body
    with urllib.request.urlopen(f"http://127.0.0.1:{stack.viser_port}/", timeout=10) as r:
        assert body == r.read(), "the proxied /viser/ page differs from viser's own"
    # A plain GET of /viser (no slash) is sent to the page.
    status, headers, _ = stack.get("/viser")
    assert status == 301
    assert headers["location"].endswith("/viser/")


@pytest.mark.parametrize("path", ["/viser", "/viser/"])
def test_viser_websocket_through_the_proxy(stack: Stack, path: str) -> None:
    from viser import __version__ as viser_version

    # viser's client asks for the `viser-v<version>` subprotocol and the server drops a
    # connection whose version does not match; a page at /viser/ connects to wss://.../viser.
    protocol = f"viser-v{viser_version}"

    async def talk() -> None:
        url = f"wss://127.0.0.1:{stack.https_port}{path}"
        async with wss_connect(
            url, ssl=stack.tls, subprotocols=[protocol], open_timeout=30, close_timeout=2
        ) as ws:
            assert ws.subprotocol == protocol
            first = await asyncio.wait_for(ws.recv(), 30)
            assert isinstance(first, bytes) and first, "viser sent an empty first message"
            await asyncio.wait_for(ws.recv(), 30)  # and keeps talking

    asyncio.run(talk())


def test_the_3d_view_through_the_proxy_only_watches(stack: Stack) -> None:
    """Without a password too, a browser that reaches `/viser/` through nginx is no
    operator station (nginx's forwarding headers say so): its panel has no controls."""
    sync_api = pytest.importorskip("playwright.sync_api")
    from laserpick.console import headless_chromium

    with sync_api.sync_playwright() as p:
        browser = headless_chromium.launch(p)
        try:
            page = browser.new_page(ignore_https_errors=True)
            page.goto(stack.url + "/viser/")
            page.get_by_text("Watching only").wait_for(timeout=60_000)
            for label in ("Detect", "Go", "STOP", "Forward"):
                assert page.get_by_role("button", name=label, exact=True).count() == 0
        finally:
            browser.close()
