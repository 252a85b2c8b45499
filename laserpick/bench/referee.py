"""The referee of the grasping experiments (004 section 8): the simulator's truth, with what
the scripted user reads of it to drive and aim.

The truth (`robot.sim.truth.SimTruth`) says where each object is, which object a grasp would
close on, whether an object ended up in the basket, and does what the experimenter does by
hand (empties the basket, moves a stuck arm home). None of it is ever shown to the pipeline;
the scripted user (`picking.ScriptedOperator`) uses it only to look at the world the way a
person would.
"""

from __future__ import annotations

import numpy as np

from laserpick.bench.route_planning import Outline
from laserpick.pipeline.cloud import fuse
from laserpick.robot.sim.truth import Captured, SimTruth


class Referee(SimTruth):
    """The simulator's truth, with what the scripted user reads of it to drive and aim."""

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

    def aim_point(self, instance: str) -> np.ndarray | None:
        """Where a person would aim: the middle of the object's visible top (m, `base`), from
        the cameras' view labelled by the simulator; None if no camera sees it."""
        frames, labels = self.robot.capture_with_labels()
        captured = Captured(self.robot, frames, labels)
        return captured.visible_top(fuse(frames), instance)
