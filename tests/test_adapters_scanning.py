"""The switch adapter's timing and scanning state machines, on a fake clock: acceptance and
release times, one-switch automatic scanning (period, cycles, repeats, back, the undo delay,
held drive items) and two-switch step scanning.
"""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.adapters import (
    GROUPS,
    AutoScanner,
    Highlight,
    ScanTiming,
    Selected,
    StepScanner,
    Stopped,
    SwitchFilter,
)


def kinds(outputs: list) -> list[str]:
    """Output type names, with the key for a highlight (`Highlight:laser`)."""
    return [type(o).__name__ + (f":{o.key}" if isinstance(o, Highlight) else "") for o in outputs]


def test_switch_filter_acceptance_and_release_time() -> None:
    f = SwitchFilter(accept=0.1, release=0.2)
    f.press(1.0)
    assert f.due() == pytest.approx(1.1)
    assert not f.up(1.05)  # shorter than the acceptance time: nothing
    f.press(1.1)  # within the release time of the last release: ignored
    assert f.due() is None
    f.up(1.5)
    f.press(1.8)
    f.accept_at(1.9)
    assert f.up(2.5)


def test_one_switch_scan_advances_each_period_and_stops_after_its_cycles() -> None:
    sc = AutoScanner(ScanTiming(period=1.0, cycles=2, accept=0.1, release=0.1))
    assert kinds(sc.start(0.0)) == ["Stopped"]
    assert sc.deadline() is None  # nothing moves until the switch is used
    sc.press(10.0)
    out = sc.advance(10.1)
    assert kinds(out) == ["Highlight:laser"] and out[0].t == pytest.approx(10.1)
    sc.release(10.2)
    out = sc.advance(20.5)
    times = [o.t for o in out if isinstance(o, Highlight)]
    assert np.allclose(np.diff([10.1, *times]), 1.0)  # exactly one period apart
    assert [o.key for o in out if isinstance(o, Highlight)] == [g.key for g in GROUPS[1:]] + [
        g.key for g in GROUPS
    ]
    assert isinstance(out[-1], Stopped) and out[-1].t == pytest.approx(20.1)  # 2 cycles x 5
    assert sc.highlighted is None


def test_one_switch_selects_repeats_and_goes_back() -> None:
    sc = AutoScanner(ScanTiming(period=1.0, cycles=0, accept=0.1, release=0.1))
    sc.start(0.0)
    sc.press(0.0)
    sc.release(0.2)  # laser highlighted at 0.1
    sc.press(0.5)
    out = sc.release(0.7)
    assert kinds(out) == ["Highlight:laser.up"]
    out = sc.advance(1.65)  # down at 1.6
    sc.press(1.7)
    out = sc.release(1.9)
    assert [o.item.key for o in out if isinstance(o, Selected)] == ["laser.down"]
    sc.press(2.1)  # again: the highlight stayed on down
    out = sc.release(2.3)
    assert [o.item.key for o in out if isinstance(o, Selected)] == ["laser.down"]
    assert sc.deadline() == pytest.approx(3.2)  # the scan goes on a period after the selection
    out = sc.advance(6.25)  # left 3.2, right 4.2, confirm 5.2, back 6.2
    assert sc.highlighted == "laser.back"
    sc.press(6.3)
    out = sc.release(6.5)
    assert kinds(out) == ["Highlight:laser"]
    assert not any(isinstance(o, Selected) for o in out)


def test_activation_delay_lets_a_wrong_pick_be_undone() -> None:
    sc = AutoScanner(ScanTiming(period=1.0, cycles=0, accept=0.1, release=0.1, delay=1.5))
    sc.start(0.0)
    for t in (0.0, 0.4):  # laser at 0.1; enter: laser.up at 0.5 (entries act at once)
        sc.press(t)
        sc.release(t + 0.2)
    sc.press(0.8)
    out = sc.release(1.0)
    assert kinds(out) == ["Pending"] and out[0].until == pytest.approx(2.4)
    assert sc.advance(2.2) == []  # the highlight holds still while pending
    sc.press(2.2)
    out = sc.release(2.5)  # accepted at 2.3 < 2.4: undone
    assert kinds(out) == ["Undone"]
    out = sc.advance(10.0)
    assert not any(isinstance(o, Selected) for o in out)
    # a selection left alone acts when the delay ends
    sc2 = AutoScanner(ScanTiming(period=1.0, cycles=0, accept=0.1, release=0.1, delay=1.5))
    sc2.start(0.0)
    for t in (0.0, 0.4, 0.8):
        sc2.press(t)
        sc2.release(t + 0.2)
    out = sc2.advance(2.45)
    sel = [o for o in out if isinstance(o, Selected)]
    assert [o.item.key for o in sel] == ["laser.up"] and sel[0].t == pytest.approx(2.4)


def test_drive_items_act_only_while_the_switch_is_held() -> None:
    sc = AutoScanner(ScanTiming(period=1.0, cycles=0, accept=0.1, release=0.1))
    sc.start(0.0)
    sc.press(0.0)
    sc.release(0.2)  # laser 0.1, grasps 1.1, drive 2.1
    sc.advance(2.2)
    sc.press(2.3)
    sc.release(2.5)  # drive.forward at 2.4
    sc.press(2.7)
    out = sc.advance(2.85)
    assert kinds(out) == ["HoldStart"] and out[0].item.key == "drive.forward"
    assert sc.advance(9.0) == []  # the scan waits while driving
    out = sc.release(9.0)
    assert kinds(out) == ["HoldEnd"]
    assert kinds(sc.advance(10.0)) == ["Highlight:drive.reverse"]
    # left 11, right 12, back 13, forward 14: a lost connection ends the hold, and the
    # switch still held does nothing more
    sc.advance(14.05)
    assert sc.highlighted == "drive.forward"
    sc.press(14.1)
    assert kinds(sc.advance(14.25)) == ["HoldStart"]
    assert kinds(sc.interrupt(14.6)) == ["HoldEnd"]
    assert all(k.startswith("Highlight") for k in kinds(sc.release(17.0)))  # the scan goes on


def test_two_switch_step_scanning() -> None:
    sc = StepScanner(ScanTiming(accept=0.05, release=0.1))
    assert kinds(sc.start(0.0)) == ["Highlight:laser"]
    assert sc.advance(0.9) == []  # nothing moves by time
    sc.press(1.0, "switch")
    assert kinds(sc.release(1.2, "switch")) == ["Highlight:grasps"]
    sc.press(2.0, "select")
    assert kinds(sc.release(2.2, "select")) == ["Highlight:grasps.previous"]
    for t in (3.0, 4.0):
        sc.press(t, "switch")
        sc.release(t + 0.2, "switch")
    sc.press(5.0, "select")
    out = sc.release(5.2, "select")
    assert [o.item.key for o in out if isinstance(o, Selected)] == ["grasps.go"]


def test_two_switch_undo_with_either_switch() -> None:
    sc = StepScanner(ScanTiming(accept=0.05, release=0.1, delay=1.0))
    sc.start(0.0)
    sc.press(1.0, "select")
    sc.release(1.2, "select")  # enter laser
    sc.press(2.0, "select")
    assert kinds(sc.release(2.2, "select")) == ["Pending"]
    sc.press(2.5, "switch")
    assert kinds(sc.release(2.7, "switch")) == ["Undone"]
    assert not any(isinstance(o, Selected) for o in sc.advance(10.0))


def test_scan_timing_is_checked() -> None:
    with pytest.raises(ValueError, match="period"):
        ScanTiming(period=0.0)
    with pytest.raises(ValueError, match="accept"):
        ScanTiming(accept=-1.0)
