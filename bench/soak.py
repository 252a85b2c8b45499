"""The soak: `laserpick serve` for a long run under a scripted mix of everything a console does.

Starts `laserpick serve --scene isolation` on free ports with a journal in a temporary
directory (or uses the server at `--url`, whose lease must be free), and for `--minutes`
(default 30) runs at once:

* one controller holding the lease (`soak_operator.py`): picks, drives, cancels mid-job,
  e-stops and resets, and reconnects (drops the lease and takes it again), in turn;
* a second client trying to take control every `--intruder-s` (it must get 409);
* `--watchers` (default 20) read-only clients, in a process of their own
  (`soak_watchers.py`): each an events websocket and a thread polling `GET /api/v1/state`
  at `--read-hz`;
* a sampler reading the real-time factor (`rtf` of `GET /api/v1/state`) every 2 s.

Every minute it reads `GET /api/v1/diagnostics?window=60` (the event loop's lag over that
minute and the server's memory) and prints a line. At the end it compares the journal
(`GET /api/v1/journal`) with the requests the soak sent (`soak_ledger.py` says which make a
row), prints a summary and writes the figures as JSON (`--out`).

    .venv/bin/python bench/soak.py [--minutes 30] [--out bench-results/soak.json]

Targets (exit code 1 when one is missed): no 5xx answer, no lost journal row, memory growth
(end less after warm-up) under 50 MB, mean real-time factor at least 0.98, the event loop's
lag p99 under 50 ms in every minute, and the second client refused (409) every time.
Exit code 2 when the server could not be started.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
try:
    import laserpick  # noqa: F401
except ImportError:  # run as a script from a checkout without `pip install -e .`
    sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests"))

import requests  # noqa: E402
from serve_process import ServeProcess  # noqa: E402
from soak_ledger import Ledger  # noqa: E402
from soak_operator import Operator  # noqa: E402
from soak_report import (  # noqa: E402
    lag_figures,
    memory_figures,
    print_summary,
    rtf_figures,
    server_error_figures,
    targets,
)
from soak_watchers import WatcherProcess  # noqa: E402

from laserpick.bench.results import environment, source_revision  # noqa: E402
from laserpick.client import Client  # noqa: E402


class Samples:
    """What the soak read of the server: rtf every 2 s, and each minute's diagnostics."""

    def __init__(self) -> None:
        self.rtf: list[float] = []
        self.unmeasured = 0  #: rtf samples of a scene too new to have measured one
        self.minutes: list[dict[str, Any]] = []  #: per minute: t, rss_mb, loop lag stats
        self.rss: dict[str, float] = {}  #: rss_mb at "start", "after_warmup", "end"


def diagnostics(c: Client, ledger: Ledger, **params: Any) -> dict[str, Any] | None:
    """`GET /diagnostics`, through the ledger; None unless 200 (no answer: counted by the
    ledger)."""
    try:
        status, body = ledger.call(c, "GET", "/diagnostics", **params)
    except (requests.RequestException, OSError):
        return None
    return body if status == 200 else None


def sample_rtf(url: str, ledger: Ledger, stop: threading.Event, out: Samples) -> None:
    """The robot's real-time factor (`rtf` of `GET /state`, the simulation's last 0.5 s)
    every 2 s. A scene just loaded reads 0 until its loop has measured its first 0.5 s (the
    loop steps whenever it runs, so a measured window is never 0): such samples are counted
    apart."""
    c = Client(url, name="soak sampler")
    while not stop.wait(2.0):
        try:
            status, state = ledger.call(c, "GET", "/state")
        except (requests.RequestException, OSError):
            continue  # counted by the ledger
        if status != 200:
            continue
        if state["rtf"] == 0.0:
            out.unmeasured += 1
        else:
            out.rtf.append(float(state["rtf"]))


