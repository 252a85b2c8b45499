"""Commands both adapters send that need a look at the server's state first. Each is a
`Run`: a function of the `Client`, run on the connection's thread, that may return a line
to announce. Every one is a sequence of public API calls, nothing more."""

from __future__ import annotations

from typing import Literal

from laserpick.adapters.connection import Run
from laserpick.client import Client

MODE_BODIES: dict[str, tuple[str, dict[str, str]]] = {
    "mode_drop": ("pick and drop", {"mode": "pick_and_drop"}),
    "mode_place": ("pick and place", {"mode": "pick_and_place"}),
    "select_auto": ("automatic grasp", {"selection": "auto"}),
    "select_manual": ("manual grasp", {"selection": "manual"}),
}


def confirm_or_go(c: Client) -> str | None:
    """The one "confirm" button: light the second beam while aiming (the object, or where to
    place it); with grasps ready, go (pick); holding an object, drop it in the basket."""
    state = c.state()["state"]
    if state == "grasps_ready":
        c.post("/execute")
        return "go: picking"
    if state == "holding":
        c.post("/execute")
        return "go: dropping in the basket"
    c.post("/laser/confirm")  # refused with a clear 409 where confirming makes no sense
    return None


def step_grasp(direction: int, level: Literal["cluster", "candidate"] = "cluster") -> Run:
    """Previous (-1) or next (+1) grasp. Stepping means the person chooses: in automatic
    selection the server would pick its own best on go, so switch to manual first."""

    def run(c: Client) -> str | None:
        state = c.state()
        said = []
        if state["state"] == "grasps_ready" and state["selection"] == "auto":
            c.post("/mode", {"selection": "manual"})
            said.append("manual grasp selection")
        c.post("/grasps/next" if direction > 0 else "/grasps/prev", {"level": level})
        grasps = c.state().get("grasps")
        if grasps:
            said.append(str(grasps["describe"]))
        return "; ".join(said) or None

    return run


def toggle_mode(c: Client) -> str:
    """Pick and drop <-> pick and place."""
    mode = c.state()["mode"]
    new = "pick_and_place" if mode == "pick_and_drop" else "pick_and_drop"
    c.post("/mode", {"mode": new})
    return f"mode: {new.replace('_', ' ')}"
