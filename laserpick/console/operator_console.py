"""The operator console in the 3D view: the session drawn over the scene, and a panel to drive it.

An in-process client of the `Session` (rule 2: it calls the same methods as the REST API).
Over the `SceneViewer`'s bodies it draws:

- the fused cloud (thinned, with a toggle), dark, except where the projector lights it: the
  projector image is projected back onto the cloud, so the lit target glows as in the room;
- the laser beams and their spots;
- the grasp candidates as gripper outlines: other clusters dim, the current cluster bright,
  the current candidate thick; each coloured by its score (red low, green high);
- the current candidate's TCP path (pre-grasp, grasp, lift) before it is executed;
- the place mark.

A click in the 3D view aims the laser where the click's ray meets the cloud; a second click
near the same spot, or the Detect button, confirms the mark. The panel has the task settings,
Detect, Previous, Next, Go, Cancel, STOP, a drive pad (one 0.5 s step per click), the status,
the stage timings and the current grasp's factors.

Control: the page and this view are one operator station (input source "console"). The view
acts with the lease the page holds, or takes the lease itself when it is free, heartbeats
while a browser shows it, and lets the lease lapse (halting motion) when the last one
disconnects. While another device (a switch adapter, a script) holds control, the view says
who and changes nothing.

Frames: the session works in `base`; the scene is drawn in `world` (z up), metres.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import viser

from laserpick.description import dims
from laserpick.pipeline.cloud import ray_distance, voxel_first
from laserpick.pipeline.reach import pregrasp_pose
from laserpick.server.lease import CONSOLE, LeaseHeld
from laserpick.server.session import Actor, Conflict, Session, TaskState
from laserpick.transforms import planar_pose
from laserpick.types import FusedCloud, Grasp, Projector

log = logging.getLogger(__name__)

_ROOT = "/laserpick/console"
#: Cloud points drawn: one per voxel of this edge (m).
CLOUD_VOXEL = 0.012
CLOUD_POINT_SIZE = 0.008
LIT_POINT_SIZE = 0.012
LIT_VOXEL = 0.005
DARK = np.array([70, 74, 82], np.uint8)  #: unlit cloud points
LIT = np.array([255, 236, 120], np.uint8)  #: points the projector lights
LASER_RED = (235, 20, 20)
#: A second click within this distance (m) of the aimed point confirms the mark.
CONFIRM_RADIUS = 0.03
#: Overlay refresh rate (Hz); the bodies move at the SceneViewer's own rate.
OVERLAY_HZ = 20.0
HEARTBEAT_S = 0.15
#: States where a click on the aimed point confirms it.
CONFIRMABLE = (TaskState.AIMING, TaskState.AWAITING_PLACE)
#: Drive pad: speed (m/s, rad/s) and length (s) of one click's step.
PAD_SPEED, PAD_TURN, PAD_STEP = 0.2, 0.4, 0.5


def score_colour(score: float, bright: bool) -> np.ndarray:
    """RGB for a grasp score in [0, 1]: red (low) to green (high); dimmed unless `bright`."""
    s = float(np.clip(score, 0.0, 1.0))
    rgb = np.array([230 * (1 - s) + 30 * s, 60 * (1 - s) + 200 * s, 50.0])
    return (rgb if bright else 0.35 * rgb + 0.65 * np.array([90, 90, 95])).astype(np.uint8)


def gripper_outline(pose: np.ndarray, width: float) -> np.ndarray:
    """Line segments (5, 2, 3) of a parallel gripper at a grasp pose (4x4, TCP frame: x hand
    axis, y closing axis, z approach), fingers opened to `width` + 1 cm (m)."""
    half = min(width + 0.01, dims.GRIPPER_STROKE) / 2
    tip, root = 0.0, -dims.GRIPPER_FINGER_LENGTH  # along the approach axis, from the TCP
    palm = root - 0.04
    local = np.array(
        [
            [[0, -half, root], [0, half, root]],  # the palm bar
            [[0, -half, root], [0, -half, tip]],  # one finger
            [[0, half, root], [0, half, tip]],  # the other
            [[0, 0, root], [0, 0, palm]],  # the wrist stem
            [[0, -half, tip], [0, -half + 0.004, tip]],  # a tick at one tip: the closing side
        ]
    )
    return local @ pose[:3, :3].T + pose[:3, 3]


def to_world(points_base: np.ndarray, base_pose: np.ndarray) -> np.ndarray:
    """Points (..., 3) from `base` at the scooter pose (x, y, yaw) into `world`."""
    T = planar_pose(*base_pose)
    return points_base @ T[:3, :3].T + T[:3, 3]


@dataclass
class _Drawn:
    """What was last drawn, to redraw only what changed."""

    cloud_key: tuple[int, int] | None = None
    lit_key: tuple[int, int] | None = None
    #: The foreseen highlight sent ahead, hidden ("lit-ahead"), and its number of points.
    ahead_key: tuple[int, int] | None = None
    ahead_points: int = 0
    sent_ahead: int = 0
    grasp_key: tuple[int, int, int] | None = None
    place_key: tuple[float, ...] | None = None
    laser_key: tuple[float, ...] | None = None
    nodes: dict[str, viser.SceneNodeHandle] = field(default_factory=dict)
    #: The projector pixel of each point of the cloud `pixels_of` (`projector_pixels`); the
    #: cloud itself is kept, not its id, which a new cloud may reuse once it is freed.
    pixels: np.ndarray | None = None
    pixels_of: FusedCloud | None = None


class OperatorConsole:
    """The session in the 3D view, with its control panel.

    controls=False draws the session but adds no panel and ignores clicks (a view-only
    console, for a port other hosts can reach).
    """

    def __init__(self, session: Session, server: viser.ViserServer, *, controls: bool = True):
        self.session, self.server, self.controls = session, server, controls
        self._drawn = _Drawn()
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._token: str | None = None  #: the lease this view took itself, if any
        self._aimed_at: np.ndarray | None = None  #: where the last click aimed (m, base)
        self._confirmed_at: float | None = None  #: when a click last confirmed a mark
        self._wake = threading.Event()
        self._clients: set[int] = set()
        self._show_cloud = True
        self._gui: dict[str, viser.GuiInputHandle | viser.GuiButtonHandle] = {}
        self._status: viser.GuiMarkdownHandle | None = None
        self._timings: viser.GuiMarkdownHandle | None = None
        self._why: viser.GuiMarkdownHandle | None = None
        server.on_client_connect(self._connected)
        server.on_client_disconnect(self._disconnected)
        self._build_panel()
        if controls:
            server.scene.on_click()(self._clicked)
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
        self._clients.add(client.client_id)

    def _disconnected(self, client: viser.ClientHandle) -> None:
        self._clients.discard(client.client_id)
        if not self._clients and self._token is not None:
            # Nobody sees the view any more: motion it commanded must stop now.
            self.session.lease.connection_lost(self._token)
            self._token = None

    # --- acting ----------------------------------------------------------------------------

    def actor(self) -> Actor:
        """Who this view acts as: the station's lease (the page's, or its own, taken when
        free). Conflict when another device holds control."""
        lease = self.session.lease
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
        """Run a session command as this view; a refusal is shown to the clicking client."""
        try:
            fn(self.actor())
            return True
        except (Conflict, ValueError, IndexError) as exc:
            if client is not None:
                client.add_notification("Not now", str(exc), color="yellow", auto_close_seconds=4.0)
            return False

    def _clicked(self, event: viser.SceneClickEvent) -> None:
        """Aim where the click's ray meets the cloud; a second click on the aimed point (its
        ray passes within CONFIRM_RADIUS of it) confirms the mark there (or the place mark),
        as the laser points: the session has worked that mark out since the first click.
        The confirm does not look for the ray's hit again: a capture refreshed between the
        two clicks would put it elsewhere, and the dot is where the user clicked."""
        session = self.session
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

    # --- the panel -------------------------------------------------------------------------

    def _build_panel(self) -> None:
        gui = self.server.gui
        self._status = gui.add_markdown("Starting.")
        if self.controls:
            s = self.session
            with gui.add_folder("Task"):
                mode = gui.add_dropdown(
                    "Mode", ("pick_and_drop", "pick_and_place"), initial_value=s.mode
                )
                selection = gui.add_dropdown(
                    "Selection", ("auto", "manual"), initial_value=s.selection
                )
                strategy = gui.add_dropdown(
                    "Strategy", ("gpd", "overhead", "jeeves"), initial_value=s.strategy
                )
                for handle, key in (
                    (mode, "mode"),
                    (selection, "selection"),
                    (strategy, "strategy"),
                ):
                    handle.on_update(self._mode_changed(handle, key))
                    self._gui[key] = handle
            with gui.add_folder("Act"):
                for label, fn, colour in (
                    ("Detect", lambda a: s.confirm(a), "blue"),
                    ("Previous", lambda a: s.step_grasp(a, -1, "cluster"), None),
                    ("Next", lambda a: s.step_grasp(a, +1, "cluster"), None),
                    ("Next candidate", lambda a: s.step_grasp(a, +1, "candidate"), None),
                    ("Go", lambda a: s.execute(a), "green"),
                    ("Cancel", lambda a: s.cancel(a), "yellow"),
                ):
                    self._button(label, fn, colour)
                stop = gui.add_button("STOP", color="red", icon=viser.Icon.HAND_STOP)
                stop.on_click(lambda e: self.session.stop(Actor(CONSOLE)))
                self._gui["STOP"] = stop
                self._button("Reset stop", lambda a: s.reset_stop(a), None)
            with gui.add_folder("Drive (0.5 s per click)"):
                for label, v, w in (
                    ("Forward", PAD_SPEED, 0.0),
                    ("Back", -PAD_SPEED, 0.0),
                    ("Left", 0.0, PAD_TURN),
                    ("Right", 0.0, -PAD_TURN),
                ):
                    self._button(label, lambda a, v=v, w=w: s.drive(a, v, w, PAD_STEP), None)
        show = gui.add_checkbox("Show cloud", True)

        @show.on_update
        def _(_: viser.GuiEvent) -> None:
            self._show_cloud = bool(show.value)
            node = self._drawn.nodes.get("cloud")
            if node is not None:
                node.visible = self._show_cloud

        self._gui["cloud"] = show
        with gui.add_folder("Timings (ms)"):
            self._timings = gui.add_markdown("-")
        with gui.add_folder("Why this grasp"):
            self._why = gui.add_markdown("-")

    def _button(self, label: str, fn: Callable[[Actor], object], colour: str | None) -> None:
        button = self.server.gui.add_button(label, color=colour)
        button.on_click(lambda e: self.act(e.client, fn))
        self._gui[label] = button

    def _mode_changed(self, handle: viser.GuiDropdownHandle, key: str) -> Callable:
        def changed(event: viser.GuiEvent) -> None:
            if event.client is None:
                return  # our own refresh, not a person
            ok = self.act(event.client, lambda a: self.session.set_mode(a, **{key: handle.value}))
            if not ok:
                handle.value = getattr(self.session, key)

        return changed

    # --- drawing ---------------------------------------------------------------------------

    def _on_event(self, event: dict) -> None:
        names = ("state", "grasp", "scene", "failure", "estop", "job", "foreseen")
        if event.get("name") in names:
            self._wake.set()

    def _loop(self) -> None:
        period = 1.0 / OVERLAY_HZ
        next_beat = 0.0
        while not self._stop.is_set():
            try:
                self.refresh()
                now = time.monotonic()
                if self._token is not None and self._clients and now >= next_beat:
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
            self._draw_laser()
            self._draw_grasps()
            self._draw_place(status)
            self._update_panel(status)

    def _node(self, key: str, handle: viser.SceneNodeHandle | None) -> None:
        # Adding a node under a name in use replaces the old one, so only a node that is not
        # replaced by one of its name needs removing.
        old = self._drawn.nodes.pop(key, None)
        if handle is not None:
            self._drawn.nodes[key] = handle
        if old is not None and (handle is None or old.name != handle.name):
            old.remove()

    def _draw_cloud(self) -> None:
        """The lit points first (the highlight is what the user waits for), then the dark
        cloud under them, each only when it changed. A highlight the session foresaw (a
        clicked mark worked out before its confirm) is sent ahead, hidden: the confirm then
        shows it, a few bytes instead of its points."""
        latest = self.session.latest_cloud
        image = self.session.projection
        lit_key = None if latest is None else (id(latest[0]), id(image))
        cloud_key = None if latest is None else (id(latest[0]), 0)
        if latest is None:
            self._node("cloud", None)
            self._node("lit", None)
            self._node("lit-ahead", None)
            self._drawn.cloud_key = self._drawn.lit_key = self._drawn.ahead_key = None
            return
        cloud, pose = latest
        if self._drawn.pixels_of is not cloud:
            # Once per cloud, as it arrives (a click aims in it): a highlight in it is then
            # a lookup, not a projection of its 200k points just when the user waits.
            self._drawn.pixels = projector_pixels(self.session.projector, cloud.points)
            self._drawn.pixels_of = cloud
        if lit_key != self._drawn.lit_key:
            self._drawn.lit_key = lit_key
            if image is not None and lit_key == self._drawn.ahead_key:
                ahead = self._drawn.nodes.pop("lit-ahead")
                ahead.visible = True
                self._node("lit", ahead)
                self._drawn.ahead_key = None
                sent = self._drawn.ahead_points
            else:
                handle, sent = self._lit_cloud("lit", cloud, image, pose, visible=True)
                self._node("lit", handle)
            if sent:
                # Since a click here confirmed the mark (s): the server's share of the
                # click-to-highlight time (bench/click_latency.py).
                since = None
                if self._confirmed_at is not None:
                    since = round(time.monotonic() - self._confirmed_at, 4)
                    self._confirmed_at = None
                self.session.announce("highlight", points=sent, since_click=since)
        foreseen = self.session.foreseen
        ahead_key = None
        if foreseen is not None and foreseen[0] is cloud and foreseen[1] is not image:
            ahead_key = (id(cloud), id(foreseen[1]))
        if ahead_key != self._drawn.ahead_key:
            self._drawn.ahead_key = ahead_key
            self._drawn.sent_ahead += 1  # a path of its own: shown, it is the "lit" node
            handle, self._drawn.ahead_points = (
                self._lit_cloud(
                    f"lit-{self._drawn.sent_ahead}", cloud, foreseen[1], pose, visible=False
                )
                if foreseen is not None and ahead_key is not None
                else (None, 0)
            )
            self._node("lit-ahead", handle)
        if cloud_key != self._drawn.cloud_key:
            self._drawn.cloud_key = cloud_key
            points = cloud.points[voxel_first(cloud.points, CLOUD_VOXEL)]
            self._node(
                "cloud",
                self.server.scene.add_point_cloud(
                    f"{_ROOT}/cloud",
                    points=to_world(points, pose).astype(np.float32),
                    colors=DARK,
                    point_size=CLOUD_POINT_SIZE,
                    point_shape="rounded",
                    visible=self._show_cloud,
                ),
            )

    def _lit_cloud(
        self,
        name: str,
        cloud: FusedCloud,
        image: np.ndarray | None,
        pose: np.ndarray,
        *,
        visible: bool,
    ) -> tuple[viser.SceneNodeHandle | None, int]:
        """The points of `cloud` that the projector `image` lights, as a bright point cloud
        node `name` (None when it lights none), and how many points it has."""
        assert self._drawn.pixels is not None and self._drawn.pixels_of is cloud
        lit = cloud.points[lit_by(image, self._drawn.pixels)] if image is not None else None
        if lit is None or not len(lit):
            return None, 0
        points = to_world(lit[voxel_first(lit, LIT_VOXEL)], pose).astype(np.float32)
        # Larger and bright, and drawn whether or not the cloud is: the projector's light
        # on the object shows either way.
        handle = self.server.scene.add_point_cloud(
            f"{_ROOT}/{name}",
            points=points,
            colors=LIT,
            point_size=LIT_POINT_SIZE,
            point_shape="circle",
            point_shading="flat",
            visible=visible,
        )
        return handle, len(points)

    def _draw_laser(self) -> None:
        robot = self.session.robot
        beams = robot.laser.beams_base()
        if not beams:
            self._node("laser", None)
            self._node("spots", None)
            self._drawn.laser_key = None
            return
        pose = robot.base_pose()
        hits = [np.asarray(h) for h in robot.laser_hits()]  # world; simulator truth, drawn
        segments, spots = [], []
        for origin, direction in beams:
            start = to_world(origin, pose)
            along = to_world(direction, np.array([0.0, 0.0, pose[2]]))
            on_beam = [h for h in hits if np.linalg.norm(np.cross(h - start, along)) < 0.01]
            end = on_beam[0] if on_beam else start + 3.0 * along
            segments.append([start, end])
            spots += on_beam[:1]
        # Redraw only when the beam moved by a millimetre: each redraw makes the browser draw
        # a frame, and a click waits behind it (bench/click_latency.py).
        key = tuple(np.round(np.concatenate([np.ravel(segments), np.ravel(spots)]), 3))
        if key == self._drawn.laser_key:
            return
        self._drawn.laser_key = key
        self._node(
            "laser",
            self.server.scene.add_line_segments(
                f"{_ROOT}/laser",
                np.array(segments),
                LASER_RED,
                thickness=2.0,
                thickness_units="screen",
            ),
        )
        if spots:
            self._node(
                "spots",
                self.server.scene.add_point_cloud(
                    f"{_ROOT}/spots",
                    points=np.array(spots, np.float32),
                    colors=(255, 40, 40),
                    point_size=0.02,
                    point_shape="circle",
                ),
            )
        else:
            self._node("spots", None)

    def _draw_grasps(self) -> None:
        session = self.session
        cursor = session.task.cursor
        key = None if cursor is None else (id(cursor.clusters), cursor.cluster, cursor.candidate)
        if key == self._drawn.grasp_key:
            return
        self._drawn.grasp_key = key
        for name in ("grasps", "current", "path"):
            self._node(name, None)
        latest = session.latest_cloud
        if cursor is None or latest is None:
            return
        pose = latest[1]
        grasps = cursor.clusters.grasps
        current = cursor.current
        members = set(cursor.clusters.clusters[cursor.cluster])
        segs, cols = [], []
        for i, g in enumerate(grasps):
            if g is current:
                continue
            lines = gripper_outline(g.pose, g.width)
            segs.append(lines)
            cols.append(np.broadcast_to(score_colour(g.score, i in members), lines.shape))
        if segs:
            self._node(
                "grasps",
                self.server.scene.add_line_segments(
                    f"{_ROOT}/grasps",
                    to_world(np.concatenate(segs), pose),
                    np.concatenate(cols),
                    thickness=2.0,
                    thickness_units="screen",
                ),
            )
        self._node(
            "current",
            self.server.scene.add_line_segments(
                f"{_ROOT}/current",
                to_world(gripper_outline(current.pose, current.width), pose),
                score_colour(current.score, True),
                thickness=6.0,
                thickness_units="screen",
            ),
        )
        self._node(
            "path",
            self.server.scene.add_line_segments(
                f"{_ROOT}/path",
                to_world(tcp_path(current), pose),
                (80, 170, 255),
                thickness=3.0,
                thickness_units="screen",
            ),
        )

    def _draw_place(self, status: dict) -> None:
        mark = status.get("place_mark")
        key = None if mark is None else tuple(mark)
        if key == self._drawn.place_key:
            return
        self._drawn.place_key = key
        latest = self.session.latest_cloud
        if mark is None or latest is None:
            self._node("place", None)
            return
        ring = (
            np.array(mark)
            + 0.04
            * np.c_[
                np.cos(np.linspace(0, 2 * np.pi, 33)),
                np.sin(np.linspace(0, 2 * np.pi, 33)),
                np.zeros(33),
            ]
        )
        segments = np.stack([ring[:-1], ring[1:]], axis=1)
        self._node(
            "place",
            self.server.scene.add_line_segments(
                f"{_ROOT}/place",
                to_world(segments, latest[1]),
                (60, 200, 255),
                thickness=4.0,
                thickness_units="screen",
            ),
        )

    def _update_panel(self, status: dict) -> None:
        lease = status["lease"]
        control = (
            ""
            if not lease["held"] or lease["source"] == CONSOLE
            else f" · controlled by {lease['holder']}"
        )
        estop = " · **E-STOP LATCHED**" if status["estopped"] else ""
        stop = f" · **{status['drive_stop']}**" if status["drive_stop"] else ""
        text = (
            f"**{status['state'].replace('_', ' ')}** · {status['message']}{estop}{stop}{control}"
        )
        if self._status is not None and self._status.content != text:
            self._status.content = text
        timings = status["timings"]
        table = " · ".join(f"{k} {1000 * v:.0f}" for k, v in timings.items()) or "-"
        if self._timings is not None and self._timings.content != table:
            self._timings.content = table
        current = status["current"]
        why = "-"
        if current is not None and current["factors"]:
            f = current["factors"]
            why = (
                f"score **{current['score']:.3f}** = Cw {f['Cw']:.2f} × Cj {f['Cj']:.2f} × "
                f"Ca {f['Ca']:.2f} × Cs {f['Cs']:.2f} × Cp {f['Cp']:.2f}  \n"
                "Cw width in the stroke · Cj short joint move · Ca top, then front · "
                "Cs near the target's points · Cp near the mark (004 eq. 3-7)"
            )
        if self._why is not None and self._why.content != why:
            self._why.content = why
        for key in ("mode", "selection", "strategy"):
            handle = self._gui.get(key)
            if handle is not None and handle.value != status[key]:
                handle.value = status[key]


def tcp_path(grasp: Grasp, lift: float = 0.10) -> np.ndarray:
    """The TCP's planned path as segments (2, 2, 3) in `base`: from the pre-grasp along the
    approach to the grasp, then straight up by `lift` (m)."""
    pre = pregrasp_pose(grasp.pose, 0.10)[:3, 3]
    at = grasp.position
    up = at + np.array([0.0, 0.0, lift])
    return np.array([[pre, at], [at, up]])


def projector_pixels(projector: Projector, points: np.ndarray) -> np.ndarray:
    """The flat index (N,) into the projector image of the pixel each point (N, 3) (m,
    `base`) falls on; -1 for a point outside the image or behind the projector. It depends
    only on the points: the projector is fixed to the scooter, the cloud is in `base`."""
    uv, front = projector.project(points)
    px = np.round(uv).astype(np.int64)
    w, h = projector.width, projector.height
    inside = front & (px[:, 0] >= 0) & (px[:, 0] < w) & (px[:, 1] >= 0) & (px[:, 1] < h)
    return np.where(inside, px[:, 1] * w + px[:, 0], -1)


def lit_by(image: np.ndarray, pixels: np.ndarray) -> np.ndarray:
    """Mask of the points whose projector pixels (N,) (`projector_pixels`) the image
    (height x width) lights (pixel > 0)."""
    return (pixels >= 0) & (image.ravel()[np.maximum(pixels, 0)] > 0)
