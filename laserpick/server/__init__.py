"""The server room: the operator session (`session`, the task state machine every input
drives), its web API (`app` with one router a resource in `routers`, the bodies in `schemas`
and `wire`, refusals in `errors`, the websocket fan-out in `events`), the control lease
(`lease`) and the session journal (`journal`).

It works on any `laserpick.robot.interface.Robot`; only `routers.simulation`, which the CLI
includes for a simulated robot, imports the simulator. Nothing here imports the bench.
Submodules are imported where used, so that reading the journal needs no web framework.
"""

__all__ = ["app", "errors", "events", "journal", "lease", "routers", "schemas", "session", "wire"]