def intrude(
    url: str, op: Operator, ledger: Ledger, stop: threading.Event, every: float, out: Counter[str]
) -> None:
    """Try to take control while the operator holds it, counting the answers in `out`; a
    lease wrongly granted is given back."""
    c = Client(url, name="soak intruder")
    while not stop.wait(every):
        with op.lease_lock:
            if op.client.token is None:
                continue
            try:
                status, body = ledger.call(c, "POST", "/control", {"name": "soak intruder"})
                out[str(status)] += 1
                if status == 200:
                    c.token = body["token"]
                    ledger.call(c, "DELETE", "/control")
                    c.token = None
            except (requests.RequestException, OSError):
                pass  # counted by the ledger
            # A fresh connection each try: a kept-alive one the server closes as the next
            # request goes out (uvicorn closes idle ones after 5 s) fails on the client's side.
            c.http.close()


def tick(c: Client, ledger: Ledger, samples: Samples, t0: float, window: float) -> None:
    """Read the last `window` s of diagnostics and print the progress line."""
    d = diagnostics(c, ledger, window=round(min(max(window, 1.0), 600.0), 1))
    if d is None:
        return
    elapsed = time.monotonic() - t0
    samples.minutes.append(
        {"t_s": round(elapsed, 1), "rss_mb": d["rss_mb"], **d["loop_lag"], "gc": d["gc"]}
    )
    recent = samples.rtf[-30:] or [float("nan")]
    print(
        f"soak {elapsed / 60:5.1f} min  rss {d['rss_mb']:6.1f} MB  "
        f"rtf {statistics.fmean(recent):.3f}  lag p99 {d['loop_lag']['p99_ms']:6.1f} ms  "
        f"gc longest {d['gc']['longest_ms']:5.1f} ms  "
        f"sent {sum(ledger.sent.values())}  5xx {len(ledger.server_errors)}  "
        f"exceptions {sum(ledger.exceptions.values())}",
        flush=True,
    )


def observe(url: str, args: argparse.Namespace, ledger: Ledger, samples: Samples) -> float:
    """Wait out the run, reading memory after the warm-up and a minute's diagnostics each
    minute (and the last part minute); the run's wall time (s)."""
    c = Client(url, name="soak observer")
    t0 = time.monotonic()
    total, warmup = args.minutes * 60.0, min(args.warmup_minutes * 60.0, args.minutes * 20.0)
    minutes = {60.0 * m for m in range(1, int(args.minutes) + 1)} | {total}
    marks = sorted([(m, "minute") for m in minutes] + [(warmup, "warmup")])
    last = 0.0
    for mark, kind in marks:
        time.sleep(max(0.0, t0 + mark - time.monotonic()))
        if kind == "warmup":
            if (d := diagnostics(c, ledger)) is not None:
                samples.rss["after_warmup"] = d["rss_mb"]
        else:
            tick(c, ledger, samples, t0, mark - last)
            last = mark
    if samples.minutes:
        samples.rss["end"] = samples.minutes[-1]["rss_mb"]
    return time.monotonic() - t0


def journal_rows(c: Client, ledger: Ledger, since_id: int) -> list[dict[str, Any]]:
    """Every journal row after `since_id`, page by page (those read before the server stopped
    answering, if it did)."""
    rows: list[dict[str, Any]] = []
    while True:
        try:
            status, page = ledger.call(c, "GET", "/journal", format="json", since_id=since_id)
        except (requests.RequestException, OSError):
            return rows  # counted by the ledger
        if status != 200 or not page:
            return rows
        rows += page
        since_id = page[-1]["id"]


def last_row_id(c: Client, ledger: Ledger) -> int:
    """The journal's last row id (0 when empty)."""
    rows = journal_rows(c, ledger, 0)
    return rows[-1]["id"] if rows else 0


