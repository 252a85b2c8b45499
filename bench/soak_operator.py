"""The soak's controller: a scripted operator holding the lease and working through a mix of
episodes, one after another, until told to stop.

Episodes (`MIX`, in turn):

* `pick`: aim at an object on the table (`GET /sim/objects`, the simulator's truth playing
  the person who sees it), confirm, Go, and wait until the job ends;
* `drive`: drive out and back (`POST /drive` at 10 Hz, 0.3 s dead-man commands);
* `cancel`: a pick cancelled (`POST /cancel`) once the arm has moved for a while;
* `estop`: a pick e-stopped (`POST /stop`, with the lease's token) mid-motion, then the stop
  reset (`POST /stop/reset`, retried while the stopped job winds down);
* `reconnect`: mark an object, drop the lease (`DELETE /control`, the heartbeats stop), take
  it again and pick.

Before each episode the session is brought to rest (idle, not e-stopped, nothing in the hand)
and the scene is reset (`POST /scene {"name": "isolation"}`) when the table is empty or the
scooter has moved from where the scene put it. Every changing request goes through the
`Ledger`. Times in seconds, positions in `base` (m).
"""

from __future__ import annotations

import itertools
import math
import random
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from typing import Any

import requests
from soak_ledger import Ledger

from laserpick.client import ApiError, Client

MIX = ("pick", "drive", "cancel", "pick", "estop", "reconnect")
#: An object counts as on the table with its centre this high (m; the table's top is 0.46 m).
ON_TABLE_Z = 0.3
#: The scene is reset once the scooter is this far (m) or turned this much (rad) from its start.
DRIFT_M, DRIFT_RAD = 0.05, 0.05
#: Objects that failed this often since the scene's last reset are left alone.
MAX_TRIES = 2
SCENE = {"name": "isolation"}


class LoggedClient(Client):
    """A `Client` that notes (wall clock, s) when each state frame and heartbeat
    acknowledgement arrives, and the server's time on each acknowledgement: around a
    watchdog stop they tell a silent client (frames kept coming, so its thread ran and sent
    heartbeats) from a server that read nothing (the acknowledgements' server times stop)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.frames_at: deque[float] = deque(maxlen=200_000)
        self.acks: deque[tuple[float, float]] = deque(maxlen=100_000)  #: (arrived, server t)

    def _on_message(self, msg: dict[str, Any]) -> None:
        now = time.time()
        if msg.get("type") == "state":
            self.frames_at.append(now)
        elif msg.get("type") == "heartbeat_ack":
            self.acks.append((now, float(msg.get("t", math.nan))))
        super()._on_message(msg)

    def gaps_before(self, t: float, span: float = 3.0) -> dict[str, float]:
        """The longest gaps (s) in the `span` s before wall time `t`: between state frames
        arriving, acknowledgements arriving, and the server's times on them."""

        def longest(times: list[float]) -> float:
            near = [t - span, *sorted(x for x in times if t - span < x < t), t]
            return round(max(b - a for a, b in itertools.pairwise(near)), 3)

        return {
            "frames_arrived": longest(list(self.frames_at)),
            "acks_arrived": longest([a for a, _ in self.acks]),
            "acks_server_t": longest([s for _, s in self.acks]),
        }


class Stopped(Exception):
    """The soak is over: the episode under way is abandoned."""


