"""Load on the API: many watchers and one busy controller, against a live `laserpick serve`.

Starts `laserpick serve --scene isolation` on free ports with a journal in a temporary
directory (or uses the server at `--url`), then for `--seconds` runs:

* `--readers` read clients (default 20), each with an events websocket (counting the state
  frames it receives and the gaps in `seq`, i.e. messages the server dropped for it) and a
  thread polling `GET /api/v1/state` at `--read-hz` (default 5);
* one controller holding the lease (heartbeating on its own websocket, as `Client` does) and
  sending `--command-hz` commands a second (default 50), one after another: `POST /laser/nudge`
  by +-0.01 rad and `POST /laser/aim` by yaw and pitch, in turn (both allowed in idle and
  aiming). 409s (state conflicts) are counted apart from errors (any other status, or no
  answer);
* a sampler reading the simulation's real-time factor (`rtf` of `GET /api/v1/health`, the
  sim's own last 0.5 s) once a second.

It prints command latency p50/p99/max, read latency p50/p99/max, websocket frames per client
(Hz) and dropped messages (total and %), errors, and the real-time factor (min and mean of the
samples, and sim time over wall time for the whole run).

    MUJOCO_GL=egl .venv/bin/python bench/api_load.py [--seconds 60] [--url http://HOST:PORT]

`--url` must be a server whose lease is free (the controller takes it, and gives it back at
the end). The exit code is 0 unless the server could not be started or the lease taken.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

try:
    import laserpick  # noqa: F401
except ImportError:  # run as a script from a checkout without `pip install -e .`
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import requests
from websockets.exceptions import WebSocketException
from websockets.sync.client import connect

from laserpick.client import API, ApiError, Client

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

from serve_process import ServeProcess  # noqa: E402

# --- the load ------------------------------------------------------------------------------


@dataclass
class Stats:
    """What one thread saw. Latencies in seconds."""

    latencies: list[float] = field(default_factory=list)
    statuses: Counter[int] = field(default_factory=Counter)
    errors: Counter[str] = field(default_factory=Counter)  #: no answer, by exception type
    frames: int = 0  #: state frames received on the websocket
    messages: int = 0  #: messages with a `seq` received
    gaps: int = 0  #: messages dropped by the server (gaps in `seq`)
    rtf: list[float] = field(default_factory=list)


def paced(period: float, start: float, stop: threading.Event) -> Iterator[None]:
    """Yield at start, start + period, ... until `stop`. Late ticks are made up at once (the
    rate holds on average) unless a whole second behind (then the schedule restarts)."""
    next_at = start
    while not stop.is_set():
        delay = next_at - time.perf_counter()
        if delay > 0 and stop.wait(delay):
            return
        yield
        next_at += period
        if next_at < time.perf_counter() - 1.0:
            next_at = time.perf_counter()


def watch_events(url: str, go: threading.Event, stop: threading.Event, out: Stats) -> None:
    """Read the events websocket: count state frames and gaps in `seq` once `go` is set."""
    last = 0
    try:
        with connect("ws" + url[len("http") :] + f"{API}/events", max_size=2**22) as ws:
            while not stop.is_set():
                try:
                    msg = json.loads(ws.recv(timeout=0.5))
                except TimeoutError:
                    continue
                seq = msg.get("seq")
                if not isinstance(seq, int) or not go.is_set() or stop.is_set():
                    continue
                if last and seq > last + 1:
                    out.gaps += seq - last - 1
                last = seq
                out.messages += 1
                out.frames += msg.get("type") == "state"
    except (WebSocketException, OSError) as exc:
        if not stop.is_set():
            out.errors[f"websocket: {type(exc).__name__}"] += 1


def poll_state(url: str, hz: float, start: float, stop: threading.Event, out: Stats) -> None:
    """GET /state at `hz` from `start` on."""
    http = requests.Session()
    for _ in paced(1.0 / hz, start, stop):
        t0 = time.perf_counter()
        try:
            r = http.get(f"{url}{API}/state", timeout=10)
        except requests.RequestException as exc:
            out.errors[type(exc).__name__] += 1
            continue
        out.latencies.append(time.perf_counter() - t0)
        out.statuses[r.status_code] += 1


def command(c: Client, hz: float, start: float, stop: threading.Event, out: Stats) -> None:
    """Send commands one after another at `hz`: nudge +, aim, nudge -, aim, ..."""
    for i, _ in enumerate(paced(1.0 / hz, start, stop)):
        if i % 2 == 0:
            path, body = "/laser/nudge", {"dyaw": 0.01 if i % 4 == 0 else -0.01, "dpitch": 0.0}
        else:
            t = i / hz
            path, body = "/laser/aim", {"yaw": 0.2 * math.sin(t), "pitch": -0.3}
        t0 = time.perf_counter()
        try:
            c.post(path, body)
            status = 200
        except ApiError as exc:
            status = exc.status
        except requests.RequestException as exc:
            out.errors[type(exc).__name__] += 1
            continue
        out.latencies.append(time.perf_counter() - t0)
        out.statuses[status] += 1


def sample_rtf(url: str, start: float, stop: threading.Event, out: Stats) -> None:
    http = requests.Session()
    for _ in paced(1.0, start + 1.0, stop):
        try:
            out.rtf.append(float(http.get(f"{url}{API}/health", timeout=10).json()["rtf"]))
        except (requests.RequestException, ValueError, KeyError) as exc:
            out.errors[f"health: {type(exc).__name__}"] += 1


def percentile(values: list[float], q: float) -> float:
    """The q-th percentile (0-100), nearest rank; nan for no values."""
    if not values:
        return math.nan
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q / 100 * len(ordered)) - 1))]


def latency(values: list[float]) -> str:
    """p50, p99 and max of latencies (s), in ms."""
    worst = max(values, default=math.nan)
    return (
        f"p50 {percentile(values, 50) * 1000:6.1f} ms   p99 {percentile(values, 99) * 1000:6.1f} ms"
        f"   max {worst * 1000:6.1f} ms"
    )


@dataclass
class Load:
    """What every thread of the load saw: the websocket readers, the /state pollers (one
    per reader), the controller's commands and the real-time factor samples."""

    readers: list[Stats]
    pollers: list[Stats]
    commands: Stats = field(default_factory=Stats)
    rtf: Stats = field(default_factory=Stats)