def figures(run: dict[str, Any], ledger: Ledger, samples: Samples) -> dict[str, Any]:
    """Everything the soak measured, as the JSON it writes."""
    op, intruder = run["operator"], run["intruder"]
    f = {
        **run["meta"],
        "wall_s": round(run["wall_s"], 1),
        "rtf": {**rtf_figures(samples.rtf), "unmeasured_new_scene": samples.unmeasured},
        "memory_mb": memory_figures(samples.rss),
        "loop_lag_ms": lag_figures(samples.minutes),
        "journal": ledger.compare(run["rows"], source="bench"),
        "server_errors": server_error_figures(ledger.server_errors),
        "client_exceptions": {
            "count": sum(ledger.exceptions.values()),
            "by_kind": dict(ledger.exceptions),
            "episode_errors": op.errors[:20],
        },
        "operator": {
            "episodes": dict(op.episodes),
            "outcomes": dict(op.outcomes),
            "scenes": op.scene_resets,
        },
        "second_client": {
            "tries": sum(intruder.values()),
            "refused": intruder["409"],
            "answers": dict(intruder),
        },
        "watchers": run["watchers"],
        "statuses": dict(sorted(ledger.statuses.items())),
    }
    for halt in f["journal"]["watchdog_halts"]:
        halt["controller_gaps_s"] = op.client.gaps_before(halt["t"])
    f["targets"] = targets(f)
    f["met"] = all(t["met"] for t in f["targets"].values())
    return f


def soak(url: str, args: argparse.Namespace) -> dict[str, Any]:
    """Run the mix on the server at `url` for `args.minutes`; the figures."""
    ledger, samples, stop = Ledger(), Samples(), threading.Event()
    reader = Client(url, name="soak reader")
    since = last_row_id(reader, ledger)
    samples.rss["start"] = (diagnostics(reader, ledger) or {}).get("rss_mb", float("nan"))
    op = Operator(url, ledger, stop, seed=args.seed)
    watchers = WatcherProcess(url, args.watchers, args.read_hz, ledger)
    intruder: Counter[str] = Counter()
    watchers.start()
    threads = [
        threading.Thread(target=op.run, daemon=True),
        threading.Thread(target=sample_rtf, args=(url, ledger, stop, samples), daemon=True),
        threading.Thread(
            target=intrude, args=(url, op, ledger, stop, args.intruder_s, intruder), daemon=True
        ),
    ]
    for t in threads:
        t.start()
    wall = observe(url, args, ledger, samples)
    stop.set()
    for t in threads:
        t.join(timeout=600)
    seen = watchers.stop()
    meta = {"url": url, "minutes": args.minutes, **source_revision(), **environment()}
    run = {"meta": meta, "wall_s": wall, "operator": op, "intruder": intruder}
    run["watchers"] = seen
    run["rows"] = journal_rows(reader, ledger, since)
    return figures(run, ledger, samples)


def served(args: argparse.Namespace) -> dict[str, Any] | None:
    """Start a server in a temporary directory and soak it; None if it did not start."""
    with tempfile.TemporaryDirectory(prefix="laserpick-soak-") as tmp:
        server = ServeProcess(Path(tmp))
        try:
            try:
                server.start(timeout=180)
            except AssertionError as exc:
                print(f"soak: the server did not start:\n{exc}", file=sys.stderr)
                return None
            time.sleep(2.0)  # let the simulation settle into real time
            f = soak(server.url, args)
            if server.proc.poll() is not None:
                f["server_exit"] = server.proc.returncode
            f["server_log_tail"] = server.stderr_path.read_text()[-8000:]  # 5xx tracebacks
            return f
        finally:
            server.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="use this server (its lease must be free)")
    parser.add_argument("--minutes", type=float, default=30.0, help="how long to soak")
    parser.add_argument(
        "--warmup-minutes",
        type=float,
        default=2.0,
        help="memory growth is counted from then (at most a third of the run)",
    )
    parser.add_argument("--watchers", type=int, default=20, help="read-only clients")
    parser.add_argument("--read-hz", type=float, default=2.0, help="GET /state per watcher")
    parser.add_argument("--intruder-s", type=float, default=5.0, help="second client's period")
    parser.add_argument("--seed", type=int, default=1, help="the operator's choices")
    parser.add_argument("--out", type=Path, default=REPO / "bench-results" / "soak.json")
    args = parser.parse_args(argv)
    f = soak(args.url.rstrip("/"), args) if args.url else served(args)
    if f is None:
        return 2
    print_summary(f)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(f, indent=1, default=str) + "\n")
    print(f"wrote {args.out}")
    return 0 if f["met"] else 1


if __name__ == "__main__":
    sys.exit(main())
