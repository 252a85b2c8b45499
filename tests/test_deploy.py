"""The deployment room: deploy/nginx/laserpick.conf in front of a real `laserpick serve`.

The real nginx binary (Debian's nginx-light, installed by scripts/bootstrap.sh) runs as the
current user with the committed site file, rewritten only where a test must: its listen ports
become free loopback ports (the IPv6 listens go), its certificate becomes a self-signed one
made here with the `openssl` CLI, and its upstreams point at the live server's ports. Each
rewrite is asserted to have happened exactly as often as expected, so a change to the
committed file that these regexes no longer match fails here instead of testing nothing.

Through nginx, over HTTPS verified against that certificate:
1. plain HTTP answers 301 to https;
2. `/` (the console page) and `/api/v1/health` (JSON) come from the app, with the security
   headers added;
3. the `/api/v1/events` websocket upgrades, says hello, and streams state frames at its pace
   (no proxy buffering), with a heartbeat sent along the way;
4. `/viser/` serves viser's client page (byte for byte what viser serves directly), and
   viser's websocket upgrades with its `viser-v<version>` subprotocol at `/viser` (where
   viser's client connects from a page at /viser/) and at `/viser/`, and delivers messages;
5. `laserpick.client.Client` holds control over https, its heartbeats keeping the lease,
   and hears every state frame.
"""

from __future__ import annotations

import asyncio
import http.client
import json
import os
import re
import shutil
import socket
import ssl
import subprocess
import time
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from serve_process import ServeProcess, free_port, stop_process

# The asyncio client, not websockets.sync: the sync client reads its TLS socket on a thread of
# its own while the caller writes, and one OpenSSL session must not be used from two threads
# (under load about 1 handshake in 75 was lost that way; with the asyncio client, none of 400).
from websockets.asyncio.client import connect as wss_connect

REPO = Path(__file__).resolve().parents[1]
SITE_CONF = REPO / "deploy" / "nginx" / "laserpick.conf"
NGINX = "/usr/sbin/nginx"
START_TIMEOUT = 90.0

pytestmark = [
    pytest.mark.skipif(
        not os.access(NGINX, os.X_OK),
        reason=f"no nginx at {NGINX} (scripts/bootstrap.sh installs Debian's nginx-light)",
    ),
    pytest.mark.skipif(shutil.which("openssl") is None, reason="no `openssl` CLI to make a cert"),
    pytest.mark.timeout(240),
]


def _wait_for_port(port: int, proc: subprocess.Popen, timeout: float) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if proc.poll() is not None:
            raise AssertionError(f"process exited with {proc.returncode} before port {port}")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return
        except OSError:
            time.sleep(0.05)
    raise AssertionError(f"nothing listening on 127.0.0.1:{port} after {timeout} s")


def _sub(pattern: str, repl: str, text: str, count: int) -> str:
    """re.subn that insists on exactly `count` replacements (multiline patterns)."""
    new, n = re.subn(pattern, repl, text, flags=re.MULTILINE)
    assert n == count, f"expected {count} match(es) of {pattern!r} in {SITE_CONF}, found {n}"
    return new


def rewrite_site(
    conf: str,
    *,
    http_port: int,
    https_port: int,
    cert: Path,
    key: Path,
    api_port: int,
    viser_port: int,
) -> str:
    """The committed site file with only ports and certificate paths changed."""
    # IPv6 listens go (the test binds loopback IPv4 only; both would collide once rewritten).
    conf = _sub(r"^[ \t]*listen[ \t]+\[::\]:(?:80|443)\b[^;]*;[ \t]*\n", "", conf, 2)
    conf = _sub(r"\blisten[ \t]+80;", f"listen 127.0.0.1:{http_port};", conf, 1)
    conf = _sub(r"\blisten[ \t]+443\b", f"listen 127.0.0.1:{https_port}", conf, 1)
    conf = _sub(r"\bssl_certificate[ \t]+[^;\s]+;", f"ssl_certificate {cert};", conf, 1)
    conf = _sub(r"\bssl_certificate_key[ \t]+[^;\s]+;", f"ssl_certificate_key {key};", conf, 1)
    conf = _sub(
        r"(upstream[ \t]+laserpick_api[ \t]*\{\s*server[ \t]+)127\.0\.0\.1:8000;",
        rf"\g<1>127.0.0.1:{api_port};",
        conf,
        1,
    )
    conf = _sub(
        r"(upstream[ \t]+laserpick_viser[ \t]*\{\s*server[ \t]+)127\.0\.0\.1:8080;",
        rf"\g<1>127.0.0.1:{viser_port};",
        conf,
        1,
    )
    # Nothing else may still point at the production ports.
    assert not re.search(r"\blisten[ \t]+(?!127\.0\.0\.1:)", conf), conf
    assert ":8000;" not in conf and ":8080;" not in conf, conf
    return conf