def start_watchers(
    url: str, go: threading.Event, stop: threading.Event, readers: list[Stats]
) -> list[threading.Thread]:
    """One events websocket reader a Stats of `readers`, started."""
    threads = [
        threading.Thread(target=watch_events, args=(url, go, stop, s), daemon=True) for s in readers
    ]
    for t in threads:
        t.start()
    return threads


def start_load(
    url: str,
    args: argparse.Namespace,
    controller: Client,
    start: float,
    stop: threading.Event,
    load: Load,
) -> list[threading.Thread]:
    """The /state pollers (spread over the read period, not all at once), the controller's
    commands and the real-time factor sampler, started at `start`."""
    threads = []
    period = 1.0 / args.read_hz
    for i, s in enumerate(load.pollers):
        offset = start + period * i / args.readers
        threads.append(
            threading.Thread(
                target=poll_state, args=(url, args.read_hz, offset, stop, s), daemon=True
            )
        )
    threads.append(
        threading.Thread(
            target=command,
            args=(controller, args.command_hz, start, stop, load.commands),
            daemon=True,
        )
    )
    threads.append(
        threading.Thread(target=sample_rtf, args=(url, start, stop, load.rtf), daemon=True)
    )
    for t in threads:
        t.start()
    return threads


def run(url: str, args: argparse.Namespace) -> int:
    """Put the load on the server at `url` for `args.seconds` and print what it saw."""
    http = requests.Session()
    controller = Client(url, name="api_load bench", source="bench", timeout=10.0)
    try:
        controller.take_control()
    except ApiError as exc:
        print(f"api_load: cannot take the lease: {exc}", file=sys.stderr)
        return 2

    stop, go = threading.Event(), threading.Event()
    load = Load([Stats() for _ in range(args.readers)], [Stats() for _ in range(args.readers)])
    threads = start_watchers(url, go, stop, load.readers)
    time.sleep(1.0)  # the websockets connect
    state0 = http.get(f"{url}{API}/state", timeout=10).json()
    wall0 = start = time.perf_counter()
    go.set()
    threads += start_load(url, args, controller, start, stop, load)
    time.sleep(args.seconds)
    stop.set()
    wall1 = time.perf_counter()
    state1 = http.get(f"{url}{API}/state", timeout=10).json()
    for t in threads:
        t.join(timeout=15)
    controller.release()
    wall = wall1 - wall0
    print_load(url, args, load, wall, (state1["sim_time"] - state0["sim_time"]) / wall)
    return 0


