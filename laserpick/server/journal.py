"""The session journal: every operator-session event of the laserpick server, in SQLite.

The user studies compare access methods (console, REST, switch, joystick), so every request,
refusal, failure and completion is recorded with its source, outcome, failure kind and stage
timings, and exported afterwards as JSON or CSV (`export_json`, `export_csv`).

Durability: `Journal.record` commits before it returns, and the database runs in WAL mode with
`synchronous=NORMAL`. A commit in that mode is a write into the WAL file, which the operating
system holds even if the process dies, so a returned row id survives the server being killed
(`kill -9`, a crash, an exception). What it does not survive is an OS crash or power loss
before the next checkpoint's fsync: then the last few transactions may roll back, but the
database stays consistent. While a journal is open it is three files (`x.db`, `x.db-wal`,
`x.db-shm`); copy it only once closed, or use the exports.

Schema (version `SCHEMA_VERSION`, kept in `PRAGMA user_version`; `PRAGMA application_id` marks
the file as a laserpick journal), one table `events`:

    id       INTEGER PRIMARY KEY   ascending in record order
    t        REAL                  unix time of the record (s)
    session  TEXT                  the server run's id (a uuid, given to the constructor)
    source   TEXT                  one of SOURCES: console, rest, switch, joystick, bench, system
    action   TEXT                  what was asked, e.g. "laser/aim", "execute", "stop"
    outcome  TEXT                  e.g. "ok", "refused", "failed", "cancelled", "done"
    failure  TEXT NULL             one of FAILURES, or NULL
    message  TEXT                  a human sentence, may be ""
    timings  TEXT                  JSON object, stage name -> seconds; non-finite -> null
    detail   TEXT                  JSON object of extra fields, "{}" by default

The journal only appends; nothing here updates or deletes a row.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import sqlite3
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import Any

SCHEMA_VERSION = 1
"""The schema this module writes, stored in `PRAGMA user_version`."""

APPLICATION_ID = 0x4C504A4E  # "LPJN": marks a SQLite file as a laserpick journal
"""`PRAGMA application_id` of a journal file."""

SOURCES = frozenset({"console", "rest", "switch", "joystick", "bench", "system"})
"""Where an event came from: the operator's access method, the bench, or the server itself."""

FAILURES = frozenset(
    {"detect_laser", "detect_grasp", "ik_plan", "wrong_object", "execute", "precondition"}
)
"""The failure kinds an event may carry (or None)."""

COLUMNS = (
    "id",
    "t",
    "session",
    "source",
    "action",
    "outcome",
    "failure",
    "message",
    "timings",
    "detail",
)
"""The columns of `events`, in order: the keys of an event dict and the CSV header."""

_SCHEMA = """
CREATE TABLE IF NOT EXISTS events (
    id INTEGER PRIMARY KEY,
    t REAL NOT NULL,
    session TEXT NOT NULL,
    source TEXT NOT NULL,
    action TEXT NOT NULL,
    outcome TEXT NOT NULL,
    failure TEXT,
    message TEXT NOT NULL DEFAULT '',
    timings TEXT NOT NULL DEFAULT '{}',
    detail TEXT NOT NULL DEFAULT '{}'
);
CREATE INDEX IF NOT EXISTS events_session ON events (session, id);
"""

_INSERT = (
    "INSERT INTO events (t, session, source, action, outcome, failure, message, timings, detail)"
    " VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)"
)


class JournalError(ValueError):
    """A file that cannot be opened as a journal: not SQLite, not a journal, or too new."""


def _finite_or_none(x: float) -> float | None:
    return x if math.isfinite(x) else None


def _jsonable(value: Any, where: str) -> Any:
    """`value` with non-finite floats as None and numpy scalars/arrays as Python values."""
    if value is None or isinstance(value, str | bool | int):
        return value
    if isinstance(value, float):
        return _finite_or_none(value)
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v, where) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v, where) for v in value]
    if hasattr(value, "tolist"):  # numpy scalar or array, without importing numpy
        return _jsonable(value.tolist(), where)
    raise TypeError(f"{where}: {type(value).__name__} is not JSON-serialisable: {value!r}")


def _timings_json(timings: Mapping[str, float | None] | None) -> str:
    if not timings:
        return "{}"
    out: dict[str, float | None] = {}
    for stage, seconds in timings.items():
        if not isinstance(stage, str):
            raise TypeError(f"timings: stage names must be str, got {stage!r}")
        out[stage] = None if seconds is None else _finite_or_none(float(seconds))
    return json.dumps(out, allow_nan=False, separators=(",", ":"))


