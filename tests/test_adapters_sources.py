"""Where an adapter's input comes from: the scripted event file and its replay, the terminal
keyboard, evdev devices; the announcer; and a bad `--source` as a usage error.
"""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from serve_process import REPO

from laserpick.adapters import (
    Announcer,
    Binding,
    EvdevSource,
    InputEvent,
    KeyboardSource,
    Quit,
    ScriptError,
    ScriptSource,
    SourceError,
    Wait,
    normalize,
    parse_maps,
    parse_script,
    split_keys,
)

# --- the event file ------------------------------------------------------------------------------

SCRIPT = """# a comment
0.5 press switch   # trailing comment
+0.25 release switch
1.0 tap select 0.3
2.0 axis y -0.5

2.0 wait state=grasps_ready,holding timeout=30
0.1 wait highlight=grasps.go
0.2 quit
"""


def test_event_file_parses_times_taps_and_waits() -> None:
    events = parse_script(SCRIPT, buttons={"switch", "select"}, axes={"y"})
    assert events == [
        InputEvent(0.5, "press", "switch"),
        InputEvent(0.75, "release", "switch"),
        InputEvent(1.0, "press", "select"),
        InputEvent(1.3, "release", "select"),
        InputEvent(2.0, "axis", "y", -0.5),
        Wait(2.0, "state", ("grasps_ready", "holding"), 30.0),
        Wait(0.1, "highlight", ("grasps.go",), 120.0),
        Quit(0.2),
    ]


def test_event_file_forgives_float_rounding_at_a_wait() -> None:
    events = parse_script("1.0 tap switch 0.2\n1.2 wait state=idle", buttons={"switch"})
    assert [type(e).__name__ for e in events] == ["InputEvent", "InputEvent", "Wait"]
    assert events[1].kind == "release" and events[1].t <= events[2].t  # in its segment


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1.0 press nose", ":1: press needs a control name"),
        ("1.0 press switch\n0.5 release switch", ":2: time 0.5 s goes back"),
        ("x press switch", "'x' is not a time"),
        ("1.0 axis y 2", "outside [-1, 1]"),
        ("1.0 jump", "unknown event 'jump'"),
        ("1.0 wait", "wait needs exactly one"),
        ("1.0 tap switch 1.0\n1.5 wait state=idle", "still held at this wait"),
    ],
)
def test_event_file_errors_name_the_line(text: str, message: str) -> None:
    with pytest.raises(ScriptError, match=re.escape(message)):
        parse_script(text, buttons={"switch"}, axes={"y"}, where="f.txt")


def test_script_source_times_from_waits_and_pauses_while_disconnected() -> None:
    src = ScriptSource(parse_script(SCRIPT, buttons={"switch", "select"}, axes={"y"}))
    src.start(lambda: None, 100.0)
    assert src.next_due() == pytest.approx(100.5)
    src.pause(100.6)  # the server went away
    assert src.poll(200.0) == [] and src.next_due() is None
    src.unpause(110.6)  # back 10 s later: the rest is 10 s later too
    got = src.poll(110.8)
    assert [e.t for e in got] == [pytest.approx(110.5), pytest.approx(110.75)]
    got = src.poll(1000.0)
    assert isinstance(got[-1], Wait) and len(got) == 4
    assert src.poll(2000.0) == []  # blocked until the wait is satisfied
    src.resume(3000.0)
    got = src.poll(3000.1)
    assert isinstance(got[0], Wait) and got[0].t == pytest.approx(3000.1)
    src.resume(4000.0)
    assert src.poll(4000.2) == [Quit(pytest.approx(4000.2))]
    assert src.finished


# --- sources and announcements -------------------------------------------------------------------


def test_keyboard_keys_and_holds() -> None:
    assert split_keys(" \r\x1b[A\x1b[1;2Dq") == (["space", "enter", "up", "shift+left", "q"], "")
    assert split_keys("a\x1b[1") == (["a"], "\x1b[1")  # the rest of the sequence is coming
    master, slave = os.openpty()
    try:
        kb = KeyboardSource(
            {"space": Binding(button="switch"), "c": Binding(button="confirm", tap=True)},
            fd=slave,
        )
        kb.key("space", 1.0)
        kb.key("space", 1.5)  # auto-repeat keeps it held
        kb.key("space", 1.53)
        kb.expire(1.6)
        assert kb.poll(2.0) == [InputEvent(1.0, "press", "switch")]
        kb.expire(2.0)
        assert kb.poll(2.0) == [InputEvent(pytest.approx(1.68), "release", "switch")]
        kb.key("c", 3.0)
        kb.expire(4.0)
        assert [e.kind for e in kb.poll(4.0)] == ["press", "release"]
        kb.key("q", 5.0)
        assert kb.poll(5.0) == [Quit(5.0)]
    finally:
        os.close(master)
        os.close(slave)


