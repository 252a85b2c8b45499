"""The soak's ledger: every request it sent, and the journal rows those requests must leave.

What the server journals (`laserpick/server/session/`, each `_record` call):

* a session command makes one row, `(action, "ok")` when it is taken and `(action,
  "refused")` when it conflicts with the state (HTTP 409): `laser/aim`, `laser/nudge`,
  `laser/off`, `laser/confirm`, `cancel`, `stop`, `stop/reset`, `scene`, `mode`, `resync`,
  `detect`, the grasp cursor's moves; a refused `execute` or `drive` too;
* a job makes one more row when it ends (`perceiving`, `detecting`, `picking`, `dropping`,
  `placing`, outcome `done`, `failed` or `cancelled`): a taken `laser/confirm` starts one, a
  taken `execute` starts one and makes no row of its own;
* the dead-man makes a `watchdog` row (source `system`) when it halts motion.

Not journaled: a taken `drive` (a dead-man command a client repeats at 10 Hz), the lease
(`POST /control` to take it, to heartbeat or refused with 409, and `DELETE /control`), and
requests refused before the session (401 without the lease's token). The ledger counts those
apart, by route, so that the rows it expects are exactly the rows the server promises.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from typing import Any

import requests

from laserpick.client import ApiError, Client

#: The session action of each command route (method, path under /api/v1).
ACTIONS: dict[tuple[str, str], str] = {
    ("POST", "/laser/aim"): "laser/aim",
    ("POST", "/laser/nudge"): "laser/nudge",
    ("POST", "/laser/confirm"): "laser/confirm",
    ("DELETE", "/laser"): "laser/off",
    ("POST", "/execute"): "execute",
    ("POST", "/cancel"): "cancel",
    ("POST", "/stop"): "stop",
    ("POST", "/stop/reset"): "stop/reset",
    ("POST", "/scene"): "scene",
    ("POST", "/mode"): "mode",
    ("POST", "/drive"): "drive",
}
#: The jobs' rows: one a job, whatever its outcome, counted under `JOB`.
JOBS = frozenset({"perceiving", "detecting", "picking", "dropping", "placing"})
JOB = ("job", "*")
#: Actions taken (200) that leave no row of their own.
_UNRECORDED_OK = frozenset({"drive", "execute"})
#: Taken actions that start a job, which leaves its row when it ends.
_STARTS_JOB = frozenset({"laser/confirm", "execute"})


def expected_rows(method: str, path: str, status: int) -> list[tuple[str, str]]:
    """The journal rows `(action, outcome)` a request answered `status` must leave (JOB for
    a job's row, whatever its outcome); [] for one the server does not journal."""
    action = ACTIONS.get((method, path))
    if action is None:
        return []
    if status == 409:
        return [(action, "refused")]
    if status != 200:
        return []
    rows = [] if action in _UNRECORDED_OK else [(action, "ok")]
    return rows + ([JOB] if action in _STARTS_JOB else [])


def row_key(row: dict[str, Any]) -> tuple[str, str]:
    """A journal row as the ledger counts it."""
    return JOB if row["action"] in JOBS else (row["action"], row["outcome"])


class Ledger:
    """Sends the soak's requests and keeps account of them (thread-safe): statuses by
    route, the rows the journal should hold, 5xx answers and client-side exceptions."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.sent: Counter[str] = Counter()  #: changing requests, by route
        self.statuses: Counter[str] = Counter()  #: "ROUTE STATUS" for every answer
        self.expected: Counter[tuple[str, str]] = Counter()
        self.not_journaled: Counter[str] = Counter()  #: changing requests with no row, by route
        self.server_errors: list[dict[str, Any]] = []
        self.exceptions: Counter[str] = Counter()

    def call(self, c: Client, method: str, path: str, body: Any = None, **params: Any) -> Any:
        """Send a request through `c` (with its token, if any); (status, payload). A request
        without an answer is counted as an exception and re-raised."""
        route = f"{method} {path}"
        try:
            payload, status = c.request(method, path, body, **params), 200
        except ApiError as exc:
            payload, status = exc.detail, exc.status
        except (requests.RequestException, OSError) as exc:
            self.exception(route, exc)
            raise
        self.answered(method, path, status, payload)
        return status, payload

    def answered(self, method: str, path: str, status: int, payload: Any = None) -> None:
        """Count an answer; a changing request's expected rows with it."""
        route = f"{method} {path}"
        with self._lock:
            self.statuses[f"{route} {status}"] += 1
            if status >= 500:
                detail = {"route": route, "status": status, "detail": str(payload)[:500]}
                self.server_errors.append({"t": time.time(), **detail})
            if method == "GET":
                return
            self.sent[route] += 1
            rows = expected_rows(method, path, status)
            self.expected.update(rows)
            if not rows and status < 500:
                self.not_journaled[f"{route} {status}"] += 1

    def merge(
        self, statuses: Counter[str], server_errors: list[dict[str, Any]], exceptions: Counter[str]
    ) -> None:
        """Add what another ledger saw of read requests (the watchers' process)."""
        with self._lock:
            self.statuses.update(statuses)
            self.server_errors += server_errors
            self.exceptions.update(exceptions)

    def exception(self, where: str, exc: BaseException) -> None:
        with self._lock:
            self.exceptions[f"{where}: {type(exc).__name__}"] += 1

    def compare(self, rows: list[dict[str, Any]], source: str) -> dict[str, Any]:
        """The journal's rows of `source` against the expected ones: sent, recorded, lost."""
        recorded = Counter(row_key(r) for r in rows if r["source"] == source)
        lost = self.expected - recorded
        unexpected = recorded - self.expected
        name = "/".join
        return {
            "commands_sent": sum(self.sent.values()),
            "commands_journaled": sum(self.sent.values()) - sum(self.not_journaled.values()),
            "rows_expected": sum(self.expected.values()),
            "rows_recorded": sum(recorded.values()),
            "lost": sum(lost.values()),
            "lost_by_action": {name(k): n for k, n in sorted(lost.items())},
            "unexpected": sum(unexpected.values()),
            "unexpected_by_action": {name(k): n for k, n in sorted(unexpected.items())},
            "not_journaled": dict(sorted(self.not_journaled.items())),
            "watchdog_halts": [
                _around(rows, i) for i, r in enumerate(rows) if r["action"] == "watchdog"
            ],
            "sent_by_route": dict(sorted(self.sent.items())),
        }


def _around(rows: list[dict[str, Any]], i: int) -> dict[str, Any]:
    """A watchdog row, with the rows just before and after it (what was under way)."""
    near = rows[max(0, i - 6) : i + 3]
    brief = [f"{r['id']} {r['t']:.1f} {r['action']} {r['outcome']}: {r['message']}" for r in near]
    return {"id": rows[i]["id"], "t": rows[i]["t"], "message": rows[i]["message"], "around": brief}
