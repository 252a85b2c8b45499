"""The API's routes, one module a resource, sharing `dependencies` (the session, the app's
settings, the events hub and the lease check) and `replies` (how a command is answered).

page (`/`, `/view`), read (health, state, projector image, cloud, journal), control (the
lease), laser, grasps, task (execute, cancel, mode), motion (drive, e-stop), events (the
websocket); and simulation (`/sim/objects`, `POST /scene`), for a simulated robot only, which
imports the simulator and so is not imported here.
"""

from laserpick.server.routers import (
    control,
    dependencies,
    events,
    grasps,
    laser,
    motion,
    page,
    read,
    replies,
    task,
)

__all__ = [
    "control",
    "dependencies",
    "events",
    "grasps",
    "laser",
    "motion",
    "page",
    "read",
    "replies",
    "task",
]
