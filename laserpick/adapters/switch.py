"""`laserpick adapter switch`: one or two switches, by scanning (`scanning.py`, over the
items of `scan_menu.py`, with the switch timing of `switch_timing.py`).

Inputs: "switch" (the one switch; in two-switch mode, the one that moves the highlight) and
"select" (two-switch mode: selects; in one-switch mode it is the same switch). What the
scanned items do, through the public API:

    laser.up/down/left/right   POST /laser/nudge, `step` rad (up: +pitch, left: +yaw)
    laser.confirm              POST /laser/confirm
    grasps.previous/next       POST /grasps/prev|next (cluster); in automatic selection it
                               switches to manual first, so that go picks the grasp shown
    grasps.go                  POST /execute
    drive.forward/reverse      POST /drive v = +/-speed, while the switch stays held
    drive.left/right           POST /drive w = +/-turn, while the switch stays held
    mode.drop/place            POST /mode {"mode": pick_and_drop | pick_and_place}
    mode.auto/manual           POST /mode {"selection": auto | manual}
    cancel                     POST /cancel
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from laserpick.adapters.announce import Announcer
from laserpick.adapters.commands import MODE_BODIES, step_grasp
from laserpick.adapters.connection import Connection
from laserpick.adapters.scan_menu import GROUPS, Item
from laserpick.adapters.scanning import (
    AutoScanner,
    Highlight,
    HoldEnd,
    HoldStart,
    Output,
    Pending,
    Selected,
    StepScanner,
    Stopped,
    Undone,
)
from laserpick.adapters.sources import InputEvent
from laserpick.adapters.switch_timing import ScanTiming

__all__ = ["SwitchAdapter", "SwitchOptions"]

BUTTONS = frozenset({"switch", "select"})
#: While a drive item is held, the drive command is renewed this often (s).
DRIVE_REFRESH = 0.1


@dataclass(frozen=True)
class SwitchOptions:
    """mode: one-switch (automatic scanning) or two-switch (step scanning); timing: see
    `ScanTiming`; step: laser nudge per selection (rad); speed: m/s and turn: rad/s while a
    drive item is held."""

    mode: Literal["one-switch", "two-switch"] = "one-switch"
    timing: ScanTiming = field(default_factory=ScanTiming)
    step: float = 0.02
    speed: float = 0.2
    turn: float = 0.4


class SwitchAdapter:
    """Scanner outputs -> announcements and API commands."""

    buttons = BUTTONS
    axes: frozenset[str] = frozenset()

    def __init__(self, options: SwitchOptions, link: Connection, say: Announcer) -> None:
        self.options, self.link, self.say = options, link, say
        self.timed_highlight = options.mode == "one-switch"
        if options.mode == "one-switch":
            self.scanner: AutoScanner | StepScanner = AutoScanner(options.timing, GROUPS)
        else:
            self.scanner = StepScanner(options.timing, GROUPS)
        self._drive: tuple[float, float] | None = None

    # --- the runner's interface ----------------------------------------------------------

    def start(self, t: float) -> None:
        if self.options.mode == "one-switch":
            self.say.say("press the switch to start scanning")
            self.scanner.start(t)
        else:
            self.say.say("two-switch scanning: switch moves, select selects")
            self._emit(self.scanner.start(t))

    def on_input(self, ev: InputEvent) -> None:
        if ev.kind not in ("press", "release"):
            return
        scanner = self.scanner
        if isinstance(scanner, AutoScanner):
            out = scanner.press(ev.t) if ev.kind == "press" else scanner.release(ev.t)
        else:
            out = (
                scanner.press(ev.t, ev.name)
                if ev.kind == "press"
                else scanner.release(ev.t, ev.name)
            )
        self._emit(out)

    def advance(self, t: float) -> None:
        self._emit(self.scanner.advance(t))
        if self._drive is not None:
            self.link.drive(*self._drive)

    def deadline(self) -> float | None:
        d = self.scanner.deadline()
        if self._drive is not None:
            refresh = self.scanner.now + DRIVE_REFRESH
            d = refresh if d is None else min(d, refresh)
        return d

    def on_link(self, connected: bool, t: float) -> None:
        if not connected:
            self._emit(self.scanner.interrupt(t))

    def highlighted(self) -> tuple[str, float] | None:
        key = self.scanner.highlighted
        return None if key is None else (key, self.scanner.highlighted_at)

    def shutdown(self, t: float) -> None:
        self._drive = None
        self.link.stop_drive()

    # --- outputs -------------------------------------------------------------------------

    def _emit(self, outputs: list[Output]) -> None:
        for o in outputs:
            if isinstance(o, Highlight):
                self.say.say(f"highlight {o.key}", o.label, at=o.t)
            elif isinstance(o, Selected):
                self.say.say(f"select {o.item.key}", o.item.label)
                self._act(o.item)
            elif isinstance(o, Pending):
                delay = o.until - o.t
                self.say.say(
                    f"selected {o.item.key}: acts in {delay:.1f} s, press to undo",
                    f"{o.item.label}, press to undo",
                )
            elif isinstance(o, Undone):
                self.say.say(f"undone {o.item.key}", "undone")
            elif isinstance(o, HoldStart):
                self.say.say(f"hold {o.item.key}: moving while the switch is held", o.item.label)
                self._drive = self._drive_of(o.item)
                self.link.drive(*self._drive)
            elif isinstance(o, HoldEnd):
                self.say.say(f"release {o.item.key}: stop", "stop")
                self._drive = None
                self.link.stop_drive()
            elif isinstance(o, Stopped):
                self.say.say("scanning stopped: press the switch to start", "scanning stopped")

    def _drive_of(self, item: Item) -> tuple[float, float]:
        s, w = self.options.speed, self.options.turn
        return {
            "drive_forward": (s, 0.0),
            "drive_reverse": (-s, 0.0),
            "drive_left": (0.0, w),
            "drive_right": (0.0, -w),
        }[item.action]

    def _act(self, item: Item) -> None:
        a, s, link = item.action, self.options.step, self.link
        nudges = {
            "nudge_up": (0.0, s),
            "nudge_down": (0.0, -s),
            "nudge_left": (s, 0.0),
            "nudge_right": (-s, 0.0),
        }
        if a in nudges:
            if not link.connected:
                self.say.note(f"not connected: {item.key} not sent")
            link.nudge(*nudges[a])
        elif a == "confirm":
            link.post("confirm", "/laser/confirm")
        elif a in ("grasp_prev", "grasp_next"):
            link.call(item.label, step_grasp(+1 if a == "grasp_next" else -1))
        elif a == "go":
            link.post("go", "/execute")
        elif a in MODE_BODIES:
            label, body = MODE_BODIES[a]
            link.post(label, "/mode", body)
        elif a == "cancel":
            link.post("cancel", "/cancel")
        else:
            raise ValueError(f"no action {a!r}")
