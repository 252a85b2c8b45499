"""perceive() end to end: five simulated frames with a laser dot in, the target out, scored
against the simulator's truth (which perceive never sees)."""

from __future__ import annotations

import numpy as np
import pytest

from laserpick.bench.scoring import iou
from laserpick.pipeline.cloud import fuse
from laserpick.pipeline.perceive import perceive
from laserpick.robot.sim.scenes import parse_scene
from laserpick.robot.sim.truth import capture


@pytest.fixture(scope="module")
def isolation():
    c = capture("isolation", seed=5)
    yield c
    c.close()


def _visible_top(c, instance: str) -> np.ndarray:
    return c.visible_top(fuse(c.frames), instance)


def test_laser_marks_segment_each_object(isolation):
    c = isolation
    for p in c.scene.placements:
        c.robot.laser.aim_at(_visible_top(c, p.instance))
        c.robot.laser.confirm()
        frames, labels = c.robot.capture_with_labels()
        c.labels = labels  # score against the frames perceive saw
        result = perceive(frames)
        assert result.ok, f"{p.instance}: {result.failure}"
        assert result.mark is not None and result.mark.state == "confirmed"
        assert result.mark.views >= 2
        truth = c.object_points(result.cloud, p.instance)
        found = np.zeros(len(result.cloud), bool)
        found[result.segmentation.indices] = True
        assert iou(found, truth) >= 0.9, f"{p.instance}: IoU {iou(found, truth):.2f}"
        assert set(result.timings) == {"fuse", "detect_laser", "segment"}
        assert result.target_points.shape == (len(result.segmentation.indices), 3)


def test_a_direct_point_skips_the_laser(isolation):
    c = isolation
    c.robot.laser.off()
    p = c.scene.placements[0]
    result = perceive(c.robot.capture(), point=_visible_top(c, p.instance))
    assert result.ok and result.mark.source == "direct" and result.mark.views == 0
    assert len(result.target_points) > 100


def test_no_laser_is_a_typed_failure_with_a_sentence(isolation):
    c = isolation
    c.robot.laser.off()
    result = perceive(c.robot.capture())
    assert not result.ok and result.failure.kind == "detect_laser"
    assert result.segmentation is None and "laser" in result.failure.message
    assert "segment" not in result.timings


def test_a_transparent_cup_is_no_object_never_a_piece_of_table():
    text = """
name: glass
scooter: {x: 0, y: 0, yaw_deg: 0}
surfaces:
  - {name: table, kind: table, xy: [1.6, -0.15], size: [0.6, 1.0], height: 0.46}
objects:
  - {name: cup, model: glass_cup, on: table, xy: [1.5, -0.2]}
"""
    c = capture(parse_scene(text))
    try:
        pos, _ = c.object_pose("cup")
        c.robot.laser.aim_at(pos + [0.0, 0.0, 0.05])
        c.robot.laser.confirm()
        result = perceive(c.robot.capture())
        assert not result.ok
        assert "no object" in result.failure.message or "can't" in result.failure.message
    finally:
        c.close()
