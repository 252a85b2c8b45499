"""What the server claims about who may command the robot, tried on a real `laserpick serve`.

- With `LASERPICK_OPERATOR_PASSWORD` set, `POST /api/v1/control` without the password, or
  with a wrong one, is 401 and leaves the lease free; the right one gives a token that drives.
- `laserpick serve` without `--host` listens on 127.0.0.1 only, the API's port and the 3D
  view's alike. How it is checked: the listening TCP sockets of the server's process (and of
  any child it started) are read from Linux's own tables: each socket inode among the
  processes' file descriptors (`/proc/PID/fd`) is looked up in the LISTEN rows of
  `/proc/PID/net/tcp` and `tcp6`, whose local addresses are decoded; every one must be
  127.0.0.1. Where the machine has a non-loopback address, connecting there is refused too.
- A client that does not hold the lease is refused (401) on every route that commands the
  robot, table-driven over `/openapi.json`: each POST, PUT and DELETE route but taking
  control and the e-stop, which anyone may use, is called with a body the app's own request
  model accepts, without a token, with a made-up one and with a former holder's; nothing
  changes (the session's state, the objects, the journal).
- Malformed frames on the events websocket (binary, over the size limit, not JSON, JSON of
  the wrong shape or types, unknown message names, nesting deeper than the parser goes) are
  answered with an error or the socket is closed with a clean code; `GET /health` still
  answers 200 after each, and the lease holder keeps its lease. Nonsense on the 3D view's
  websocket (viser's own code, which drops that socket) leaves the server and the view
  answering.

    MUJOCO_GL=egl .venv/bin/python -m pytest -q tests/test_security.py
"""

from __future__ import annotations

import contextlib
import ipaddress
import json
import os
import socket
import struct
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import requests
from serve_process import ServeProcess
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from laserpick.client import API, Client
from laserpick.server import schemas

pytestmark = pytest.mark.timeout(300)

PASSWORD = "correct horse battery staple"

#: The command routes anyone may use, by the code (routers/control.py, routers/motion.py):
#: taking control (the password and the lease guard it) and the e-stop.
OPEN_TO_ANYONE = frozenset({f"POST {API}/control", f"POST {API}/stop"})

#: Every other command route, with a body its request model accepts (None: it takes none).
LEASE_ROUTES: dict[str, dict[str, Any] | None] = {
    f"DELETE {API}/control": None,
    f"POST {API}/laser/aim": {"yaw": 0.1, "pitch": -0.3},
    f"POST {API}/laser/nudge": {"dyaw": 0.02, "dpitch": -0.02},
    f"POST {API}/laser/confirm": None,
    f"DELETE {API}/laser": None,
    f"POST {API}/detect": None,
    f"POST {API}/grasps/next": {"level": "candidate"},
    f"POST {API}/grasps/prev": {"level": "cluster"},
    f"POST {API}/grasps/select": {"cluster": 0, "candidate": 1},
    f"POST {API}/grasps/auto": None,
    f"POST {API}/execute": None,
    f"POST {API}/cancel": None,
    f"POST {API}/mode": {"mode": "pick_and_place", "selection": "manual"},
    f"POST {API}/drive": {"v": 0.2, "w": 0.1, "duration": 0.3},
    f"POST {API}/stop/reset": None,
    f"POST {API}/scene": {"name": "kitchen"},
}

COMMAND_METHODS = ("post", "put", "patch", "delete")


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServeProcess]:
    """A server with an operator password."""
    proc = ServeProcess(
        tmp_path_factory.mktemp("secure"), env={"LASERPICK_OPERATOR_PASSWORD": PASSWORD}
    )
    try:
        yield proc.start()
    finally:
        proc.close()


def lease_of(server: ServeProcess) -> dict[str, Any]:
    r = requests.get(f"{server.url}{API}/state", timeout=10)
    r.raise_for_status()
    return r.json()["lease"]


