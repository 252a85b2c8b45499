"""The operator console's panel beside the 3D view: task settings, buttons, status, timings.

Task (mode, selection, strategy); Act (Detect, Previous, Next, Next candidate, Go, Cancel,
STOP, Reset stop); Drive (one `PAD_STEP` s step per click); Show cloud; the status line, the
stage timings and why the current grasp scored as it did. Every button calls the same
session method as the REST API, through `act`, which shows a refusal to the clicking client.
"""

from __future__ import annotations

from collections.abc import Callable

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


class ControlPanel:
    """The panel's GUI elements. `controls=False` shows the status only (a view-only
    console); `on_show_cloud(bool)` is called when the "Show cloud" box changes."""

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        act: Act,
        *,
        controls: bool,
        on_show_cloud: Callable[[bool], None],
    ) -> None:
        self.server, self.session, self._act = server, session, act
        self.handles: dict[str, viser.GuiInputHandle | viser.GuiButtonHandle] = {}
        gui = server.gui
        self._status = gui.add_markdown("Starting.")
        if controls:
            self._build_task()
            self._build_act()
            self._build_drive()
        show = gui.add_checkbox("Show cloud", True)
        show.on_update(lambda _: on_show_cloud(bool(show.value)))
        self.handles["cloud"] = show
        with gui.add_folder("Timings (ms)"):
            self._timings = gui.add_markdown("-")
        with gui.add_folder("Why this grasp"):
            self._why = gui.add_markdown("-")

    def _build_task(self) -> None:
        gui = self.server.gui
        with gui.add_folder("Task"):
            for label, key, choices in TASK_CHOICES:
                handle = gui.add_dropdown(label, choices, initial_value=getattr(self.session, key))
                handle.on_update(self._mode_changed(handle, key))
                self.handles[key] = handle

    def _build_act(self) -> None:
        s = self.session
        with self.server.gui.add_folder("Act"):
            for label, fn, colour in (
                ("Detect", lambda a: s.confirm(a), "blue"),
                ("Previous", lambda a: s.step_grasp(a, -1, "cluster"), None),
                ("Next", lambda a: s.step_grasp(a, +1, "cluster"), None),
                ("Next candidate", lambda a: s.step_grasp(a, +1, "candidate"), None),
                ("Go", lambda a: s.execute(a), "green"),
                ("Cancel", lambda a: s.cancel(a), "yellow"),
            ):
                self._button(label, fn, colour)
            stop = self.server.gui.add_button("STOP", color="red", icon=viser.Icon.HAND_STOP)
            stop.on_click(lambda e: self.session.stop(Actor(CONSOLE)))
            self.handles["STOP"] = stop
            self._button("Reset stop", lambda a: s.reset_stop(a), None)

    def _build_drive(self) -> None:
        s = self.session
        with self.server.gui.add_folder(f"Drive ({PAD_STEP:g} s per click)"):
            for label, v, w in (
                ("Forward", PAD_SPEED, 0.0),
                ("Back", -PAD_SPEED, 0.0),
                ("Left", 0.0, PAD_TURN),
                ("Right", 0.0, -PAD_TURN),
            ):
                self._button(label, lambda a, v=v, w=w: s.drive(a, v, w, PAD_STEP), None)

    def _button(self, label: str, fn: Callable[[Actor], object], colour: str | None) -> None:
        button = self.server.gui.add_button(label, color=colour)
        button.on_click(lambda e: self._act(e.client, fn))
        self.handles[label] = button

    def _mode_changed(self, handle: viser.GuiDropdownHandle, key: str) -> Callable:
        def changed(event: viser.GuiEvent) -> None:
            if event.client is None:
                return  # our own refresh, not a person
            ok = self._act(event.client, lambda a: self.session.set_mode(a, **{key: handle.value}))
            if not ok:
                handle.value = getattr(self.session, key)

        return changed

    def update(self, status: dict) -> None:
        """Bring the texts and the task settings up to date with the session's status."""
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
        for key in ("mode", "selection", "strategy"):
            handle = self.handles.get(key)
            if handle is not None and handle.value != status[key]:
                handle.value = status[key]
