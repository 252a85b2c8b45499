"""The session journal: round trips, filters, exports, validation, threads, and that a
committed event survives the process being killed with SIGKILL."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import signal
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from laserpick.server.journal import COLUMNS, SCHEMA_VERSION, Journal, JournalError

ROOT = Path(__file__).resolve().parents[1]
SESSION = "3f0c1c9e-6a59-4d2e-9d7e-2f4f6f1b0a11"


@pytest.fixture
def journal(tmp_path):
    with Journal(tmp_path / "journal.db", SESSION) as j:
        yield j


def test_record_and_events_round_trip(journal):
    t0 = time.time()
    first = journal.record(
        source="console",
        action="laser/aim",
        outcome="ok",
        timings={"detect_laser": 0.0123},
        detail={"pixel": [320, 240], "confidence": 0.9},
    )
    second = journal.record(
        source="switch",
        action="execute",
        outcome="failed",
        failure="ik_plan",
        message="No collision-free path to the grasp.",
    )
    assert second > first
    events = journal.events()
    assert [e["id"] for e in events] == [first, second]
    a, b = events
    assert set(a) == set(COLUMNS)
    assert a["session"] == SESSION and b["session"] == SESSION
    assert (a["source"], a["action"], a["outcome"], a["failure"]) == (
        "console",
        "laser/aim",
        "ok",
        None,
    )
    assert a["message"] == ""
    assert a["timings"] == {"detect_laser": 0.0123}
    assert a["detail"] == {"pixel": [320, 240], "confidence": 0.9}
    assert (b["failure"], b["message"]) == ("ik_plan", "No collision-free path to the grasp.")
    assert b["timings"] == {} and b["detail"] == {}
    assert t0 - 1 <= a["t"] <= b["t"] <= time.time() + 1


def test_non_finite_timings_and_detail_are_stored_as_null(journal):
    rid = journal.record(
        source="bench",
        action="execute",
        outcome="done",
        timings={"plan": math.nan, "move": math.inf, "grip": -math.inf, "ik": np.float32(0.5)},
        detail={"residual": np.float64("nan"), "xyz": np.array([1.0, np.inf, 3.0])},
    )
    con = sqlite3.connect(journal.path)  # the raw text, as any other reader would see it
    try:
        raw_timings, raw_detail = con.execute(
            "SELECT timings, detail FROM events WHERE id = ?", (rid,)
        ).fetchone()
    finally:
        con.close()
    # Strict JSON: no NaN/Infinity tokens that other readers (pandas, JS) choke on.
    for raw in (raw_timings, raw_detail):
        assert not any(bad in raw for bad in ("NaN", "Infinity")), raw
        json.loads(raw)
    (event,) = journal.events()
    assert event["timings"] == {"plan": None, "move": None, "grip": None, "ik": 0.5}
    assert event["detail"] == {"residual": None, "xyz": [1.0, None, 3.0]}
    json.loads(journal.export_json())  # the export stays valid too


def test_filters_and_ordering(tmp_path):
    path = tmp_path / "journal.db"
    other = "9b8a7c6d-0000-4000-8000-000000000000"
    ids: dict[str, list[int]] = {SESSION: [], other: []}
    with Journal(path, SESSION) as a, Journal(path, other) as b:
        for i in range(10):  # interleave two sessions (two server runs) in one file
            ids[SESSION].append(a.record(source="rest", action="stop", outcome="ok"))
            ids[other].append(b.record(source="joystick", action=f"nudge/{i}", outcome="ok"))
        everything = a.events()
        all_ids = [e["id"] for e in everything]
        assert all_ids == sorted(ids[SESSION] + ids[other])
        assert all_ids == sorted(set(all_ids))
        times = [e["t"] for e in everything]
        assert times == sorted(times)

        assert [e["id"] for e in a.events(session=other)] == ids[other]
        assert {e["session"] for e in b.events(session=SESSION)} == {SESSION}

        cut = all_ids[6]
        assert [e["id"] for e in a.events(since_id=cut)] == all_ids[7:]
        assert [e["id"] for e in a.events(limit=3)] == all_ids[:3]
        assert a.events(limit=0) == []
        assert [e["id"] for e in a.events(since_id=cut, limit=2, session=other)] == [
            i for i in ids[other] if i > cut
        ][:2]
        assert a.events(since_id=all_ids[-1]) == []
        with pytest.raises(ValueError):
            a.events(limit=-1)


@pytest.mark.parametrize("source", ["keyboard", "", "Console", None])
def test_invalid_source_is_refused(journal, source):
    with pytest.raises(ValueError, match="source"):
        journal.record(source=source, action="execute", outcome="ok")
    assert journal.events() == []


def test_invalid_failure_kind_is_refused(journal):
    with pytest.raises(ValueError, match="failure"):
        journal.record(source="rest", action="execute", outcome="failed", failure="oops")
    assert journal.events() == []


def test_csv_export_parses_back_to_the_same_rows(journal):
    journal.record(
        source="console",
        action="laser/aim",
        outcome="refused",
        failure="precondition",
        message='Arm busy, "stop" first,\nthen aim — again.',
        timings={"a": 0.25, "b": math.nan},
        detail={"note": 'comma, quote " and ünïcode'},
    )
    journal.record(source="system", action="watchdog", outcome="cancelled")
    journal.record(source="bench", action="execute", outcome="done", timings={"total": 12.5})
    text = journal.export_csv()
    reader = csv.DictReader(io.StringIO(text, newline=""))
    assert tuple(reader.fieldnames) == COLUMNS
    parsed = [
        {
            **row,
            "id": int(row["id"]),
            "t": float(row["t"]),
            "failure": row["failure"] or None,
            "timings": json.loads(row["timings"]),
            "detail": json.loads(row["detail"]),
        }
        for row in reader
    ]
    assert parsed == journal.events()
    assert len(parsed) == 3

    since = parsed[0]["id"]
    assert len(list(csv.DictReader(io.StringIO(journal.export_csv(since_id=since))))) == 2


def test_json_export_parses(journal):
    for outcome in ("ok", "failed", "done"):
        journal.record(source="rest", action="execute", outcome=outcome, timings={"x": 1.0})
    assert json.loads(journal.export_json()) == journal.events()
    assert [e["outcome"] for e in json.loads(journal.export_json(limit=2))] == ["ok", "failed"]
    assert json.loads(journal.export_json(session="nobody")) == []


def test_file_is_in_wal_mode(tmp_path):
    path = tmp_path / "nested" / "dirs" / "journal.db"  # parents are created
    with Journal(path, SESSION) as j:
        j.record(source="system", action="start", outcome="ok")
        # synchronous is per connection, so ask the journal's own: 1 is NORMAL (2 FULL, 0 OFF).
        assert j._connection().execute("PRAGMA synchronous").fetchone()[0] == 1
        con = sqlite3.connect(path)
        try:
            assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
            assert con.execute("PRAGMA user_version").fetchone()[0] == SCHEMA_VERSION
        finally:
            con.close()
    con = sqlite3.connect(path)  # WAL mode is a property of the file: it persists after close
    try:
        assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert con.execute("SELECT count(*) FROM events").fetchone()[0] == 1
    finally:
        con.close()


_CHILD = """
import sys
from laserpick.server.journal import Journal