def nginx_main_conf(root: Path, site: Path) -> str:
    """A top-level nginx.conf that keeps every file nginx writes inside `root`."""
    return f"""\
daemon off;
worker_processes 1;
pid {root}/nginx.pid;
error_log {root}/error.log info;
events {{
    worker_connections 128;
}}
http {{
    access_log {root}/access.log;
    client_body_temp_path {root}/client_body;
    proxy_temp_path {root}/proxy;
    fastcgi_temp_path {root}/fastcgi;
    uwsgi_temp_path {root}/uwsgi;
    scgi_temp_path {root}/scgi;
    include {site};
}}
"""


@dataclass
class Stack:
    https_port: int
    http_port: int
    api_port: int
    viser_port: int
    tls: ssl.SSLContext
    ca: Path  #: the self-signed certificate, which `tls` trusts

    def get(self, path: str) -> tuple[int, dict[str, str], bytes]:
        conn = http.client.HTTPSConnection(
            "127.0.0.1", self.https_port, context=self.tls, timeout=10
        )
        try:
            conn.request("GET", path)
            resp = conn.getresponse()
            return resp.status, {k.lower(): v for k, v in resp.getheaders()}, resp.read()
        finally:
            conn.close()


@pytest.fixture(scope="module")
def stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Stack]:
    tmp = tmp_path_factory.mktemp("deploy")
    cert, key = tmp / "cert.pem", tmp / "key.pem"
    subprocess.run(
        [
            *["openssl", "req", "-x509", "-nodes", "-days", "2", "-newkey", "ec"],
            *["-pkeyopt", "ec_paramgen_curve:prime256v1", "-subj", "/CN=127.0.0.1"],
            *["-addext", "subjectAltName=IP:127.0.0.1"],
            *["-keyout", str(key), "-out", str(cert)],
        ],
        check=True,
        capture_output=True,
    )
    tls = ssl.create_default_context(cafile=str(cert))

    api_port, viser_port, http_port, https_port = (free_port() for _ in range(4))
    site = tmp / "laserpick.conf"
    site.write_text(
        rewrite_site(
            SITE_CONF.read_text(),
            http_port=http_port,
            https_port=https_port,
            cert=cert,
            key=key,
            api_port=api_port,
            viser_port=viser_port,
        )
    )
    main_conf = tmp / "nginx.conf"
    main_conf.write_text(nginx_main_conf(tmp, site))
    nginx = [NGINX, "-p", str(tmp), "-e", str(tmp / "error.log"), "-c", str(main_conf)]
    check = subprocess.run([*nginx, "-t"], capture_output=True, text=True)
    assert check.returncode == 0, f"nginx rejects the config:\n{check.stderr}"

    serve = ServeProcess(tmp, api_port=api_port, viser_port=viser_port)
    web: subprocess.Popen | None = None
    try:
        serve.start(START_TIMEOUT)
        web = subprocess.Popen(nginx, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _wait_for_port(https_port, web, timeout=10)
        _wait_for_port(viser_port, serve.proc, timeout=10)
        yield Stack(https_port, http_port, api_port, viser_port, tls, cert)
        assert serve.proc.poll() is None, f"`laserpick serve` died:\n{serve.log()}"
    finally:
        if web is not None:
            stop_process(web)
        serve.close()
        err = tmp / "error.log"
        if err.exists():
            print("--- nginx error.log (tail) ---\n" + err.read_text()[-3000:])


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
