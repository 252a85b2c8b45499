"""Live input sources: the terminal keyboard, and Linux evdev devices (switch interfaces,
gamepads, sip-and-puff switches) found by name or path.

Keyboard. The terminal is put in cbreak mode (keys arrive one by one, unechoed; Ctrl-C still
interrupts) and restored on exit. A terminal reports no key releases, so a key bound as
"hold" counts as held from its first keystroke until `hold_s` s (0.55 s: longer than the
usual auto-repeat delay) pass without another; holding the key down keeps it held through
auto-repeat. A key bound as "tap" is a press released `tap_s` s later. q or Ctrl-D quits.

evdev. `evdev:/dev/input/event5` opens that path; `evdev:NAME` the device whose name is NAME
(case-insensitive; else the one whose name contains it). Needs the optional `evdev` package
(`pip install 'laserpick[evdev]'`) and read access to /dev/input (the `input` group). Keys and
buttons (EV_KEY) map to control names by their evdev code names (KEY_SPACE, BTN_SOUTH, ...);
absolute axes (EV_ABS) to axes, scaled from the device's range to [-1, 1]. Auto-repeat
reports (value 2) are ignored: a held button is one press.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from laserpick.adapters.sources import InputEvent, LiveSource, Quit, SourceError

# --- key bindings ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Binding:
    """What a key or button does: press `button`, and/or move `axis` to `value`, while it is
    held; `tap` (keyboard only): a short press whatever the key does."""

    button: str | None = None
    axis: str | None = None
    value: float = 0.0
    tap: bool = False


# --- the terminal keyboard ---------------------------------------------------------------------

_ARROW = {"A": "up", "B": "down", "C": "right", "D": "left"}
_SEQ = re.compile(r"\x1b\[(?:1;(\d+))?([A-D])")
_SINGLE = {" ": "space", "\r": "enter", "\n": "enter", "\t": "tab", "\x7f": "backspace"}


def split_keys(buf: str) -> tuple[list[str], str]:
    """Key names in `buf` (letters as themselves, "space", "enter", "up", "shift+up", ...),
    and what is left of an incomplete escape sequence."""
    keys: list[str] = []
    while buf:
        if buf[0] == "\x1b":
            m = _SEQ.match(buf)
            if m:
                keys.append(("shift+" if m.group(1) == "2" else "") + _ARROW[m.group(2)])
                buf = buf[m.end() :]
                continue
            if len(buf) < 6 and re.fullmatch(r"\x1b(\[(1(;\d?)?)?)?", buf):
                return keys, buf  # wait for the rest of the sequence
            buf = buf[1:]  # a lone Escape, or a sequence we do not use
            continue
        keys.append(_SINGLE.get(buf[0], buf[0]))
        buf = buf[1:]
    return keys, ""


class KeyboardSource(LiveSource):
    """Keys from the controlling terminal. bindings: key name -> Binding (see `split_keys`
    for the names)."""

    def __init__(
        self,
        bindings: dict[str, Binding],
        *,
        clock: Callable[[], float] = time.monotonic,
        hold_s: float = 0.55,
        repeat_s: float = 0.15,
        tap_s: float = 0.15,
        fd: int | None = None,
    ) -> None:
        super().__init__()
        self.bindings, self.clock = bindings, clock
        self.hold_s, self.repeat_s, self.tap_s = hold_s, repeat_s, tap_s
        self.fd = sys.stdin.fileno() if fd is None else fd
        if not os.isatty(self.fd):
            raise SourceError(
                "the keyboard source needs a terminal; use --source script:FILE or evdev:DEVICE"
            )
        self._held: dict[str, float] = {}  #: key -> when it is released
        self._stop = threading.Event()
        self._saved: Any = None
        self._thread: threading.Thread | None = None

    def start(self, notify: Callable[[], None], now: float) -> None:
        import termios
        import tty

        self._notify = notify
        self._saved = termios.tcgetattr(self.fd)
        tty.setcbreak(self.fd)
        self._thread = threading.Thread(target=self._read, name="adapter-keyboard", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(1.0)
        if self._saved is not None:
            import termios

            termios.tcsetattr(self.fd, termios.TCSADRAIN, self._saved)
            self._saved = None

    def _read(self) -> None:
        buf = ""
        while not self._stop.is_set():
            ready, _, _ = select.select([self.fd], [], [], 0.02)
            now = self.clock()
            if ready:
                data = os.read(self.fd, 64)
                if not data:  # the terminal closed
                    self.push(Quit(now))
                    return
                keys, buf = split_keys(buf + data.decode("utf-8", "replace"))
                for key in keys:
                    self.key(key, now)
            elif buf:
                buf = ""  # an incomplete sequence that never completed
            self.expire(now)

    def key(self, key: str, now: float) -> None:
        """One keystroke of `key` at `now`."""
        if key in ("q", "\x04"):
            self.push(Quit(now))
            return
        b = self.bindings.get(key)
        if b is None:
            return
        if b.tap:
            self._down(b, now)
            self._held[key] = now + self.tap_s
        elif key in self._held:
            self._held[key] = max(self._held[key], now + self.repeat_s)  # auto-repeat
        else:
            self._down(b, now)
            self._held[key] = now + self.hold_s

    def expire(self, now: float) -> None:
        """Release the keys whose time is up (stamped when they ran out, not now)."""
        for key, until in sorted(self._held.items(), key=lambda kv: kv[1]):
            if until <= now:
                del self._held[key]
                self._up(self.bindings[key], until)

    def _down(self, b: Binding, t: float) -> None:
        if b.button:
            self.push(InputEvent(t, "press", b.button))
        if b.axis:
            self.push(InputEvent(t, "axis", b.axis, b.value))

    def _up(self, b: Binding, t: float) -> None:
        if b.axis:
            self.push(InputEvent(t, "axis", b.axis, 0.0))
        if b.button:
            self.push(InputEvent(t, "release", b.button))


# --- evdev devices -----------------------------------------------------------------------------


def normalize(value: int, lo: int, hi: int, invert: bool = False) -> float:
    """An absolute axis reading scaled from [lo, hi] to [-1, 1] (centre 0)."""
    if hi <= lo:
        return 0.0
    x = 2.0 * (value - lo) / (hi - lo) - 1.0
    x = min(1.0, max(-1.0, x))
    return -x if invert else x


def parse_maps(
    specs: list[str], controls: frozenset[str], axes: frozenset[str]
) -> dict[str, Binding]:
    """`--map CODE=NAME` options as {code name: Binding}; NAME is a control, or an axis
    (prefix "-" to invert it, as forward on most sticks reads negative)."""
    out: dict[str, Binding] = {}
    for spec in specs:
        code, _, name = spec.partition("=")
        code, name = code.strip().upper(), name.strip()
        axis = name.lstrip("-")
        if not code or not name:
            raise SourceError(f"--map {spec!r}: expected CODE=NAME, e.g. BTN_TR=drive")
        if code.startswith("ABS_") and axis in axes:
            out[code] = Binding(axis=axis, value=-1.0 if name.startswith("-") else 1.0)
        elif name in controls:
            out[code] = Binding(button=name)
        else:
            known = ", ".join(sorted(controls | axes))
            raise SourceError(f"--map {spec!r}: {name!r} is not one of: {known}")
    return out


def find_device(spec: str) -> Any:
    """The evdev InputDevice named by path or name. SourceError says what is available."""
    try:
        import evdev
    except ImportError:
        raise SourceError(
            "the evdev source needs the evdev package: pip install 'laserpick[evdev]'"
        ) from None
    if spec.startswith("/"):
        try:
            return evdev.InputDevice(spec)
        except OSError as exc:
            raise SourceError(f"cannot open {spec}: {exc}") from None
    devices = []
    for path in evdev.list_devices():
        with contextlib.suppress(OSError):
            devices.append(evdev.InputDevice(path))
    exact = [d for d in devices if d.name.lower() == spec.lower()]
    partial = [d for d in devices if spec.lower() in d.name.lower()]
    chosen = exact or partial
    if len(chosen) == 1:
        return chosen[0]
    listing = "; ".join(f"{d.path}: {d.name}" for d in devices) or "none readable"
    if not chosen:
        raise SourceError(f"no input device named {spec!r} (devices: {listing})")
    raise SourceError(f"{len(chosen)} devices match {spec!r}; give a path ({listing})")


class EvdevSource(LiveSource):
    """Events from one evdev device. bindings: evdev code name -> Binding."""

    def __init__(
        self,
        spec: str,
        bindings: dict[str, Binding],
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__()
        self.device = find_device(spec)
        from evdev import ecodes

        self._ecodes = ecodes
        self.clock = clock
        self._keys: dict[int, Binding] = {}
        self._abs: dict[int, tuple[Binding, int, int]] = {}
        for code_name, b in bindings.items():
            code = ecodes.ecodes.get(code_name)
            if code is None:
                raise SourceError(f"unknown evdev code {code_name!r}")
            if code_name.startswith("ABS_"):
                try:
                    info = self.device.absinfo(code)
                except OSError:
                    continue  # the device has no such axis
                self._abs[code] = (b, info.min, info.max)
            else:
                self._keys[code] = b
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self, notify: Callable[[], None], now: float) -> None:
        self._notify = notify
        self._thread = threading.Thread(target=self._read, name="adapter-evdev", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(1.0)
        with contextlib.suppress(OSError):
            self.device.close()

    def _read(self) -> None:
        ec = self._ecodes
        while not self._stop.is_set():
            ready, _, _ = select.select([self.device.fd], [], [], 0.05)
            if not ready:
                continue
            try:
                events = list(self.device.read())
            except BlockingIOError:
                continue
            except OSError as exc:  # unplugged
                self.push(Quit(self.clock()))
                print(f"the input device went away: {exc}", file=sys.stderr)
                return
            now = self.clock()
            for e in events:
                if e.type == ec.EV_KEY and e.code in self._keys and e.value in (0, 1):
                    b = self._keys[e.code]
                    self._key(b, e.value == 1, now)
                elif e.type == ec.EV_ABS and e.code in self._abs:
                    b, lo, hi = self._abs[e.code]
                    assert b.axis is not None
                    value = normalize(e.value, lo, hi, invert=b.value < 0)
                    self.push(InputEvent(now, "axis", b.axis, value))

    def _key(self, b: Binding, down: bool, t: float) -> None:
        if b.button:
            self.push(InputEvent(t, "press" if down else "release", b.button))
        if b.axis:
            self.push(InputEvent(t, "axis", b.axis, b.value if down else 0.0))
