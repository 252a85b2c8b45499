"""The operator console's panel beside the 3D view: task settings, buttons, status, timings.

Every client sees the status line, the stage timings and why the current grasp scored as it
did. A client that the view's door lets in (`view_door`) also gets, on its own panel, the
controls: Task (mode, selection, strategy); Act (Detect, Previous, Next, Next candidate, Go,
Cancel, STOP, Reset stop); Drive (one `PAD_STEP` s step per click); Show cloud. Every control
calls the same session method as the REST API, through `act`, which asks the door who the
client acts as and shows a refusal to the clicking client.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable
from typing import Any

import viser

from laserpick.server.lease import CONSOLE
from laserpick.server.session import Actor, Session

__all__ = ["PAD_SPEED", "PAD_STEP", "PAD_TURN", "ControlPanel", "status_line", "why_this_grasp"]

#: Drive pad: speed (m/s, rad/s) and length (s) of one click's step.
PAD_SPEED, PAD_TURN, PAD_STEP = 0.2, 0.4, 0.5
#: The task settings, each a dropdown of its choices.
TASK_CHOICES = (
    ("Mode", "mode", ("pick_and_drop", "pick_and_place")),
    ("Selection", "selection", ("auto", "manual")),
    ("Strategy", "strategy", ("gpd", "overhead", "jeeves")),
)

#: Runs a session command as the console; True if the session took it.
Act = Callable[[viser.ClientHandle | None, Callable[[Actor], object]], bool]


def status_line(status: dict) -> str:
    """The panel's status: state and message, the e-stop, why the scooter stopped itself,
    and who controls the robot when it is not this station."""
    lease = status["lease"]
    control = (
        ""
        if not lease["held"] or lease["source"] == CONSOLE
        else f" · controlled by {lease['holder']}"
    )
    estop = " · **E-STOP LATCHED**" if status["estopped"] else ""
    stop = f" · **{status['drive_stop']}**" if status["drive_stop"] else ""
    return f"**{status['state'].replace('_', ' ')}** · {status['message']}{estop}{stop}{control}"


def why_this_grasp(status: dict) -> str:
    """The current grasp's score as the product of its factors (004 eq. 3-7), or "-"."""
    current = status["current"]
    if current is None or not current["factors"]:
        return "-"
    f = current["factors"]
    return (
        f"score **{current['score']:.3f}** = Cw {f['Cw']:.2f} × Cj {f['Cj']:.2f} × "
        f"Ca {f['Ca']:.2f} × Cs {f['Cs']:.2f} × Cp {f['Cp']:.2f}  \n"
        "Cw width in the stroke · Cj short joint move · Ca top, then front · "
        "Cs near the target's points · Cp near the mark (004 eq. 3-7)"
    )


def _drive(session: Session, v: float, w: float, actor: Actor) -> None:
    """One drive pad step: `v` m/s forward, `w` rad/s left, for `PAD_STEP` s."""
    session.drive(actor, v, w, PAD_STEP)