def _detail_json(detail: Mapping[str, Any] | None) -> str:
    if not detail:
        return "{}"
    if not isinstance(detail, Mapping):
        raise TypeError(f"detail must be a mapping, got {type(detail).__name__}")
    return json.dumps(_jsonable(detail, "detail"), allow_nan=False, separators=(",", ":"))


class Journal:
    """An append-only SQLite log of one server run's events, safe to share between threads.

    One connection (`check_same_thread=False`) behind a `threading.Lock`: the FastAPI
    handlers, the worker thread and the watchdog all record through the same object.
    Several runs may append to the same file; each is told apart by its `session`.
    """

    def __init__(self, path: str | os.PathLike[str], session: str) -> None:
        """Open (creating it and its parent directories if needed) the journal at `path`.

        `session` is this server run's id (a uuid string), stamped on every event recorded.
        Raises `JournalError` if `path` is not a SQLite database, is a SQLite database that is
        not a journal, or is a journal of a newer schema version than `SCHEMA_VERSION`.
        """
        if not isinstance(session, str) or not session:
            raise ValueError(f"session must be a non-empty string, got {session!r}")
        self.path = Path(path).expanduser()
        self.session = session
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()
        # isolation_level=None: no implicit transactions, so each INSERT is its own transaction,
        # committed when execute() returns.
        self._conn: sqlite3.Connection | None = sqlite3.connect(
            self.path, check_same_thread=False, isolation_level=None, timeout=5.0
        )
        try:
            self._open()
        except BaseException:
            self._conn.close()
            self._conn = None
            raise

    def _open(self) -> None:
        conn = self._conn
        assert conn is not None
        try:
            version, app_id, n_objects = self._identity()
            self._check_identity(version, app_id, n_objects)
            mode = conn.execute("PRAGMA journal_mode=WAL").fetchone()[0]
            if str(mode).lower() != "wal":
                raise JournalError(
                    f"{self.path}: cannot switch to WAL mode (got {mode!r}); a journal needs a "
                    "local file system"
                )
            # WAL + synchronous=NORMAL: a commit appends to the WAL without an fsync. The
            # process being killed loses no committed transaction (the OS still holds the
            # written pages); only an OS crash or power loss can roll back the last few
            # commits, and never corrupts the file. That is the requirement, and it keeps
            # record() well under a millisecond. FULL would fsync every commit.
            conn.execute("PRAGMA synchronous=NORMAL")
            if version == 0:
                self._create()
        except sqlite3.DatabaseError as exc:  # "file is not a database", "unable to open", ...
            raise JournalError(f"{self.path}: not a usable SQLite database ({exc})") from exc

    def _identity(self) -> tuple[int, int, int]:
        """(user_version, application_id, number of schema objects) of the open file."""
        assert self._conn is not None
        version = self._conn.execute("PRAGMA user_version").fetchone()[0]
        app_id = self._conn.execute("PRAGMA application_id").fetchone()[0]
        n_objects = self._conn.execute("SELECT count(*) FROM sqlite_master").fetchone()[0]
        return int(version), int(app_id), int(n_objects)

    def _check_identity(self, version: int, app_id: int, n_objects: int) -> None:
        if version == 0 and app_id == 0 and n_objects == 0:
            return  # a new or empty file: ours to initialise
        if app_id != APPLICATION_ID:
            raise JournalError(f"{self.path}: a SQLite database, but not a laserpick journal")
        if version > SCHEMA_VERSION:
            raise JournalError(
                f"{self.path}: journal schema version {version} is newer than this laserpick "
                f"reads (version {SCHEMA_VERSION}); open it with a newer laserpick"
            )
        if version < 1:
            raise JournalError(f"{self.path}: journal has no schema version (user_version 0)")

    def _create(self) -> None:
        """Initialise an empty file, in one transaction (another process may race us)."""
        conn = self._conn
        assert conn is not None
        conn.execute("BEGIN IMMEDIATE")
        try:
            version, app_id, n_objects = self._identity()
            self._check_identity(version, app_id, n_objects)
            if version == 0:
                for statement in _SCHEMA.split(";"):
                    if statement.strip():
                        conn.execute(statement)
                conn.execute(f"PRAGMA application_id={APPLICATION_ID}")
                conn.execute(f"PRAGMA user_version={SCHEMA_VERSION}")
            conn.execute("COMMIT")
        except BaseException:
            if conn.in_transaction:
                conn.execute("ROLLBACK")
            raise

    def _connection(self) -> sqlite3.Connection:
        if self._conn is None:
            raise RuntimeError(f"journal {self.path} is closed")
        return self._conn

    def record(
        self,
        *,
        source: str,
        action: str,
        outcome: str,
        failure: str | None = None,
        message: str = "",
        timings: Mapping[str, float | None] | None = None,
        detail: Mapping[str, Any] | None = None,
    ) -> int:
        """Append one event stamped with the current unix time (s); return its row id.

        The row is committed before this returns, so a returned id survives the process being
        killed. `source` must be in `SOURCES` and `failure` in `FAILURES` or None (ValueError
        otherwise). `timings` maps stage names to durations (s); NaN and ±inf are stored as
        null. `detail` is any JSON-able mapping (numpy values allowed; non-finite floats become
        null). Typically tens of microseconds: a WAL commit does not fsync.
        """
        if source not in SOURCES:
            raise ValueError(f"unknown source {source!r}; expected one of {sorted(SOURCES)}")
        if failure is not None and failure not in FAILURES:
            raise ValueError(
                f"unknown failure kind {failure!r}; expected None or one of {sorted(FAILURES)}"
            )
        if not isinstance(action, str) or not action:
            raise ValueError(f"action must be a non-empty string, got {action!r}")
        if not isinstance(outcome, str) or not outcome:
            raise ValueError(f"outcome must be a non-empty string, got {outcome!r}")
        if not isinstance(message, str):
            raise TypeError(f"message must be a string, got {type(message).__name__}")
        row = (
            time.time(),
            self.session,
            source,
            action,
            outcome,
            failure,
            message,
            _timings_json(timings),
            _detail_json(detail),
        )
        with self._lock:
            cur = self._connection().execute(_INSERT, row)  # autocommit: committed on return
        assert cur.lastrowid is not None
        return cur.lastrowid

    def events(
        self, *, since_id: int = 0, limit: int | None = None, session: str | None = None
    ) -> list[dict[str, Any]]:
        """Events with id > `since_id`, ascending by id, at most `limit` of them, of `session`
        only if given (any session otherwise). Each is a dict keyed by `COLUMNS`, with
        `timings` and `detail` parsed back to dicts and `t` in unix seconds."""
        sql = f"SELECT {', '.join(COLUMNS)} FROM events WHERE id > ?"
        args: list[Any] = [int(since_id)]
        if session is not None:
            sql += " AND session = ?"
            args.append(session)
        sql += " ORDER BY id"
        if limit is not None:
            if limit < 0:
                raise ValueError(f"limit must be >= 0, got {limit}")
            sql += " LIMIT ?"
            args.append(int(limit))
        with self._lock:
            rows = self._connection().execute(sql, args).fetchall()
        out = []
        for row in rows:
            event = dict(zip(COLUMNS, row, strict=True))
            event["timings"] = json.loads(event["timings"])
            event["detail"] = json.loads(event["detail"])
            out.append(event)
        return out

    def export_json(
        self, *, since_id: int = 0, limit: int | None = None, session: str | None = None
    ) -> str:
        """The selected events (as `events`) as a JSON array of objects."""
        rows = self.events(since_id=since_id, limit=limit, session=session)
        return json.dumps(rows, allow_nan=False, indent=1)

    def export_csv(
        self, *, since_id: int = 0, limit: int | None = None, session: str | None = None
    ) -> str:
        """The selected events (as `events`) as CSV with a header row of `COLUMNS`.

        `timings` and `detail` are JSON strings; a NULL `failure` is an empty field."""
        buf = io.StringIO(newline="")
        writer = csv.writer(buf)
        writer.writerow(COLUMNS)
        for event in self.events(since_id=since_id, limit=limit, session=session):
            event["timings"] = json.dumps(event["timings"], allow_nan=False)
            event["detail"] = json.dumps(event["detail"], allow_nan=False)
            writer.writerow([event[c] for c in COLUMNS])
        return buf.getvalue()

    def close(self) -> None:
        """Close the connection (checkpointing the WAL into the main file). Idempotent."""
        with self._lock:
            if self._conn is not None:
                self._conn.close()
                self._conn = None

    @property
    def closed(self) -> bool:
        """Whether `close` has been called."""
        return self._conn is None

    def __enter__(self) -> Journal:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else "open"
        return f"Journal({str(self.path)!r}, session={self.session!r}, {state})"
