"""Household objects: their models, the built-in library, their rest poses, their MuJoCo bodies.

Every object is a rigid body made of a few primitive geoms (or convex mesh pieces for user
meshes). Its frame has its origin at the centre of its bottom face and z up when it stands in
its natural upright pose, so an object placed with its origin on a surface rests on it. All
numbers are SI: metres, kilograms; `friction` is the sliding coefficient.

Geom groups are a convention shared with the sensor code: surfaces and opaque objects are in
`GROUP_OPAQUE`, the robot in `GROUP_ROBOT`, transparent objects in `GROUP_TRANSPARENT` (the
depth sensors do not see them) and specular objects in `GROUP_SPECULAR`.
"""

from laserpick.robot.sim.objects.geometry import (
    axis_angle_quat,
    center_of_mass,
    min_width,
    part_support,
    part_volume,
    quat_mul,
    support,
    yaw_quat,
)
from laserpick.robot.sim.objects.groups import (
    GROUP_OPAQUE,
    GROUP_ROBOT,
    GROUP_SPECULAR,
    GROUP_TRANSPARENT,
    OBJECT_CONAFFINITY,
    OBJECT_CONTYPE,
    OPTICAL_GROUP,
    SURFACE_CONAFFINITY,
    SURFACE_CONTYPE,
    TRANSPARENT_ALPHA,
)
from laserpick.robot.sim.objects.library import (
    GRIPPABLE_WIDTH,
    LIBRARY,
    MAX_OBJECT_MASS,
    opaque_names,
)
from laserpick.robot.sim.objects.mjcf import OBJECT_CONDIM, OBJECT_FRICTION_TAIL, add_object_body
from laserpick.robot.sim.objects.object_model import (
    MeshAsset,
    ObjectModel,
    OpticalKind,
    Part,
    PartKind,
)
from laserpick.robot.sim.objects.rest import (
    REST_BACK_DEG,
    REST_TIP_DEG,
    RestPose,
    at_rest,
    footprint_half_extents,
    rest_pose,
)

__all__ = [
    "GRIPPABLE_WIDTH",
    "GROUP_OPAQUE",
    "GROUP_ROBOT",
    "GROUP_SPECULAR",
    "GROUP_TRANSPARENT",
    "LIBRARY",
    "MAX_OBJECT_MASS",
    "OBJECT_CONAFFINITY",
    "OBJECT_CONDIM",
    "OBJECT_CONTYPE",
    "OBJECT_FRICTION_TAIL",
    "OPTICAL_GROUP",
    "REST_BACK_DEG",
    "REST_TIP_DEG",
    "SURFACE_CONAFFINITY",
    "SURFACE_CONTYPE",
    "TRANSPARENT_ALPHA",
    "MeshAsset",
    "ObjectModel",
    "OpticalKind",
    "Part",
    "PartKind",
    "RestPose",
    "add_object_body",
    "at_rest",
    "axis_angle_quat",
    "center_of_mass",
    "footprint_half_extents",
    "min_width",
    "opaque_names",
    "part_support",
    "part_volume",
    "quat_mul",
    "rest_pose",
    "support",
    "yaw_quat",
]
