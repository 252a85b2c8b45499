"""Arm collision checks for planning (paper 004 section 7): the UR5 and its gripper as chains
of spheres (`arm_spheres`), tested against the fused cloud (`obstacles`: a KD-tree of
voxel-thinned points), the keep-out boxes around the scooter and its rider (`keepout`), and
the floor; on planned transits, also against the space no camera saw (`seen_space`). What
the hand carries is checked with it (`carried`), its many points bounded by a ball first
(`broad_phase`). `CollisionChecker` (`checker`) asks all of these. Frames: `base` (x
forward, y left, z up), metres; joint angles in rad.
"""

from laserpick.pipeline.cloud import thin
from laserpick.pipeline.collision.arm_spheres import (
    HAND_BODY,
    SPHERES,
    SphereModel,
    sphere_centres,
    sphere_model,
)
from laserpick.pipeline.collision.carried import (
    CARRIED_PADDING,
    CARRIED_TOP_BAND,
    CARRIED_VOXEL,
    COARSE_PAYLOAD,
    PAYLOAD_CLEAR_OF_BODY,
    PAYLOAD_POINT_RADIUS,
    carried_shape,
    coarse_payload,
    held_at,
    held_clear_of_arm,
    held_points,
    mirrored_back,
    not_carried,
    object_middle,
)
from laserpick.pipeline.collision.checker import (
    CLEARANCE_STEPS,
    SEGMENT_COARSE,
    CollisionChecker,
)
from laserpick.pipeline.collision.obstacles import (
    REACH,
    SELF_PADDING,
    obstacle_mask,
    self_filter,
    surface_front,
    within_reach,
)
from laserpick.pipeline.collision.seen_space import (
    OWN_SPACE_PADDING,
    SEEN_TOLERANCE,
    UNSTOW_BOX,
    unseen_spheres,
)

__all__ = [
    "CARRIED_PADDING",
    "CARRIED_TOP_BAND",
    "CARRIED_VOXEL",
    "CLEARANCE_STEPS",
    "COARSE_PAYLOAD",
    "HAND_BODY",
    "OWN_SPACE_PADDING",
    "PAYLOAD_CLEAR_OF_BODY",
    "PAYLOAD_POINT_RADIUS",
    "REACH",
    "SEEN_TOLERANCE",
    "SEGMENT_COARSE",
    "SELF_PADDING",
    "SPHERES",
    "UNSTOW_BOX",
    "CollisionChecker",
    "SphereModel",
    "carried_shape",
    "coarse_payload",
    "held_at",
    "held_clear_of_arm",
    "held_points",
    "mirrored_back",
    "not_carried",
    "object_middle",
    "obstacle_mask",
    "self_filter",
    "sphere_centres",
    "sphere_model",
    "surface_front",
    "thin",
    "unseen_spheres",
    "within_reach",
]