# --- the password ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "body",
    [
        {"name": "intruder"},
        {"name": "intruder", "password": None},
        {"name": "intruder", "password": ""},
        {"name": "intruder", "password": "guess"},
        {"name": "intruder", "password": PASSWORD.upper()},
        {"name": "intruder", "password": PASSWORD[:-1]},
        {"name": "intruder", "password": PASSWORD + " "},
    ],
    ids=["missing", "null", "empty", "wrong", "other-case", "prefix", "longer"],
)
def test_control_without_the_password_is_401_and_takes_nothing(
    server: ServeProcess, body: dict[str, Any]
) -> None:
    assert not lease_of(server)["held"]
    r = requests.post(f"{server.url}{API}/control", json=body, timeout=10)
    taken = r.json().get("token") if r.ok else None
    try:
        assert r.status_code == 401, r.text
        assert lease_of(server) == {"held": False, "holder": None, "source": None}
    finally:  # a lease wrongly given is given back, so that it fails only this test
        if taken is not None:
            auth = {"Authorization": f"Bearer {taken}"}
            requests.delete(f"{server.url}{API}/control", headers=auth, timeout=10)


def test_the_right_password_gives_a_token_that_commands(server: ServeProcess) -> None:
    assert not lease_of(server)["held"]
    body = {"name": "operator", "password": PASSWORD}
    r = requests.post(f"{server.url}{API}/control", json=body, timeout=10)
    assert r.status_code == 200, r.text
    token = r.json()["token"]
    try:
        assert lease_of(server) == {"held": True, "holder": "operator", "source": "rest"}
        auth = {"Authorization": f"Bearer {token}"}
        drive = {"v": 0.0, "w": 0.0, "duration": 0.1}
        r = requests.post(f"{server.url}{API}/drive", json=drive, headers=auth, timeout=10)
        assert r.status_code == 200, r.text
        nudge = {"dyaw": 0.01}
        r = requests.post(f"{server.url}{API}/laser/nudge", json=nudge, headers=auth, timeout=10)
        assert r.status_code == 200, r.text
    finally:
        auth = {"Authorization": f"Bearer {token}"}
        requests.delete(f"{server.url}{API}/control", headers=auth, timeout=10)
    assert not lease_of(server)["held"]


# --- the default bind address ------------------------------------------------------------------


def _descendants(pid: int) -> set[int]:
    """`pid` and every process below it, from each process's parent in /proc/PID/stat."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    found, frontier = {pid}, [pid]
    while frontier:
        parent = frontier.pop()
        children = [p for p, pp in parents.items() if pp == parent and p not in found]
        found.update(children)
        frontier.extend(children)
    return found


def _decode(hex_address: str) -> tuple[str, int]:
    """An address of /proc/net/tcp{,6} ("0100007F:1F90"): the IP, in its kernel's byte order
    (32-bit words in host order), and the port."""
    ip_hex, port_hex = hex_address.split(":")
    words = [int(ip_hex[i : i + 8], 16) for i in range(0, len(ip_hex), 8)]
    packed = b"".join(struct.pack("=I", w) for w in words)
    return str(ipaddress.ip_address(packed)), int(port_hex, 16)


def listening_addresses(pid: int) -> list[tuple[str, int]]:
    """(IP, port) of every TCP socket in LISTEN held by `pid` or a process below it."""
    inodes: set[str] = set()
    for p in _descendants(pid):
        fd_dir = Path(f"/proc/{p}/fd")
        try:
            links = [os.readlink(fd) for fd in fd_dir.iterdir()]
        except OSError:
            continue
        inodes.update(link[8:-1] for link in links if link.startswith("socket:["))
    out = []
    for table in ("tcp", "tcp6"):
        path = Path(f"/proc/{pid}/net/{table}")
        if not path.exists():
            continue
        for row in path.read_text().splitlines()[1:]:
            fields = row.split()
            if fields[3] == "0A" and fields[9] in inodes:  # 0A: TCP_LISTEN
                out.append(_decode(fields[1]))
    return sorted(out)


def _outward_address() -> str | None:
    """This machine's address toward the outside (no packet is sent), or None."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            s.connect(("192.0.2.1", 9))  # TEST-NET-1: only the route is looked up
        except OSError:
            return None
        address = s.getsockname()[0]
    return None if ipaddress.ip_address(address).is_loopback else address


