"""The frames stacked for the free-space test (`frame_stack`): kept while asked, and a
stack let go lends its buffer to the next only when no one holds it, so that what a search
on another thread still asks is never written over."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.pipeline import frame_stack as fs
from laserpick.pipeline.frame_stack import STACKS_KEPT, frame_stack
from laserpick.types import DepthFrame


def _frames(n: int, fill: float, shape: tuple[int, int] = (6, 8)) -> tuple[DepthFrame, ...]:
    """n frames of one depth `fill` (m), looking along +x from the origin."""
    K = np.array([[4.0, 0.0, shape[1] / 2], [0.0, 4.0, shape[0] / 2], [0.0, 0.0, 1.0]])
    T = np.eye(4)
    T[:3, :3] = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    return tuple(
        DepthFrame(
            depth=np.full(shape, fill + 0.1 * k, np.float32),
            ir=np.zeros((0, 0), np.uint8),
            K=K,
            T_base_cam=T,
            camera=f"cam{k}",
            stamp=0.0,
        )
        for k in range(n)
    )


@pytest.fixture(autouse=True)
def _empty_cache():
    fs._STACKS.clear()
    fs._SPARES.clear()
    yield
    fs._STACKS.clear()
    fs._SPARES.clear()


def _asked_alike(stack: fs.FrameStack, frames: tuple[DepthFrame, ...]) -> None:
    """The stack reads what a stack built afresh reads, at points before and past every
    frame's depth."""
    fresh = fs.FrameStack(frames)
    np.testing.assert_array_equal(stack.depths, fresh.depths)
    points = np.array([[x, 0.0, 0.0] for x in np.linspace(0.2, 3.0, 29)])
    tolerance = np.full(len(points), 0.006)
    np.testing.assert_array_equal(
        stack.seen_past(points, tolerance), fresh.seen_past(points, tolerance)
    )


def test_the_same_frames_are_stacked_once() -> None:
    frames = _frames(3, 1.0)
    assert frame_stack(frames) is frame_stack(list(frames))


def test_a_stack_let_go_lends_its_buffer_to_the_next() -> None:
    kept = [_frames(3, 1.0 + k) for k in range(STACKS_KEPT)]
    first = frame_stack(kept[0]).buffer
    for frames in kept[1:]:
        frame_stack(frames)
    later = _frames(3, 2.5)
    stack = frame_stack(later)
    assert stack.buffer is first
    _asked_alike(stack, later)


def test_a_stack_still_asked_keeps_its_buffer() -> None:
    held = frame_stack(_frames(3, 1.0))  # a search on another thread asks it still
    before = held.depths.copy()
    for k in range(1, STACKS_KEPT + 2):
        frame_stack(_frames(3, 1.0 + k))
    assert all(stack is not held for stack in fs._STACKS.values())
    np.testing.assert_array_equal(held.depths, before)
    assert all(b is not held.buffer for b in fs._SPARES)


def test_a_buffer_much_larger_than_needed_is_not_taken() -> None:
    large = frame_stack(_frames(12, 1.0)).buffer
    for k in range(STACKS_KEPT):
        small = frame_stack(_frames(2, 2.0 + k))
        assert small.buffer is not large
    again = _frames(12, 3.0)
    stack = frame_stack(again)
    assert stack.buffer is large
    _asked_alike(stack, again)
