"""The scanning state machines, pure: every method takes the time (s, on the adapter's
monotonic clock) and returns what happened (`Output`), so a test can drive them with a fake
clock. What is scanned is `scan_menu.GROUPS`; when a press counts is `switch_timing`.

One-switch automatic scanning (`AutoScanner`): the first activation starts the scan at the
first group; the highlight moves every `period` s; an activation enters the highlighted group
or selects the highlighted item. After a selection the highlight stays on that item (press
again to repeat it, e.g. several nudges) and the scan goes on from there. `cycles` full passes
without an activation fall back: items to their group, groups to a stopped scan (0: never).
With an activation `delay`, a selection waits that long before it acts, the highlight holding
still, and another activation meanwhile undoes it.

Two-switch step scanning (`StepScanner`): the "switch" input moves the highlight one step, the
"select" input selects (enter a group, act, undo a pending selection). Nothing moves by time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from laserpick.adapters.scan_menu import BACK, GROUPS, Group, Item
from laserpick.adapters.switch_timing import ScanTiming, SwitchFilter

__all__ = [
    "AutoScanner",
    "Highlight",
    "HoldEnd",
    "HoldStart",
    "Output",
    "Pending",
    "Scanner",
    "Selected",
    "StepScanner",
    "Stopped",
    "Undone",
]


# --- what the scanners report ------------------------------------------------------------------


@dataclass(frozen=True)
class Highlight:
    """The highlight moved onto `key`, a group or an item, at t."""

    t: float
    key: str
    label: str
    level: Literal["group", "item"]


@dataclass(frozen=True)
class Selected:
    """The item's action runs now."""

    t: float
    item: Item


@dataclass(frozen=True)
class Pending:
    """Selected; acts at `until` unless undone."""

    t: float
    item: Item
    until: float


@dataclass(frozen=True)
class Undone:
    """A pending selection was undone before it acted."""

    t: float
    item: Item


@dataclass(frozen=True)
class HoldStart:
    """A hold item (drive) acts from now until HoldEnd."""

    t: float
    item: Item


@dataclass(frozen=True)
class HoldEnd:
    """The switch held for a hold item was released (or the link dropped): stop."""

    t: float
    item: Item


@dataclass(frozen=True)
class Stopped:
    """Automatic scanning stopped after its cycles; an activation starts it again."""

    t: float


Output = Highlight | Selected | Pending | Undone | HoldStart | HoldEnd | Stopped

# --- the scanners ------------------------------------------------------------------------------


@dataclass
class _Cursor:
    level: Literal["idle", "group", "item"] = "idle"
    group: int = 0
    item: int = 0
    shown: int = 0  #: highlights since the last activation at this level


@dataclass
class Scanner:
    """What both scanners share: the cursor over groups and items, selection with delay and
    undo, and hold items. Subclasses decide what moves the highlight."""

    timing: ScanTiming
    groups: tuple[Group, ...] = GROUPS
    cursor: _Cursor = field(default_factory=_Cursor)
    pending: Pending | None = None
    holding: Item | None = None
    now: float = -math.inf
    highlighted_at: float = -math.inf  #: when the current highlight appeared

    # --- queries -------------------------------------------------------------------------

    @property
    def highlighted(self) -> str | None:
        """The key of what is highlighted (None when the scan is stopped)."""
        c = self.cursor
        if c.level == "idle":
            return None
        group = self.groups[c.group]
        return group.key if c.level == "group" else group.items[c.item].key

    def deadline(self) -> float | None:
        """The next time something happens without input (None: nothing scheduled)."""
        raise NotImplementedError

    # --- shared moves --------------------------------------------------------------------

    def _show(self, t: float, out: list[Output]) -> None:
        c = self.cursor
        group = self.groups[c.group]
        c.shown += 1
        self.highlighted_at = t
        if c.level == "group":
            out.append(Highlight(t, group.key, group.label, "group"))
        else:
            item = group.items[c.item]
            out.append(Highlight(t, item.key, item.label, "item"))

    def _step(self, t: float, out: list[Output]) -> None:
        """Move the highlight one element on, wrapping."""
        c = self.cursor
        if c.level == "group":
            c.group = (c.group + 1) % len(self.groups)
        elif c.level == "item":
            c.item = (c.item + 1) % len(self.groups[c.group].items)
        self._show(t, out)

    def _select(self, t: float, out: list[Output]) -> None:
        """An activation on what is highlighted."""
        c = self.cursor
        if self.pending is not None:
            out.append(Undone(t, self.pending.item))
            self.pending = None
            self._after_selection(t)
            return
        if c.level == "idle":
            c.level, c.group, c.shown = "group", 0, 0
            self._show(t, out)
            return
        group = self.groups[c.group]
        if c.level == "group" and group.action is None:
            c.level, c.item, c.shown = "item", 0, 0
            self._show(t, out)
            return
        item = group.as_item() if c.level == "group" else group.items[c.item]
        if item.hold:
            self.holding = item
            out.append(HoldStart(t, item))
        elif self.timing.delay > 0 and item.action != BACK:
            self.pending = Pending(t, item, t + self.timing.delay)
            out.append(self.pending)
        else:
            self._act(t, item, out)

    def _act(self, t: float, item: Item, out: list[Output]) -> None:
        c = self.cursor
        if item.action == BACK:
            c.level, c.shown = "group", 0
            self._show(t, out)
        else:
            out.append(Selected(t, item))
            c.shown = 1  # the highlight stays: a further activation repeats it
        self._after_selection(t)

    def _after_selection(self, t: float) -> None:
        """Hook: the scan resumes after a selection (or an undo) at t."""

    def _end_hold(self, t: float, out: list[Output]) -> None:
        if self.holding is not None:
            out.append(HoldEnd(t, self.holding))
            self.holding = None
            self._after_selection(t)

    def interrupt(self, t: float) -> list[Output]:
        """The connection dropped: end a hold and undo a pending selection. The switch must be
        released and pressed again before anything acts."""
        out = self.advance(t)
        if self.pending is not None:
            out.append(Undone(t, self.pending.item))
            self.pending = None
            self._after_selection(t)
        self._end_hold(t, out)
        return out

    def advance(self, t: float) -> list[Output]:
        raise NotImplementedError