def test_evdev_helpers() -> None:
    assert normalize(0, 0, 255) == -1.0 and normalize(255, 0, 255) == 1.0
    assert normalize(-32768, -32768, 32767, invert=True) == 1.0
    maps = parse_maps(["BTN_TR=drive", "ABS_RY=-y"], frozenset({"drive"}), frozenset({"x", "y"}))
    assert maps == {"BTN_TR": Binding(button="drive"), "ABS_RY": Binding(axis="y", value=-1.0)}
    with pytest.raises(Exception, match="not one of"):
        parse_maps(["BTN_TR=fly"], frozenset({"drive"}), frozenset())


class FakeDevice:
    """An evdev InputDevice stand-in: a pipe makes it readable, `queue` holds its events."""

    def __init__(self, path: str) -> None:
        self.path, self.name = path, "Acme Sip/Puff Breeze" if path.endswith("3") else "Mouse"
        self.fd, self._w = os.pipe()
        self.queue: list[SimpleNamespace] = []

    def absinfo(self, code: int) -> SimpleNamespace:
        return SimpleNamespace(min=-512, max=511)

    def emit(self, *events: tuple[int, int, int]) -> None:
        self.queue += [SimpleNamespace(type=t, code=c, value=v) for t, c, v in events]
        os.write(self._w, b"x")

    def read(self) -> list[SimpleNamespace]:
        os.read(self.fd, 64)
        out, self.queue = self.queue, []
        return out

    def close(self) -> None:
        os.close(self.fd)
        os.close(self._w)


def test_evdev_source_finds_by_name_and_maps_codes(monkeypatch: pytest.MonkeyPatch) -> None:
    devices = {p: FakeDevice(p) for p in ("/dev/input/event2", "/dev/input/event3")}
    codes = {"KEY_1": 2, "BTN_0": 256, "ABS_Y": 1}
    fake = SimpleNamespace(
        list_devices=lambda: list(devices),
        InputDevice=lambda path: devices[path],
        ecodes=SimpleNamespace(EV_KEY=1, EV_ABS=3, ecodes=codes),
    )
    monkeypatch.setitem(sys.modules, "evdev", fake)
    with pytest.raises(SourceError, match="no input device named 'joystick'"):
        EvdevSource("joystick", {})
    bindings = {
        "KEY_1": Binding(button="hard_puff"),
        "ABS_Y": Binding(axis="y", value=-1.0),
    }
    src = EvdevSource("sip/puff", bindings, clock=lambda: 7.0)
    assert src.device is devices["/dev/input/event3"]
    src.start(lambda: None, 0.0)
    try:
        src.device.emit((1, 2, 1), (1, 2, 2), (3, 1, -512), (1, 256, 1), (1, 2, 0))
        end = time.monotonic() + 5
        got: list = []
        while len(got) < 3 and time.monotonic() < end:
            got += src.poll(10.0)
            time.sleep(0.01)
    finally:
        src.close()
    assert got == [  # auto-repeat (value 2) and unbound codes are dropped; forward is +y
        InputEvent(7.0, "press", "hard_puff"),
        InputEvent(7.0, "axis", "y", 1.0),
        InputEvent(7.0, "release", "hard_puff"),
    ]


def test_announcer_stamps_lines_and_speaks_when_it_can() -> None:
    clock = iter([10.0, 11.5, 12.0, 13.0]).__next__
    out = io.StringIO()
    spoken: list[list[str]] = []

    class Proc:
        def __init__(self, argv: list[str], **kw: Any) -> None:
            spoken.append(argv)

        def poll(self) -> int:
            return 0

    say = Announcer(clock=clock, out=out, speak=True, which=lambda _: "/x/espeak-ng", popen=Proc)
    say.say("highlight laser.up", "up")
    assert out.getvalue() == "[    1.500] highlight laser.up\n"
    assert spoken == [["/x/espeak-ng", "-s", "170", "up"]]
    out2 = io.StringIO()
    Announcer(clock=lambda: 0.0, out=out2, speak=True, which=lambda _: None).say("hi")
    assert "espeak-ng is not installed" in out2.getvalue() and "hi" in out2.getvalue()


def test_bad_source_is_a_usage_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text("1.0 press nose\n")
    for source, message in (
        (f"script:{bad}", "bad.txt:1: press needs a control name"),
        ("carrier-pigeon", "use evdev:NAME_OR_PATH, keyboard or script:FILE"),
    ):
        res = subprocess.run(
            [sys.executable, "-m", "laserpick.cli", "adapter", "switch", "--source", source],
            cwd=REPO,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert res.returncode == 2 and message in res.stderr, res.stderr
