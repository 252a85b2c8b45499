"""Geom groups and collision bitmasks, shared by the object, scene, model and sensor code.

Surfaces and opaque objects are in `GROUP_OPAQUE`, the robot in `GROUP_ROBOT`, transparent
objects in `GROUP_TRANSPARENT` (the depth sensors do not see them) and specular objects in
`GROUP_SPECULAR`.
"""

from __future__ import annotations

#: Geom groups shared with the sensor and model code.
GROUP_OPAQUE = 0
GROUP_ROBOT = 1
GROUP_TRANSPARENT = 2
GROUP_SPECULAR = 3

#: Geom group of each optical kind.
OPTICAL_GROUP: dict[str, int] = {
    "opaque": GROUP_OPAQUE,
    "transparent": GROUP_TRANSPARENT,
    "specular": GROUP_SPECULAR,
}
#: Alpha that transparent objects render with in the viewer.
TRANSPARENT_ALPHA = 0.3
#: Collision bitmasks shared with the robot model (two geoms touch if type_a & affinity_b or
#: type_b & affinity_a): surfaces are static (type 1) and touch objects only; objects (type 2)
#: touch the floor and surfaces (1), each other (2), the arm (4) and the scooter (8).
SURFACE_CONTYPE, SURFACE_CONAFFINITY = 1, 2
OBJECT_CONTYPE, OBJECT_CONAFFINITY = 2, 1 | 2 | 4 | 8