class ControlPanel:
    """The panel: texts every client sees (the status, the stage timings, why this grasp),
    and the controls, added to one client's own panel (`add_controls`) when the view's door
    lets it in; a watcher gets a note saying why it has none (`add_watch_note`).

    `act(client, fn)` runs a command as the view's door allows `client`; `stop(client)`
    latches the e-stop for a client that has the controls; `show_cloud(client, bool)` is
    called when a client's "Show cloud" box changes (the cloud is one for every client).
    """

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        act: Act,
        *,
        stop: Callable[[viser.ClientHandle | None], None],
        show_cloud: Callable[[viser.ClientHandle | None, bool], None],
    ) -> None:
        self.server, self.session, self._act = server, session, act
        self._stop, self._show_cloud = stop, show_cloud
        self._lock = threading.Lock()
        #: Each client's controls by label (and "mode", "selection", "strategy", "cloud").
        self.controls: dict[int, dict[str, viser.GuiInputHandle | viser.GuiButtonHandle]] = {}
        gui = server.gui
        self._status = gui.add_markdown("Starting.")
        with gui.add_folder("Timings (ms)"):
            self._timings = gui.add_markdown("-")
        with gui.add_folder("Why this grasp"):
            self._why = gui.add_markdown("-")

    def _order(self, n: int) -> float:
        """Orders right after the status line, before the next shared element."""
        return self._status.order + 0.01 * n

    def add_controls(self, client: viser.ClientHandle) -> None:
        """Task, Act, Drive and Show cloud on `client`'s own panel."""
        handles: dict[str, viser.GuiInputHandle | viser.GuiButtonHandle] = {}
        gui = client.gui
        self._build_task(gui, handles)
        self._build_act(gui, handles)
        self._build_drive(gui, handles)
        show = gui.add_checkbox("Show cloud", True, order=self._order(4))
        show.on_update(lambda e: self._show_cloud(e.client, bool(show.value)))
        handles["cloud"] = show
        with self._lock:
            self.controls[client.client_id] = handles

    def add_watch_note(self, client: viser.ClientHandle, why: str) -> None:
        """A note on `client`'s panel: it watches, and `why`."""
        client.gui.add_markdown(f"**Watching only.** {why}", order=self._order(1))

    def forget(self, client: viser.ClientHandle) -> None:
        """`client` left: its controls went with it."""
        with self._lock:
            self.controls.pop(client.client_id, None)

    def _build_task(self, gui: Any, handles: dict) -> None:
        with gui.add_folder("Task", order=self._order(1)):
            for label, key, choices in TASK_CHOICES:
                handle = gui.add_dropdown(label, choices, initial_value=getattr(self.session, key))
                handle.on_update(self._mode_changed(handle, key))
                handles[key] = handle

    def _build_act(self, gui: Any, handles: dict) -> None:
        s = self.session
        with gui.add_folder("Act", order=self._order(2)):
            for label, fn, colour in (
                ("Detect", lambda a: s.confirm(a), "blue"),
                ("Previous", lambda a: s.step_grasp(a, -1, "cluster"), None),
                ("Next", lambda a: s.step_grasp(a, +1, "cluster"), None),
                ("Next candidate", lambda a: s.step_grasp(a, +1, "candidate"), None),
                ("Go", lambda a: s.execute(a), "green"),
                ("Cancel", lambda a: s.cancel(a), "yellow"),
            ):
                handles[label] = self._button(gui, label, fn, colour)
            stop = gui.add_button("STOP", color="red", icon=viser.Icon.HAND_STOP)
            stop.on_click(lambda e: self._stop(e.client))
            handles["STOP"] = stop
            handles["Reset stop"] = self._button(gui, "Reset stop", lambda a: s.reset_stop(a), None)

    def _build_drive(self, gui: Any, handles: dict) -> None:
        s = self.session
        with gui.add_folder(f"Drive ({PAD_STEP:g} s per click)", order=self._order(3)):
            for label, v, w in (
                ("Forward", PAD_SPEED, 0.0),
                ("Back", -PAD_SPEED, 0.0),
                ("Left", 0.0, PAD_TURN),
                ("Right", 0.0, -PAD_TURN),
            ):
                drive = functools.partial(_drive, s, v, w)
                handles[label] = self._button(gui, label, drive, None)

    def _button(
        self, gui: Any, label: str, fn: Callable[[Actor], object], colour: str | None
    ) -> viser.GuiButtonHandle:
        button = gui.add_button(label, color=colour)
        button.on_click(lambda e: self._act(e.client, fn))
        return button

    def _mode_changed(self, handle: viser.GuiDropdownHandle, key: str) -> Callable:
        def changed(event: viser.GuiEvent) -> None:
            if event.client is None:
                return  # our own refresh, not a person
            ok = self._act(event.client, lambda a: self.session.set_mode(a, **{key: handle.value}))
            if not ok:
                handle.value = getattr(self.session, key)

        return changed

    def update(self, status: dict) -> None:
        """Bring the texts and every client's task settings up to date with the session's
        status."""
        text = status_line(status)
        if self._status.content != text:
            self._status.content = text
        timings = status["timings"]
        table = " · ".join(f"{k} {1000 * v:.0f}" for k, v in timings.items()) or "-"
        if self._timings.content != table:
            self._timings.content = table
        why = why_this_grasp(status)
        if self._why.content != why:
            self._why.content = why
        with self._lock:
            panels = list(self.controls.values())
        for handles in panels:
            for key in ("mode", "selection", "strategy"):
                handle = handles[key]
                if handle.value != status[key]:
                    handle.value = status[key]
