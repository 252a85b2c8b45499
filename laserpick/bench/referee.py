"""The referee of the grasping experiments (004 section 8): the simulator's truth, with what
the scripted user reads of it to drive, aim and choose.

The truth (`robot.sim.truth.SimTruth`) says where each object is, which object a grasp would
close on, whether an object ended up in the basket, and does what the experimenter does by
hand (empties the basket, moves a stuck arm home). None of it is ever shown to the pipeline;
the scripted user (`picking.ScriptedOperator`) reads it to look at the world the way a
person would (docs/bench.md lists each read and why a person knows the same).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from laserpick.bench.route_planning import Outline
from laserpick.pipeline.cloud import fuse
from laserpick.robot.sim.truth import Captured, SimTruth, on_scooter
from laserpick.types import FusedCloud


@dataclass(frozen=True)
class View:
    """One look at the scene through the scooter's cameras, each seen point labelled by the
    simulator with the object it lies on: what a person in the seat sees of each object."""

    captured: Captured
    cloud: FusedCloud  #: the fused cloud of `captured`'s frames (m, `base` as it stood then)

    def top(self, instance: str) -> np.ndarray | None:
        """The middle of the object's visible top (m, `base`; `Captured.visible_top`), where
        a person aims; None if no camera sees it."""
        return self.captured.visible_top(self.cloud, instance)

    def points(self) -> dict[str, np.ndarray]:
        """The points the cameras saw on each object (m, `base`; (n, 3)), for every object
        seen at all: the objects' visible extent."""
        out = {}
        for name in (p.instance for p in self.captured.scene.placements):
            pts = self.cloud.points[self.captured.object_points(self.cloud, name)]
            if len(pts):
                out[name] = pts
        return out


class Referee(SimTruth):
    """The simulator's truth, with what the scripted user reads of it to drive, aim and
    choose."""

    def outline(self) -> Outline:
        """The scooter's footprint with the arm as it stands now, and what it holds (m,
        `base`): the bounds of the geoms of the scooter's body tree and of a held object."""
        m, d = self.robot.model, self._posed()
        bodies = self.robot.sim.info.object_bodies
        scooter = m.body("scooter").id
        held = {bodies[name] for name in bodies if self.near_hand(name)}
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        corners = []
        for g in range(m.ngeom):
            body = m.geom_bodyid[g]
            if m.body_rootid[body] != scooter and body not in held:
                continue
            local = m.geom_aabb[g, :3] + signs * m.geom_aabb[g, 3:]
            corners.append(local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g])
        world = np.vstack(corners)
        base = (self._T_base_world() @ np.c_[world, np.ones(len(world))].T).T
        lo, hi = base[:, :2].min(axis=0), base[:, :2].max(axis=0)
        return Outline((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1])))

    def rests_on_scooter(self, instance: str) -> bool:
        """Whether the object lies on the scooter outside the basket (`on_scooter`), not in
        the hand."""
        return on_scooter(self.centre_of_mass(instance)) and not self.near_hand(instance)

    def view(self) -> View:
        """A look at the scene now: one capture of the cameras, labelled by the simulator. It
        draws the cameras' noise as the session's own captures do."""
        frames, labels = self.robot.capture_with_labels()
        return View(Captured(self.robot, frames, labels), fuse(frames))

    def aim_point(self, instance: str) -> np.ndarray | None:
        """Where a person would aim: the middle of the object's visible top (m, `base`), from
        a `view` now; None if no camera sees it."""
        return self.view().top(instance)
