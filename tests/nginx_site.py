"""nginx with the committed site (deploy/nginx/laserpick.conf) in front of a real `laserpick
serve`, for the tests that go through the proxy (tests/test_deploy.py, tests/test_view_door.py).

The real nginx binary (Debian's nginx-light, installed by scripts/bootstrap.sh) runs as the
current user with the committed site file, rewritten only where a test must: its listen ports
become free loopback ports (the IPv6 listens go), its certificate becomes a self-signed one
made here with the `openssl` CLI, and its upstreams point at the live server's ports. Each
rewrite is asserted to have happened exactly as often as expected, so a change to the
committed file that these regexes no longer match fails here instead of testing nothing.
"""

from __future__ import annotations

import http.client
import os
import re
import shutil
import socket
import ssl
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest
from serve_process import ServeProcess, free_port, stop_process

REPO = Path(__file__).resolve().parents[1]
SITE_CONF = REPO / "deploy" / "nginx" / "laserpick.conf"
NGINX = "/usr/sbin/nginx"
START_TIMEOUT = 90.0

#: Skip marks for a module that needs nginx and the `openssl` CLI.
NEEDS_NGINX = [
    pytest.mark.skipif(
        not os.access(NGINX, os.X_OK),
        reason=f"no nginx at {NGINX} (scripts/bootstrap.sh installs Debian's nginx-light)",
    ),
    pytest.mark.skipif(shutil.which("openssl") is None, reason="no `openssl` CLI to make a cert"),
]


def wait_for_port(port: int, proc: subprocess.Popen, timeout: float) -> None:
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
    """nginx with the site, in front of a live `laserpick serve` (`serve`)."""

    https_port: int
    http_port: int
    api_port: int
    viser_port: int
    tls: ssl.SSLContext
    ca: Path  #: the self-signed certificate, which `tls` trusts
    serve: ServeProcess

    @property
    def url(self) -> str:
        """The site's address, as a browser reaches it."""
        return f"https://127.0.0.1:{self.https_port}"

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


@contextmanager
def site_stack(
    tmp: Path,
    *,
    env: dict[str, str | None] | None = None,
    extra_args: tuple[str, ...] = (),
) -> Iterator[Stack]:
    """nginx with the site in front of a `laserpick serve` (with `env` and `extra_args`, as
    `ServeProcess` takes them), both on free loopback ports, files in `tmp`; stopped after."""
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

    serve = ServeProcess(
        tmp, api_port=api_port, viser_port=viser_port, env=env, extra_args=extra_args
    )
    web: subprocess.Popen | None = None
    try:
        serve.start(START_TIMEOUT)
        web = subprocess.Popen(nginx, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for_port(https_port, web, timeout=10)
        wait_for_port(viser_port, serve.proc, timeout=10)
        yield Stack(https_port, http_port, api_port, viser_port, tls, cert, serve)
        assert serve.proc.poll() is None, f"`laserpick serve` died:\n{serve.log()}"
    finally:
        if web is not None:
            stop_process(web)
        serve.close()
        err = tmp / "error.log"
        if err.exists():
            print("--- nginx error.log (tail) ---\n" + err.read_text()[-3000:])
