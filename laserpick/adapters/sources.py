"""Input events, the scripted event file, and the source that replays it.

Every source turns its device into the same few events, stamped with the adapter's monotonic
clock (s): a control pressed or released (`press`, `release`), an axis moved (`axis`, value
in [-1, 1]), and, from scripts only, `wait` (for the server or the scanner) and `quit`.

The event file ("time event" lines, UTF-8):

    # comments run from '#' to the end of the line; blank lines are ignored
    0.5  press switch          # TIME EVENT ARGS...
    +0.2 release switch        # '+T': T seconds after the previous line
    1.5  tap select 0.2        # press now, release 0.2 s later (default 0.2)
    2.0  axis y 0.6            # an axis (x: right +, y: forward +) to a value in [-1, 1]
    2.0  wait state=grasps_ready,holding timeout=90
    0.1  wait highlight=grasps.go
    0.0  quit                  # stop here (the end of the file also stops)

TIME is seconds from the segment's origin. The first segment starts when the adapter starts;
each `wait` ends a segment, and the times after it count from the moment the wait was
satisfied. `wait state=S[,S...]` waits until the server reports one of those task states with
no job running; `wait highlight=KEY` until the switch adapter next highlights KEY (a group
such as `laser`, or an item such as `laser.up`), as a person waits for an item to light up;
in two-switch step scanning, where nothing moves by time, a KEY already highlighted counts.
`timeout` (s, default 120) fails the replay. While the server is unreachable the replay
pauses, and resumes where it was once reconnected.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import threading
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

InputKind = Literal["press", "release", "axis"]
DEFAULT_TAP = 0.2  #: s a scripted `tap` holds its control
DEFAULT_WAIT_TIMEOUT = 120.0  #: s before a scripted `wait` fails the replay
#: s of rounding forgiven when a tap's release meets a wait (1.0 + 0.2 > 1.2 in floats)
TIME_TOLERANCE = 1e-6


@dataclass(frozen=True)
class InputEvent:
    """A control pressed or released, or an axis moved. t: s on the adapter's clock."""

    t: float
    kind: InputKind
    name: str
    value: float = 0.0  #: axis position in [-1, 1] (kind "axis")


@dataclass(frozen=True)
class Wait:
    """A script pauses until the server's task state is one of `targets` (what "state") or the
    scanner highlights `targets[0]` (what "highlight"); fails after `timeout` s."""

    t: float
    what: Literal["state", "highlight"]
    targets: tuple[str, ...]
    timeout: float = DEFAULT_WAIT_TIMEOUT


@dataclass(frozen=True)
class Quit:
    """Stop the adapter (a script's `quit`, the keyboard's q)."""

    t: float


Event = InputEvent | Wait | Quit


class SourceError(Exception):
    """A source cannot start: a bad script, no terminal, no such device."""


class Source:
    """Where events come from. The runner calls `start` once, then `poll(now)` for the events
    due by `now` (in time order); `next_due` says when the next known event falls (scripts
    know; live devices do not), and `notify` (given to `start`) wakes the runner when a live
    device has something. Scripts also honour `resume` (a wait ended) and `pause`/`unpause`
    (the server went away and came back)."""

    def start(self, notify: Callable[[], None], now: float) -> None:
        self._notify = notify

    def poll(self, now: float) -> list[Event]:
        raise NotImplementedError

    def next_due(self) -> float | None:
        return None

    def resume(self, t: float) -> None:
        """A `wait` was satisfied at t: time what follows from there."""

    def pause(self, t: float) -> None:
        """The server went away at t."""

    def unpause(self, t: float) -> None:
        """The server came back at t."""

    @property
    def finished(self) -> bool:
        return False

    def close(self) -> None:
        """Give the device (or the terminal) back."""