@dataclass
class AutoScanner(Scanner):
    """One-switch automatic scanning. Input: presses and releases of the one switch."""

    switch: SwitchFilter = field(init=False)
    next_step: float | None = None

    def __post_init__(self) -> None:
        self.switch = SwitchFilter(self.timing.accept, self.timing.release)

    def start(self, t: float) -> list[Output]:
        """The scan waits for a first activation."""
        self.now = t
        return [Stopped(t)]

    def press(self, t: float) -> list[Output]:
        out = self.advance(t)
        self.switch.press(max(t, self.now))
        out += self.advance(t)
        return out

    def release(self, t: float) -> list[Output]:
        out = self.advance(t)
        if self.switch.up(max(t, self.now)):
            self._end_hold(max(t, self.now), out)
        return out

    def deadline(self) -> float | None:
        times = [
            x
            for x in (
                self.pending.until if self.pending else None,
                self.switch.due(),
                self.next_step,
            )
            if x is not None
        ]
        return min(times) if times else None

    def _after_selection(self, t: float) -> None:
        self.next_step = t + self.timing.period

    def advance(self, t: float) -> list[Output]:
        """Everything scheduled up to t, in time order (ties: a pending action fires, then a
        press is accepted, then the highlight moves)."""
        out: list[Output] = []
        while True:
            pend = self.pending.until if self.pending else math.inf
            acc = self.switch.due()
            acc = math.inf if acc is None else acc
            step = math.inf if self.next_step is None else self.next_step
            first = min(pend, acc, step)
            if first > t:
                break
            self.now = max(self.now, first)
            if pend == first:
                assert self.pending is not None
                item, self.pending = self.pending.item, None
                self._act(first, item, out)
            elif acc == first:
                self.switch.accept_at(first)
                self.next_step = None
                self._select(first, out)
                if self.cursor.level != "idle" and self.pending is None and not self.holding:
                    self.next_step = first + self.timing.period
            else:
                self._timed_step(first, out)
        self.now = max(self.now, t)
        return out

    def _timed_step(self, t: float, out: list[Output]) -> None:
        c = self.cursor
        limit = self.timing.cycles * (
            len(self.groups) if c.level == "group" else len(self.groups[c.group].items)
        )
        if limit and c.shown >= limit:
            if c.level == "item":
                c.level, c.shown = "group", 0
                self._show(t, out)
                self.next_step = t + self.timing.period
            else:
                c.level, c.shown = "idle", 0
                self.next_step = None
                out.append(Stopped(t))
            return
        self._step(t, out)
        self.next_step = t + self.timing.period


@dataclass
class StepScanner(Scanner):
    """Two-switch step scanning. Inputs: "switch" moves the highlight, "select" selects."""

    move: SwitchFilter = field(init=False)
    choose: SwitchFilter = field(init=False)

    def __post_init__(self) -> None:
        self.move = SwitchFilter(self.timing.accept, self.timing.release)
        self.choose = SwitchFilter(self.timing.accept, self.timing.release)

    def start(self, t: float) -> list[Output]:
        """The highlight starts on the first group."""
        self.now = t
        self.cursor = _Cursor(level="group")
        out: list[Output] = []
        self._show(t, out)
        return out

    def _switch(self, name: str) -> SwitchFilter:
        return self.choose if name == "select" else self.move

    def press(self, t: float, name: str = "switch") -> list[Output]:
        out = self.advance(t)
        self._switch(name).press(max(t, self.now))
        out += self.advance(t)
        return out

    def release(self, t: float, name: str = "switch") -> list[Output]:
        out = self.advance(t)
        ended = self._switch(name).up(max(t, self.now))
        if ended and name == "select":
            self._end_hold(max(t, self.now), out)
        return out

    def deadline(self) -> float | None:
        times = [
            x
            for x in (
                self.pending.until if self.pending else None,
                self.move.due(),
                self.choose.due(),
            )
            if x is not None
        ]
        return min(times) if times else None

    def advance(self, t: float) -> list[Output]:
        out: list[Output] = []
        while True:
            pend = self.pending.until if self.pending else math.inf
            mv = self.move.due()
            mv = math.inf if mv is None else mv
            ch = self.choose.due()
            ch = math.inf if ch is None else ch
            first = min(pend, mv, ch)
            if first > t:
                break
            self.now = max(self.now, first)
            if pend == first:
                assert self.pending is not None
                item, self.pending = self.pending.item, None
                self._act(first, item, out)
            elif ch == first:
                self.choose.accept_at(first)
                self._select(first, out)
            else:
                self.move.accept_at(first)
                if self.pending is not None:  # either switch undoes
                    self._select(first, out)
                elif self.holding is None:
                    self._step(first, out)
        self.now = max(self.now, t)
        return out
