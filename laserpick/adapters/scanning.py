"""Switch timing and scanning, as pure state machines: every method takes the time (s, on the
adapter's monotonic clock) and returns what happened, so a test can drive them with a fake
clock.

Switch timing (`SwitchFilter`), per switch:
- acceptance time: a press counts once it has been held `accept` s (shorter presses, a tremor
  or a bounce, do nothing);
- release time: presses that start within `release` s of the last release are ignored (a
  contact bouncing as it opens, a second unintended hit).

What is scanned, groups first then items (`GROUPS`): laser (up, down, left, right, confirm,
back), grasps (previous, next, go, back), drive (forward, reverse, left, right, back), mode
(pick and drop, pick and place, automatic grasp, manual grasp, back), and cancel, which acts
at once. Drive items act while the switch stays held after the selection (a dead-man).

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

# --- what is scanned ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Item:
    """One scanned choice. key: `group.item`, unique; label: what is announced; action: what
    the adapter does; hold: acts while the switch is held (driving), not once."""

    key: str
    label: str
    action: str
    hold: bool = False


@dataclass(frozen=True)
class Group:
    """A group of items, or (no items) a choice that acts itself, like cancel."""

    key: str
    label: str
    items: tuple[Item, ...] = ()
    action: str | None = None

    def as_item(self) -> Item:
        assert self.action is not None
        return Item(self.key, self.label, self.action)


BACK = "back"


def _group(key: str, label: str, *items: tuple[str, str, str, bool]) -> Group:
    made = tuple(Item(f"{key}.{k}", lab, action, hold) for k, lab, action, hold in items)
    return Group(key, label, (*made, Item(f"{key}.back", "back", BACK)))


GROUPS: tuple[Group, ...] = (
    _group(
        "laser",
        "laser",
        ("up", "up", "nudge_up", False),
        ("down", "down", "nudge_down", False),
        ("left", "left", "nudge_left", False),
        ("right", "right", "nudge_right", False),
        ("confirm", "confirm", "confirm", False),
    ),
    _group(
        "grasps",
        "grasps",
        ("previous", "previous grasp", "grasp_prev", False),
        ("next", "next grasp", "grasp_next", False),
        ("go", "go", "go", False),
    ),
    _group(
        "drive",
        "drive",
        ("forward", "forward", "drive_forward", True),
        ("reverse", "reverse", "drive_reverse", True),
        ("left", "turn left", "drive_left", True),
        ("right", "turn right", "drive_right", True),
    ),
    _group(
        "mode",
        "mode",
        ("drop", "pick and drop", "mode_drop", False),
        ("place", "pick and place", "mode_place", False),
        ("auto", "automatic grasp", "select_auto", False),
        ("manual", "manual grasp", "select_manual", False),
    ),
    Group("cancel", "cancel", action="cancel"),
)


# --- what the scanners report ------------------------------------------------------------------


@dataclass(frozen=True)
class Highlight:
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
    t: float
    item: Item


@dataclass(frozen=True)
class HoldStart:
    """A hold item (drive) acts from now until HoldEnd."""

    t: float
    item: Item


@dataclass(frozen=True)
class HoldEnd:
    t: float
    item: Item


@dataclass(frozen=True)
class Stopped:
    """Automatic scanning stopped after its cycles; an activation starts it again."""

    t: float


Output = Highlight | Selected | Pending | Undone | HoldStart | HoldEnd | Stopped


@dataclass(frozen=True)
class ScanTiming:
    """period: s per highlighted element (automatic scanning); cycles: passes without an
    activation before falling back (0: never); accept: s a press must be held; release: s
    after a release during which presses are ignored; delay: s between selecting and acting,
    during which an activation undoes the selection."""

    period: float = 1.0
    cycles: int = 3
    accept: float = 0.1
    release: float = 0.1
    delay: float = 0.0

    def __post_init__(self) -> None:
        for name in ("period", "accept", "release", "delay"):
            value = getattr(self, name)
            if not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number of seconds >= 0, not {value}")
        if self.period <= 0:
            raise ValueError("the scan period must be more than 0 s")
        if self.cycles < 0:
            raise ValueError("cycles must be 0 (never stop) or more")


# --- one switch's timing -----------------------------------------------------------------------


@dataclass
class SwitchFilter:
    """Raw presses and releases of one switch -> activations (see the module docstring)."""

    accept: float
    release: float
    down_at: float | None = None
    active: bool = False  #: the current press has been accepted
    ignored: bool = False  #: the current press started within the release time
    last_release: float = -math.inf

    def press(self, t: float) -> None:
        if self.down_at is not None:
            return  # already down (a repeated report)
        self.down_at, self.active = t, False
        self.ignored = t - self.last_release < self.release

    def up(self, t: float) -> bool:
        """The switch opened at t; True if an accepted press ended."""
        if self.down_at is None:
            return False
        was_active = self.active
        self.down_at, self.active, self.ignored = None, False, False
        self.last_release = t
        return was_active

    def due(self) -> float | None:
        """When the current press will be accepted, if it is still held then."""
        if self.down_at is None or self.active or self.ignored:
            return None
        return self.down_at + self.accept

    def accept_at(self, t: float) -> None:
        self.active = True


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
