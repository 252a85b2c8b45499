"""The control lease: one holder, renewed by heartbeats, lapsing without them."""

from __future__ import annotations

import math

import pytest

from laserpick.server.lease import ControlLease, LeaseHeld


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock() -> Clock:
    return Clock()


def test_one_holder_at_a_time(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    token = lease.acquire("switch", "switch")
    with pytest.raises(LeaseHeld, match="switch"):
        lease.acquire("joystick", "joystick")
    assert lease.check(token) == "switch"
    assert lease.check("forged") is None
    assert lease.check(None) is None
    assert lease.info().holder == "switch"


def test_heartbeats_keep_it_and_silence_lets_it_lapse(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    token = lease.acquire("a", "rest")
    for _ in range(10):
        clock.now += 4.0
        assert lease.heartbeat(token)
    clock.now += 5.1
    assert not lease.holds(token)
    assert lease.silent_for(token) == math.inf
    other = lease.acquire("b", "rest")  # free again
    assert other != token and lease.check(token) is None


def test_renewing_with_the_token_keeps_the_same_token(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    token = lease.acquire("a", "rest")
    clock.now += 3.0
    assert lease.acquire("a", "rest", token) == token
    assert lease.silent_for(token) == 0.0


def test_a_dropped_connection_is_silence_at_once(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    token = lease.acquire("a", "rest")
    clock.now += 0.1
    assert lease.silent_for(token) == pytest.approx(0.1)
    assert lease.heard_at(token) == 100.0  # when it was taken, not how long ago
    lease.connection_lost(token)
    assert lease.silent_for(token) == math.inf and lease.heard_at(token) == -math.inf
    assert lease.heartbeat(token)  # it came back
    assert lease.silent_for(token) == 0.0


def test_release_frees_it_only_for_the_holder(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    token = lease.acquire("a", "rest")
    assert not lease.release("forged")
    assert lease.release(token)
    assert not lease.info().held


def test_the_page_and_the_3d_view_may_take_over_from_each_other(clock: Clock) -> None:
    lease = ControlLease(timeout=5.0, clock=clock)
    view = lease.acquire("3D view", "console")
    assert lease.token_of("console") == view
    assert lease.token_of("switch") is None
    page = lease.acquire("page", "console")  # the same operator station
    assert page != view and not lease.holds(view)
    with pytest.raises(LeaseHeld):
        lease.acquire("switch adapter", "switch")  # another person's device may not