class LiveSource(Source):
    """A source fed by a reader thread: events are queued as they happen."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._queue: list[Event] = []
        self._notify: Callable[[], None] = lambda: None

    def push(self, event: Event) -> None:
        with self._lock:
            self._queue.append(event)
        self._notify()

    def poll(self, now: float) -> list[Event]:
        with self._lock:
            out, self._queue = self._queue, []
        return out


# --- the event file -------------------------------------------------------------------------


class ScriptSource(Source):
    """Replays a parsed event file; see the module docstring for the format.

    lines: (time from the segment's origin, event) in order; `Wait` events end segments."""

    def __init__(self, lines: list[Event]) -> None:
        self._events = lines
        self._i = 0
        self._origin = 0.0
        self._blocked = False  #: a Wait was handed out and not yet resumed
        self._paused_at: float | None = None

    def start(self, notify: Callable[[], None], now: float) -> None:
        self._origin = now

    def poll(self, now: float) -> list[Event]:
        out: list[Event] = []
        while not self._blocked and self._paused_at is None and self._i < len(self._events):
            ev = self._events[self._i]
            t = self._origin + ev.t
            if t > now:
                break
            out.append(dataclasses.replace(ev, t=t))
            self._i += 1
            if isinstance(ev, Wait):
                self._blocked = True
        return out

    def next_due(self) -> float | None:
        if self._blocked or self._paused_at is not None or self._i >= len(self._events):
            return None
        return self._origin + self._events[self._i].t

    def resume(self, t: float) -> None:
        self._blocked = False
        self._origin = t

    def pause(self, t: float) -> None:
        if self._paused_at is None:
            self._paused_at = t

    def unpause(self, t: float) -> None:
        if self._paused_at is not None:
            self._origin += t - self._paused_at
            self._paused_at = None

    @property
    def finished(self) -> bool:
        return self._i >= len(self._events) and not self._blocked


class ScriptError(SourceError):
    """A line of an event file that cannot be read; the message names the file and line."""


def parse_script(
    text: str,
    *,
    buttons: Collection[str],
    axes: Collection[str] = (),
    where: str = "<script>",
) -> list[Event]:
    """An event file's events, with times from each segment's origin (s). `buttons` and
    `axes` are the control names the adapter knows; anything else is a ScriptError."""
    out: list[Event] = []
    segment: list[tuple[int, Event]] = []
    prev = 0.0

    def close_segment() -> None:
        segment.sort(key=lambda p: p[1].t)  # stable: a tap's release may fall after later lines
        out.extend(ev for _, ev in segment)
        segment.clear()

    for lineno, raw in enumerate(text.splitlines(), 1):
        parts = raw.split("#", 1)[0].split()
        if not parts:
            continue
        err = functools.partial(_line_error, where, lineno)
        if len(parts) < 2:
            raise err("expected 'TIME EVENT ...'")
        t = _line_time(parts[0], prev, err)
        prev = t
        kind, args = parts[1], parts[2:]
        if kind == "wait":
            wait = _parse_wait(t, args, err)
            late = [n for n, ev in segment if ev.t > t + TIME_TOLERANCE]
            if late:
                raise err(f"the tap on line {late[0]} is still held at this wait")
            # a release that meets the wait but for rounding belongs before it
            segment[:] = [(n, dataclasses.replace(ev, t=min(ev.t, t))) for n, ev in segment]
            segment.append((lineno, wait))
            close_segment()
            prev = 0.0
        else:
            segment += [(lineno, ev) for ev in _line_events(t, kind, args, buttons, axes, err)]
    close_segment()
    return out


def _line_time(stamp: str, prev: float, err: Callable[[str], ScriptError]) -> float:
    """A line's TIME (s from the segment's origin; "+T": T s after the previous line)."""
    try:
        t = (prev + float(stamp[1:])) if stamp.startswith("+") else float(stamp)
    except ValueError:
        raise err(f"{stamp!r} is not a time in seconds") from None
    if not math.isfinite(t) or t < 0:
        raise err(f"time {stamp!r} must be a finite number of seconds, >= 0")
    if t < prev:
        raise err(f"time {t:g} s goes back before the previous line ({prev:g} s)")
    return t


def _line_events(
    t: float,
    kind: str,
    args: list[str],
    buttons: Collection[str],
    axes: Collection[str],
    err: Callable[[str], ScriptError],
) -> list[Event]:
    """The events of one line other than `wait`: press, release, tap, axis or quit."""
    if kind in ("press", "release", "tap"):
        if not args or args[0] not in buttons:
            known = ", ".join(sorted(buttons))
            raise err(f"{kind} needs a control name, one of: {known}")
        if kind == "tap":
            hold = _seconds(args[1], err) if len(args) > 1 else DEFAULT_TAP
            return [InputEvent(t, "press", args[0]), InputEvent(t + hold, "release", args[0])]
        return [InputEvent(t, "press" if kind == "press" else "release", args[0])]
    if kind == "axis":
        if len(args) != 2 or args[0] not in axes:
            raise err(f"axis needs a name ({', '.join(sorted(axes))}) and a value")
        try:
            value = float(args[1])
        except ValueError:
            raise err(f"{args[1]!r} is not a number") from None
        if not -1.0 <= value <= 1.0:
            raise err(f"axis value {value:g} is outside [-1, 1]")
        return [InputEvent(t, "axis", args[0], value)]
    if kind == "quit":
        return [Quit(t)]
    raise err(f"unknown event {kind!r} (press, release, tap, axis, wait, quit)")


def _line_error(where: str, lineno: int, msg: str) -> ScriptError:
    return ScriptError(f"{where}:{lineno}: {msg}")


def _seconds(text: str, fail: Callable[[str], ScriptError]) -> float:
    try:
        value = float(text)
    except ValueError:
        raise fail(f"{text!r} is not a number of seconds") from None
    if not math.isfinite(value) or value < 0:
        raise fail(f"{text!r} must be a finite number of seconds, >= 0")
    return value


def _parse_wait(t: float, args: list[str], fail: Callable[[str], ScriptError]) -> Wait:
    fields = dict(a.split("=", 1) for a in args if "=" in a)
    if len(fields) != len(args) or not set(fields) <= {"state", "highlight", "timeout"}:
        raise fail("wait takes state=S[,S...] or highlight=KEY, and timeout=SECONDS")
    timeout = _seconds(fields["timeout"], fail) if "timeout" in fields else DEFAULT_WAIT_TIMEOUT
    if ("state" in fields) == ("highlight" in fields):
        raise fail("wait needs exactly one of state=... and highlight=...")
    if "state" in fields:
        states = tuple(s for s in fields["state"].split(",") if s)
        if not states:
            raise fail("wait state= needs at least one task state")
        return Wait(t, "state", states, timeout)
    return Wait(t, "highlight", (fields["highlight"],), timeout)


def load_script(
    path: Path, *, buttons: Collection[str], axes: Collection[str] = ()
) -> ScriptSource:
    """A ScriptSource for the event file at `path`. Raises ScriptError."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScriptError(f"cannot read the event file {str(path)!r}: {exc}") from None
    return ScriptSource(parse_script(text, buttons=buttons, axes=axes, where=str(path)))
