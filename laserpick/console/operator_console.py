"""The operator console in the 3D view: the session drawn over the scene, and a panel to drive it.

An in-process client of the `Session` (rule 2: it calls the same methods as the REST API).
Over the `SceneViewer`'s robot and world it draws the fused cloud and what the projector
lights on it (`cloud_overlay`), the laser's beams and their dots (`laser_overlay`), the
grasp candidates, the current one's path and the place mark (`grasp_overlay`); beside it,
the panel (`control_panel`).

A click in the 3D view aims the laser where the click's ray meets the cloud; a second click
near the same spot, or the Detect button, confirms the mark.

Control goes through the view's door (`view_door`), the API's door: each browser client is
the station, the operator or a watcher. The station (this computer's own screen, no
password) and the page are one operator station (input source "console"): it acts with the
lease the page holds, or takes the lease itself when it is free, heartbeats while a station
client shows it, and lets the lease lapse (halting motion) when the last one disconnects.
The operator acts with the lease token the operator page handed it, checked at every
command. A watcher sees the scene and the status, and no controls. While another device (a
switch adapter, a script) holds control, the view says who and changes nothing.

Frames: the session works in `base`; the scene is drawn in `world` (z up), metres.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import numpy as np
import viser

from laserpick.console.cloud_overlay import CloudOverlay
from laserpick.console.control_panel import ControlPanel
from laserpick.console.grasp_overlay import GraspOverlay, PlaceOverlay
from laserpick.console.laser_overlay import LaserOverlay
from laserpick.console.overlay import OverlayNodes, to_world
from laserpick.console.view_door import WATCHING, ViewDoor
from laserpick.pipeline.cloud import ray_distance
from laserpick.server.lease import CONSOLE, LeaseHeld
from laserpick.server.session import Actor, CamerasUnavailable, Conflict, Session, TaskState

__all__ = ["CONFIRM_RADIUS", "OperatorConsole", "to_world"]

log = logging.getLogger(__name__)

#: A second click within this distance (m) of the aimed point confirms the mark.
CONFIRM_RADIUS = 0.03
#: Overlay refresh rate (Hz); the robot and the world move at the SceneViewer's own rate.
OVERLAY_HZ = 20.0
HEARTBEAT_S = 0.15
#: States where a click on the aimed point confirms it.
CONFIRMABLE = (TaskState.AIMING, TaskState.AWAITING_PLACE)
#: Session events after which the overlays are redrawn at once.
REDRAW_EVENTS = ("state", "grasp", "scene", "failure", "estop", "job", "foreseen")


class OperatorConsole:
    """The session in the 3D view, with its control panel for the clients its door lets in."""

    def __init__(self, session: Session, server: viser.ViserServer):
        self.session, self.server = session, server
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._token: str | None = None  #: the lease this view took itself, if any
        self._aimed_at: np.ndarray | None = None  #: where the last click aimed (m, base)
        self._confirmed_at: float | None = None  #: when a click last confirmed a mark
        self._wake = threading.Event()
        self.door = ViewDoor(
            server, session.lease, password_set=session.settings.operator_password is not None
        )
        self.nodes = OverlayNodes()
        self.cloud = CloudOverlay(server, self.nodes)
        self.laser = LaserOverlay(server, self.nodes)
        self.grasps = GraspOverlay(server, self.nodes)
        self.place = PlaceOverlay(server, self.nodes)
        self.panel = ControlPanel(
            server, session, self.act, stop=self.stop_robot, show_cloud=self.show_cloud
        )
        server.on_client_connect(self._connected)
        server.on_client_disconnect(self._disconnected)
        server.scene.on_click()(self.on_click)
        session.on_event(self._on_event)

    # --- lifecycle -------------------------------------------------------------------------

    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(
                target=self._loop, name="laserpick-console", daemon=True
            )
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        if self._token is not None:
            self.session.lease.release(self._token)
            self._token = None

    def _connected(self, client: viser.ClientHandle) -> None:
        if self.door.arrive(client).controls:
            self.panel.add_controls(client)
        else:
            self.panel.add_watch_note(client, WATCHING)

    def _disconnected(self, client: viser.ClientHandle) -> None:
        self.panel.forget(client)
        self.door.leave(client)
        if not self.door.stations() and self._token is not None:
            # No station client sees the view any more: motion it commanded must stop now.
            self.session.lease.connection_lost(self._token)
            self._token = None

    # --- acting ----------------------------------------------------------------------------

    def actor(self, client: viser.ClientHandle | None = None) -> Actor:
        """Who a command from `client` acts as (None: an in-process caller, the station).
        The door's answer: the lease token the client brought, or, for the station, the
        station's lease (the page's, or its own, taken when free). Conflict, saying why,
        for a watcher, or when another device holds control."""
        lease = self.session.lease
        actor = self.door.actor(client, self.session.state)
        if actor is not None:
            return actor
        if self._token is not None and lease.holds(self._token):
            return Actor(CONSOLE, self._token)
        token = lease.token_of(CONSOLE)
        if token is not None:
            return Actor(CONSOLE, token)
        try:
            self._token = lease.acquire("3D view", CONSOLE)
        except LeaseHeld as exc:
            raise Conflict(str(exc), self.session.state) from None
        return Actor(CONSOLE, self._token)

    def act(self, client: viser.ClientHandle | None, fn: Callable[[Actor], object]) -> bool:
        """Run a session command as `client` acts (`actor`); a refusal is shown to it."""
        try:
            fn(self.actor(client))
            return True
        except (Conflict, ValueError, IndexError, CamerasUnavailable) as exc:
            self._refuse(client, exc)
            return False

    @staticmethod
    def _refuse(client: viser.ClientHandle | None, exc: Exception) -> None:
        if client is not None:
            client.add_notification("Not now", str(exc), color="yellow", auto_close_seconds=4.0)

    def stop_robot(self, client: viser.ClientHandle | None) -> None:
        """STOP from `client`: like the API's, it needs no lease, only the controls (a
        watcher has none)."""
        if self.door.visitor(client).controls:
            self.session.stop(Actor(CONSOLE))

    def show_cloud(self, client: viser.ClientHandle | None, show: bool) -> None:
        """Show or hide the cloud (for every client), from a client that has the controls."""
        if self.door.visitor(client).controls:
            self.cloud.set_visible(show)

    def on_click(self, event: viser.SceneClickEvent) -> None:
        """Aim where the click's ray meets the cloud; a second click on the aimed point (its
        ray passes within CONFIRM_RADIUS of it) confirms the mark there (or the place mark),
        as the laser points: the session has worked that mark out since the first click.
        The confirm does not look for the ray's hit again: a capture refreshed between the
        two clicks would put it elsewhere, and the dot is where the user clicked. A click
        the door refuses changes nothing, not even which point counts as aimed."""
        session = self.session
        try:
            self.door.actor(event.client, session.state)
        except Conflict as exc:
            self._refuse(event.client, exc)
            return
        origin = np.asarray(event.ray_origin, dtype=float)
        direction = np.asarray(event.ray_direction, dtype=float)
        before = self._aimed_at if session.state in CONFIRMABLE else None
        if before is not None and (
            ray_distance(to_world(before, session.robot.base_pose()), origin, direction)
            < CONFIRM_RADIUS
        ):
            self._aimed_at = None
            self._confirmed_at = time.monotonic()
            if self.act(event.client, lambda a: session.confirm(a, point=before)):
                # The confirm lit the target it foresaw: show it from here, not after the
                # refresh loop's next turn, which the starting job slows (GIL).
                with self._lock:
                    self._draw_cloud()
            return
        hit: list[np.ndarray] = []
        if self.act(
            event.client, lambda a: hit.append(session.ray_point(origin, direction, "world"))
        ) and self.act(event.client, lambda a: session.aim_at(a, hit[0], "base", foresee=True)):
            self._aimed_at = hit[0]

    @property
    def aimed_at(self) -> np.ndarray | None:
        """Where the last click aimed the laser (m, `base`), until a click confirms it."""
        return self._aimed_at

    # --- drawing ---------------------------------------------------------------------------

    def _on_event(self, event: dict) -> None:
        if event.get("name") in REDRAW_EVENTS:
            self._wake.set()

    def _loop(self) -> None:
        period = 1.0 / OVERLAY_HZ
        next_beat = 0.0
        while not self._stop.is_set():
            try:
                self.refresh()
                now = time.monotonic()
                if self._token is not None and self.door.stations() and now >= next_beat:
                    self.session.lease.heartbeat(self._token)
                    next_beat = now + HEARTBEAT_S
            except Exception:  # the view must never take the process down
                log.exception("console refresh failed")
            self._wake.wait(period)
            self._wake.clear()

    def refresh(self) -> None:
        """Bring every overlay and the panel up to date with the session (cheap when nothing
        changed)."""
        with self._lock:
            status = self.session.status()
            self._draw_cloud()
            self.laser.draw(self.session)
            self.grasps.draw(self.session)
            self.place.draw(self.session, status)
            self.panel.update(status)

    def _draw_cloud(self) -> None:
        self.cloud.draw(self.session, self._announce_highlight)

    def _announce_highlight(self, points: int) -> None:
        """Say that a highlight of `points` points is shown, and how long (s) after a click
        here confirmed the mark: the server's share of the click-to-highlight time
        (bench/click_latency.py)."""
        since = None
        if self._confirmed_at is not None:
            since = round(time.monotonic() - self._confirmed_at, 4)
            self._confirmed_at = None
        self.session.announce("highlight", points=points, since_click=since)