path, n_printed = sys.argv[1], int(sys.argv[2])
journal = Journal(path, "killed-run")
for i in range(n_printed):
    rid = journal.record(source="bench", action="stress", outcome="ok", detail={"i": i})
    print(rid, flush=True)
print("looping", flush=True)
i = n_printed
while True:
    journal.record(
        source="bench", action="stress", outcome="ok", timings={"x": 0.001}, detail={"i": i}
    )
    i += 1
"""


def test_committed_events_survive_sigkill(tmp_path):
    path = tmp_path / "killed.db"
    n_printed = 200
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    proc = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(path), str(n_printed)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        env=env,
    )
    seen: list[int] = []
    try:
        while len(seen) < n_printed:
            line = proc.stdout.readline()
            if not line:
                proc.wait(timeout=10)
                pytest.fail(f"child exited early ({proc.returncode}): {proc.stderr.read()}")
            seen.append(int(line))
        assert proc.stdout.readline().strip() == "looping"
        time.sleep(0.3)  # let it commit a few thousand more, so the kill lands mid-write
        assert proc.poll() is None, proc.stderr.read()
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL

    with Journal(path, "after-the-kill") as j:
        events = j.events(session="killed-run")
        by_id = {e["id"]: e for e in events}
        missing = [rid for rid in seen if rid not in by_id]
        assert not missing, f"{len(missing)} committed events lost, e.g. {missing[:5]}"
        assert [by_id[rid]["detail"]["i"] for rid in seen] == list(range(n_printed))
        # The unprinted loop ran too: those rows are there, in order, without gaps.
        assert len(events) > n_printed
        assert [e["detail"]["i"] for e in events] == list(range(len(events)))
        j.record(source="system", action="start", outcome="ok")  # still writable
        con = sqlite3.connect(path)
        try:
            assert con.execute("PRAGMA integrity_check").fetchall() == [("ok",)]
        finally:
            con.close()


def test_a_non_sqlite_file_is_refused_and_left_alone(tmp_path):
    path = tmp_path / "notes.db"
    content = b"these are field notes, not a database\n" * 200
    path.write_bytes(content)
    with pytest.raises(JournalError, match="not a usable SQLite database") as info:
        Journal(path, SESSION)
    assert str(path) in str(info.value)
    assert isinstance(info.value, ValueError)
    assert path.read_bytes() == content


def test_a_foreign_sqlite_database_is_refused(tmp_path):
    path = tmp_path / "other.db"
    con = sqlite3.connect(path)
    con.execute("CREATE TABLE things (x)")
    con.commit()
    con.close()
    with pytest.raises(JournalError, match="not a laserpick journal") as info:
        Journal(path, SESSION)
    assert str(path) in str(info.value)
    con = sqlite3.connect(path)  # untouched: no events table, still a rollback journal
    try:
        assert con.execute("PRAGMA journal_mode").fetchone()[0] == "delete"
        names = [r[0] for r in con.execute("SELECT name FROM sqlite_master")]
        assert names == ["things"]
    finally:
        con.close()


def test_a_newer_schema_version_is_refused(tmp_path):
    path = tmp_path / "future.db"
    with Journal(path, SESSION) as j:
        j.record(source="system", action="start", outcome="ok")
    con = sqlite3.connect(path)
    con.execute(f"PRAGMA user_version={SCHEMA_VERSION + 1}")
    con.commit()
    con.close()
    with pytest.raises(JournalError, match="newer") as info:
        Journal(path, SESSION)
    assert str(path) in str(info.value)


def test_reopening_appends_to_the_same_file(tmp_path):
    path = tmp_path / "journal.db"
    with Journal(path, "run-1") as j:
        first = j.record(source="system", action="start", outcome="ok")
    with Journal(path, "run-2") as j:
        second = j.record(source="system", action="start", outcome="ok")
        assert second > first
        assert [(e["id"], e["session"]) for e in j.events()] == [
            (first, "run-1"),
            (second, "run-2"),
        ]


def test_concurrent_records_from_threads(journal):
    n_threads, per_thread = 4, 200
    barrier = threading.Barrier(n_threads)
    ids: list[list[int]] = [[] for _ in range(n_threads)]
    errors: list[BaseException] = []

    def work(k: int) -> None:
        try:
            barrier.wait()
            for i in range(per_thread):
                ids[k].append(
                    journal.record(
                        source="rest", action="thread", outcome="ok", detail={"k": k, "i": i}
                    )
                )
                if i % 50 == 0:
                    journal.events(since_id=ids[k][-1])  # readers interleave with writers
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(n_threads)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert not errors, errors
    flat = [rid for per in ids for rid in per]
    assert len(flat) == n_threads * per_thread
    assert len(set(flat)) == len(flat)
    events = journal.events()
    assert len(events) == n_threads * per_thread
    assert sorted(flat) == [e["id"] for e in events]
    for k in range(n_threads):
        mine = [e["detail"]["i"] for e in events if e["detail"]["k"] == k]
        assert mine == list(range(per_thread))  # each thread's events in its own order


def test_close_and_context_manager(tmp_path):
    path = tmp_path / "journal.db"
    with Journal(path, SESSION) as j:
        j.record(source="system", action="start", outcome="ok")
        assert not j.closed
    assert j.closed
    with pytest.raises(RuntimeError, match="closed"):
        j.record(source="system", action="stop", outcome="ok")
    j.close()  # idempotent
    assert not Path(f"{path}-wal").exists() or Path(f"{path}-wal").stat().st_size == 0
