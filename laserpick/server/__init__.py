"""The server room: the operator session (`session`, the task state machine every input
drives), its web API (`app` with one router a resource in `routers`, the bodies in `schemas`
and `wire`, refusals in `errors`, the websocket fan-out in `events`), the control lease
(`lease`), the session journal (`journal`) and how the process's heap is kept (`heap`).

It works on any `laserpick.robot.interface.Robot` and imports neither the simulator nor the
bench; `routers.simulation` serves what a simulator offers when the CLI hands one in.
Submodules are imported where used, so that reading the journal needs no web framework.
"""

__all__ = [
    "app",
    "errors",
    "events",
    "heap",
    "journal",
    "lease",
    "routers",
    "schemas",
    "session",
    "wire",
]