def error_counts(load: Load) -> Counter[str]:
    """Every error of the load: no answer, by exception type, and HTTP statuses other than
    200 and 409 (state conflicts)."""
    errors: Counter[str] = Counter()
    for s in [load.commands, load.rtf, *load.pollers, *load.readers]:
        errors.update(s.errors)
        errors.update(
            {f"HTTP {code}": n for code, n in s.statuses.items() if code not in (200, 409)}
        )
    return errors


def print_load(url: str, args: argparse.Namespace, load: Load, wall: float, sim_rtf: float) -> None:
    """Print what the load saw over `wall` s; sim_rtf: sim time over wall time."""
    commands, readers, pollers, rtf = load.commands, load.readers, load.pollers, load.rtf
    read_lat = [x for s in pollers for x in s.latencies]
    hz = [s.frames / wall for s in readers]
    messages = sum(s.messages for s in readers)
    dropped = sum(s.gaps for s in readers)
    sent = sum(commands.statuses.values()) + sum(commands.errors.values())
    cmd_errors = sum(n for code, n in commands.statuses.items() if code not in (200, 409))
    cmd_errors += sum(commands.errors.values())
    reads = sum(sum(s.statuses.values()) for s in pollers)
    read_errors = sum(n for s in pollers for code, n in s.statuses.items() if code != 200)
    read_errors += sum(sum(s.errors.values()) for s in pollers)
    ws_errors = sum(sum(s.errors.values()) for s in readers)
    errors = error_counts(load)
    print(
        f"server            {url}  ({args.readers} readers: events websocket + GET /state at "
        f"{args.read_hz:g} Hz; 1 controller at {args.command_hz:g} commands/s; {wall:.1f} s)"
    )
    print(
        f"commands          {sent} sent ({sent / wall:.1f}/s): {commands.statuses[200]} ok, "
        f"{commands.statuses[409]} conflicts (409), {cmd_errors} errors"
    )
    print(f"command latency   {latency(commands.latencies)}")
    print(
        f"read latency      {latency(read_lat)}   "
        f"({reads} GET /state, {reads / wall:.1f}/s, {read_errors} errors)"
    )
    print(
        f"websocket frames  {sum(hz) / len(hz):5.1f} Hz per client (min {min(hz):.1f}, "
        f"max {max(hz):.1f}; {sum(s.frames for s in readers)} state frames in all)"
    )
    print(
        f"dropped           {dropped} of {messages + dropped} messages "
        f"({100 * dropped / max(1, messages + dropped):.2f} %; gaps in seq)"
        f"{f', {ws_errors} websocket errors' if ws_errors else ''}"
    )
    print(
        f"errors            {sum(errors.values())}"
        + "".join(f"; {k}: {n}" for k, n in errors.items())
    )
    if rtf.rtf:
        print(
            f"real-time factor  min {min(rtf.rtf):.3f}   mean {sum(rtf.rtf) / len(rtf.rtf):.3f}"
            f"   ({len(rtf.rtf)} samples of /health rtf; sim time / wall time {sim_rtf:.3f})"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="use this server (e.g. http://127.0.0.1:8000)")
    parser.add_argument("--seconds", type=float, default=60.0, help="measured time (s)")
    parser.add_argument("--readers", type=int, default=20, help="read clients")
    parser.add_argument("--read-hz", type=float, default=5.0, help="GET /state per reader")
    parser.add_argument("--command-hz", type=float, default=50.0, help="controller's rate")
    parser.add_argument("--scene", default="isolation", help="scene of a server started here")
    args = parser.parse_args(argv)
    if args.url:
        return run(args.url.rstrip("/"), args)
    with tempfile.TemporaryDirectory(prefix="laserpick-api-load-") as tmp:
        server = ServeProcess(Path(tmp), scene=args.scene)
        try:
            try:
                server.start(timeout=120)
            except AssertionError as exc:
                print(f"api_load: the server did not start:\n{exc}", file=sys.stderr)
                return 2
            time.sleep(2.0)  # let the simulation settle into real time
            return run(server.url, args)
        finally:
            server.close()


if __name__ == "__main__":
    sys.exit(main())