def test_serve_without_host_listens_on_loopback_only(tmp_path: Path) -> None:
    server = ServeProcess(tmp_path, host=None)
    try:
        server.start()
        listening = listening_addresses(server.proc.pid)
        ports = {port for _, port in listening}
        assert {server.api_port, server.viser_port} <= ports, listening
        assert all(ip == "127.0.0.1" for ip, _ in listening), listening
        assert requests.get(f"{server.url}{API}/health", timeout=10).status_code == 200
        outward = _outward_address()
        for port in (server.api_port, server.viser_port) if outward else ():
            with pytest.raises(ConnectionRefusedError):
                socket.create_connection((outward, port), timeout=5).close()
    finally:
        server.close()


# --- a client that does not hold the lease -----------------------------------------------------


def _model_names(schema: Any) -> set[str]:
    """The component names a request body's schema refers to."""
    if isinstance(schema, dict):
        ref = schema.get("$ref")
        names = {ref.rsplit("/", 1)[1]} if isinstance(ref, str) else set()
        return names.union(*(_model_names(v) for v in schema.values()))
    if isinstance(schema, list):
        return set().union(*(_model_names(v) for v in schema))
    return set()


def command_routes(openapi: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """ "METHOD path" -> operation, for every route that may change something."""
    return {
        f"{method.upper()} {path}": op
        for path, item in openapi["paths"].items()
        for method, op in item.items()
        if method in COMMAND_METHODS
    }


def _snapshot(server: ServeProcess) -> dict[str, Any]:
    get = lambda path: requests.get(f"{server.url}{API}{path}", timeout=10).json()  # noqa: E731
    return {"state": get("/state"), "objects": get("/sim/objects"), "journal": get("/journal")}


def _assert_unchanged(before: dict[str, Any], after: dict[str, Any]) -> None:
    s0, s1 = before["state"], after["state"]
    exact = [
        k for k in s0 if k not in ("sim_time", "read_at", "rtf", "joints", "base_pose", "gripper")
    ]
    assert {k: s1[k] for k in exact} == {k: s0[k] for k in exact}
    np.testing.assert_allclose(s1["joints"]["q"], s0["joints"]["q"], atol=1e-3)
    np.testing.assert_allclose(s1["base_pose"], s0["base_pose"], atol=1e-3)
    assert s1["gripper"]["closed"] == s0["gripper"]["closed"]
    assert abs(s1["gripper"]["width"] - s0["gripper"]["width"]) < 1e-3
    for o0, o1 in zip(before["objects"], after["objects"], strict=True):
        assert o1["name"] == o0["name"]
        np.testing.assert_allclose(o1["position_world"], o0["position_world"], atol=1e-3)
    assert after["journal"] == before["journal"]


def test_the_openapi_routes_that_need_the_lease_are_all_in_the_table(
    server: ServeProcess,
) -> None:
    openapi = requests.get(f"{server.url}/openapi.json", timeout=10).json()
    routes = command_routes(openapi)
    # Open to anyone: no security, or an empty alternative (the token is optional).
    open_routes = {k for k, op in routes.items() if {} in op.get("security", [{}])}
    assert open_routes == OPEN_TO_ANYONE
    assert set(routes) - OPEN_TO_ANYONE == set(LEASE_ROUTES), "a command route with no row"
    for label, body in LEASE_ROUTES.items():
        content = routes[label].get("requestBody", {}).get("content", {})
        names = _model_names(content.get("application/json", {}).get("schema", {}))
        if body is None:
            assert not routes[label].get("requestBody", {}).get("required"), label
            continue
        assert len(names) == 1, (label, names)
        getattr(schemas, names.pop()).model_validate(body)  # the app's own model accepts it


def test_a_client_without_the_lease_is_refused_on_every_command_route(
    server: ServeProcess,
) -> None:
    former = Client(server.url, name="former", password=PASSWORD)
    former.take_control()
    stale = former.token
    former.release()
    with Client(server.url, name="holder", password=PASSWORD) as holder:
        # With grasps ready, an accepted /execute or /grasps/next would show at once.
        mug = next(o for o in holder.get("/sim/objects") if o["name"] == "mug_1")
        holder.post("/laser/aim", {"point": mug["center_base"]})
        holder.post("/laser/confirm")
        assert holder.settled(60)["state"] == "grasps_ready"
        before = _snapshot(server)
        refusals: list[str] = []
        for who, headers in (
            ("no token", {}),
            ("a made-up token", {"Authorization": "Bearer not-the-token"}),
            ("a former holder's token", {"Authorization": f"Bearer {stale}"}),
        ):
            for label, body in LEASE_ROUTES.items():
                method, path = label.split(" ", 1)
                r = requests.request(
                    method, f"{server.url}{path}", json=body, headers=headers, timeout=30
                )
                if r.status_code != 401 or r.headers.get("www-authenticate") != "Bearer":
                    refusals.append(f"{label} with {who}: {r.status_code} {r.text[:200]}")
        # The right password does not take a held lease either.
        r = requests.post(
            f"{server.url}{API}/control",
            json={"name": "intruder", "password": PASSWORD},
            timeout=10,
        )
        assert r.status_code == 409, r.text
        time.sleep(0.5)  # a command that got through would have begun to act by now
        assert not refusals, "\n".join(refusals)
        _assert_unchanged(before, _snapshot(server))
        assert holder.state()["lease"]["holder"] == "holder"
        holder.post("/grasps/next", {"level": "candidate"})  # the holder still commands


# --- malformed frames on the events websocket --------------------------------------------------

#: Close codes that end a socket cleanly: normal, unsupported data, invalid payload, policy,
#: message too big. Not 1011 (the server's handler failed) nor 1006 (no close frame at all).
CLEAN_CLOSE = frozenset({1000, 1003, 1007, 1008, 1009})
MAX_WS_BYTES = 16 * 2**20  #: uvicorn's default limit on a websocket message

MALFORMED: dict[str, str | bytes] = {
    "binary": b"\x00\xff\x10 binary",
    "binary JSON": json.dumps({"type": "heartbeat"}).encode(),
    "over the size limit": "x" * (MAX_WS_BYTES + 2**20),
    "not JSON": "{this is not json",
    "empty": "",
    "NaN": "NaN",
    "a JSON list": json.dumps(["heartbeat"]),
    "a JSON number": "42",
    "JSON null": "null",
    "a JSON string": json.dumps("heartbeat"),
    "type not a string": json.dumps({"type": 5}),
    "type a list": json.dumps({"type": ["heartbeat"]}),
    "token a number": json.dumps({"type": "heartbeat", "token": 12345}),
    "token an object": json.dumps({"type": "heartbeat", "token": {"$ne": None}}),
    "token huge": json.dumps({"type": "heartbeat", "token": "t" * 1_000_000}),
    "sent an object": json.dumps({"type": "heartbeat", "token": "nope", "sent": {"a": [1]}}),
    "unknown name": json.dumps({"type": "execute"}),
    "unknown name with a token": json.dumps({"type": "take_control", "token": "x"}),
    "nested deeper than the parser goes": "[" * 200_000 + "]" * 200_000,
}


def _answer(ws: ClientConnection, timeout: float = 10.0) -> str:
    """After a frame was sent: "error" once the server answers one, or "closed CODE"."""
    end = time.monotonic() + timeout
    try:
        while time.monotonic() < end:
            try:
                msg = json.loads(ws.recv(timeout=max(end - time.monotonic(), 0.01)))
            except TimeoutError:
                break
            if msg.get("type") == "error":
                return "error"
    except ConnectionClosed:
        return f"closed {ws.close_code}"
    return "no answer"


@pytest.mark.parametrize("frame", list(MALFORMED.values()), ids=list(MALFORMED))
def test_a_malformed_websocket_frame_never_hurts_the_server(
    server: ServeProcess, frame: str | bytes
) -> None:
    logged = server.stderr_path.stat().st_size
    with Client(server.url, name="holder", password=PASSWORD) as holder:
        with connect(f"ws{server.url[4:]}{API}/events", max_size=2**22) as ws:
            assert json.loads(ws.recv(timeout=10))["type"] == "hello"
            # Closed while the frame was being written: `_answer` says how.
            with contextlib.suppress(ConnectionClosed):
                ws.send(frame)
            answer = _answer(ws)
        ok = answer == "error" or (
            answer.startswith("closed ") and int(answer.split()[1]) in CLEAN_CLOSE
        )
        assert ok, f"the server's answer: {answer}\n{server.log()[-3000:]}"
        assert requests.get(f"{server.url}{API}/health", timeout=10).status_code == 200
        assert server.proc.poll() is None
        assert holder.state()["lease"]["holder"] == "holder"
        server.log()  # flushes stderr
        with server.stderr_path.open() as f:
            f.seek(logged)
            errors = f.read()
        assert "Traceback" not in errors, errors[-3000:]


# --- malformed frames on the 3D view's websocket ---------------------------------------------


def _msgpack_map(**fields: str) -> bytes:
    """A msgpack map of short strings (what viser's messages are), written out by hand."""

    def text(s: str) -> bytes:
        data = s.encode()
        assert len(data) < 32
        return bytes([0xA0 | len(data)]) + data

    return bytes([0x80 | len(fields)]) + b"".join(text(k) + text(v) for k, v in fields.items())


VIEW_MALFORMED: dict[str, str | bytes] = {
    "text": json.dumps({"type": "GuiUpdateMessage"}),
    "not msgpack": b"\xc1\xc1\xc1 not msgpack",
    "unknown message": _msgpack_map(type="NoSuchMessage"),
    "known message, no fields": _msgpack_map(type="GuiUpdateMessage"),
    "wrong types": _msgpack_map(type="ViewerCameraMessage", wxyz="up", position="far"),
}


@pytest.mark.parametrize("frame", list(VIEW_MALFORMED.values()), ids=list(VIEW_MALFORMED))
def test_a_malformed_3d_view_frame_never_hurts_the_server(
    server: ServeProcess, frame: str | bytes
) -> None:
    """The 3D view's websocket (viser's own code) may drop the socket that sent nonsense,
    but the server, its API and the view for everyone else carry on."""
    import viser

    url = f"ws://127.0.0.1:{server.viser_port}/"
    protocol = [f"viser-v{viser.__version__}"]
    with connect(url, subprotocols=protocol, max_size=2**26) as ws:  # type: ignore[list-item]
        ws.recv(timeout=10)  # the scene starts arriving
        with contextlib.suppress(ConnectionClosed, TimeoutError):
            ws.send(frame)
            end = time.monotonic() + 3.0
            while time.monotonic() < end:  # until it closes, or for 3 s
                ws.recv(timeout=1.0)
    assert server.proc.poll() is None
    assert requests.get(f"{server.url}{API}/health", timeout=10).status_code == 200
    with connect(url, subprotocols=protocol, max_size=2**26) as ws:  # type: ignore[list-item]
        assert ws.recv(timeout=10)  # a fresh viewer still gets the scene