class Operator:
    """The controller. `lease_lock` is held while the lease is dropped and retaken, so the
    second client tries to take control only while this one holds it."""

    def __init__(self, url: str, ledger: Ledger, stop: threading.Event, seed: int = 1) -> None:
        self.url, self.ledger, self.stop = url, ledger, stop
        self.client = LoggedClient(url, name="soak operator", source="bench", timeout=60.0)
        self.lease_lock = threading.Lock()
        self.rng = random.Random(seed)
        self.episodes: Counter[str] = Counter()
        self.outcomes: Counter[str] = Counter()  #: how the picks ended: "done", failure kinds
        self.tries: Counter[str] = Counter()  #: failed picks by object since the last reset
        self.scene_resets = 0
        self.errors: list[str] = []

    # --- plumbing ----------------------------------------------------------------------------

    def send(self, method: str, path: str, body: Any = None) -> int:
        """A changing request through the ledger; its status."""
        return self.ledger.call(self.client, method, path, body)[0]

    def take(self) -> None:
        """Take the lease and start heartbeating, through the ledger."""
        try:
            self.client.take_control()
        except ApiError as exc:
            self.ledger.answered("POST", "/control", exc.status, exc.detail)
            raise
        self.ledger.answered("POST", "/control", 200)

    def release(self) -> None:
        """Give the lease back, through the ledger, and stop heartbeating."""
        self.ledger.call(self.client, "DELETE", "/control")
        self.client.token = None  # no more heartbeats, and no second DELETE from release()
        self.client.release()

    def state(self) -> dict[str, Any]:
        status, state = self.ledger.call(self.client, "GET", "/state")
        if status != 200:
            raise RuntimeError(f"GET /state answered {status}")
        return state

    def until(
        self, pred: Callable[[dict[str, Any]], bool], timeout: float, stoppable: bool = True
    ) -> dict[str, Any]:
        """Poll the state every 0.1 s until `pred` holds; Stopped once the soak is over."""
        end = time.monotonic() + timeout
        while True:
            state = self.state()
            if pred(state):
                return state
            if stoppable and self.stop.is_set():
                raise Stopped
            if time.monotonic() > end:
                where = f"{state['state']}: {state['message']}"
                raise TimeoutError(f"waited {timeout:.0f} s in {where}")
            time.sleep(0.1)

    def settled(self, timeout: float = 300.0, stoppable: bool = True) -> dict[str, Any]:
        return self.until(lambda s: not s["busy"], timeout, stoppable)

    # --- the loop ----------------------------------------------------------------------------

    def run(self) -> None:
        """Episodes in turn until `stop`; then cancel what runs and give the lease back."""
        try:
            self.take()
            self.send("POST", "/mode", {"mode": "pick_and_drop", "selection": "auto"})
            i = 0
            while not self.stop.is_set():
                name = MIX[i % len(MIX)]
                i += 1
                try:
                    self.rest()
                    self.prepare_scene()
                    getattr(self, f"episode_{name}")()
                    self.episodes[name] += 1
                except Stopped:
                    break
                except Exception as exc:  # a failed episode is counted; the soak goes on
                    if not isinstance(exc, requests.RequestException | OSError):
                        self.ledger.exception(f"episode {name}", exc)  # else counted already
                    self.errors.append(f"{name}: {type(exc).__name__}: {exc}")
                    time.sleep(1.0)
        finally:
            self.finish()

    def finish(self) -> None:
        """Cancel the job under way, reset the e-stop, wait for rest and release the lease."""
        try:
            if self.client.token is None:
                self.take()
            state = self.state()
            if state["busy"]:
                self.send("POST", "/cancel")
            self.settled(300, stoppable=False)
            if self.state()["estopped"]:
                self.send("POST", "/stop/reset")
        except Exception as exc:
            self.ledger.exception("finish", exc)
            self.errors.append(f"finish: {type(exc).__name__}: {exc}")
        finally:
            if self.client.token is not None:
                self.release()

    def rest(self) -> None:
        """Bring the session to idle with an empty hand and no e-stop."""
        for _ in range(4):
            state = self.settled()
            if state["estopped"]:
                self.send("POST", "/stop/reset")
            elif state["state"] == "holding":
                self.send("POST", "/execute")  # drop it in the basket
            elif state["state"] != "idle":
                self.send("POST", "/cancel")
            else:
                return
        # Stuck (a drop that keeps failing, say): a new scene starts afresh.
        self.settled()
        if self.send("POST", "/scene", SCENE) == 200:
            self.scene_resets += 1
            self.tries.clear()
        self.errors.append(f"could not rest: {self.state()['message']}")

    def prepare_scene(self) -> None:
        """Reset the scene when no object is left to pick or the scooter has moved."""
        x, y, yaw = self.state()["base_pose"]
        drifted = abs(x) + abs(y) > DRIFT_M or abs(yaw) > DRIFT_RAD
        if (drifted or self.target() is None) and self.send("POST", "/scene", SCENE) == 200:
            self.scene_resets += 1
            self.tries.clear()

    def target(self) -> dict[str, Any] | None:
        """An object on the table that has not failed `MAX_TRIES` times; None if none."""
        status, objects = self.ledger.call(self.client, "GET", "/sim/objects")
        if status != 200:
            return None
        left = [
            o
            for o in objects
            if not o["in_basket"]
            and o["center_base"][2] > ON_TABLE_Z
            and self.tries[o["name"]] < MAX_TRIES
        ]
        return self.rng.choice(left) if left else None

    # --- the episodes ------------------------------------------------------------------------

    def mark(self) -> str | None:
        """Aim at an object and confirm; its name once grasps are ready, else None."""
        obj = self.target()
        if obj is None:
            return None
        if self.send("POST", "/laser/aim", {"point": obj["center_base"]}) != 200:
            return None
        if self.send("POST", "/laser/confirm") != 200:
            return None
        state = self.settled(120)
        if state["state"] != "grasps_ready":
            self.outcomes[f"mark: {(state['failure'] or {}).get('kind', state['state'])}"] += 1
            self.tries[obj["name"]] += 1
            return None
        return obj["name"]

    def go(self, name: str) -> None:
        """Execute and wait until the job ends; count how it ended."""
        if self.send("POST", "/execute") != 200:
            return
        state = self.settled(300)
        failure = state["failure"]
        if failure is None:
            self.outcomes["done"] += 1
        else:
            self.outcomes[f"pick: {failure['kind']}"] += 1
            self.tries[name] += 1

    def episode_pick(self) -> None:
        name = self.mark()
        if name is not None:
            self.go(name)

    def episode_drive(self) -> None:
        """Out and back: back, turn left, turn right, forward, 1 s each at 10 Hz (back first:
        the scene parks the scooter at the table)."""
        for v, w in ((-0.1, 0.0), (0.0, 0.2), (0.0, -0.2), (0.1, 0.0)):
            for _ in range(10):
                self.send("POST", "/drive", {"v": v, "w": w, "duration": 0.3})
                time.sleep(0.1)
        self.send("POST", "/drive", {"v": 0.0, "w": 0.0, "duration": 0.1})

    def interrupt(self, path: str) -> bool:
        """Start a pick and send `path` once the arm has moved for 1 to 6 s; whether sent."""
        if self.mark() is None or self.send("POST", "/execute") != 200:
            return False
        time.sleep(self.rng.uniform(1.0, 6.0))
        self.send("POST", path)
        return True

    def episode_cancel(self) -> None:
        if self.interrupt("/cancel"):
            self.settled(300)

    def episode_estop(self) -> None:
        if not self.interrupt("/stop"):
            return
        time.sleep(0.5)
        for _ in range(600):  # refused while the stopped job winds down
            if self.send("POST", "/stop/reset") == 200:
                return
            time.sleep(0.5)
        raise RuntimeError("the e-stop could not be reset in 300 s")

    def episode_reconnect(self) -> None:
        """Drop the lease with the grasps ready, take it again after 0.2-2 s, and pick."""
        name = self.mark()
        with self.lease_lock:
            self.release()
            time.sleep(self.rng.uniform(0.2, 2.0))
            self.take()
        if name is not None and self.state()["state"] == "grasps_ready":
            self.go(name)
