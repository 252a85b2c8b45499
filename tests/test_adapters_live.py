"""The adapters as separate processes against a real `laserpick serve`, replaying scripted
event files: a pick and drop by one-switch scanning and by the stick, a pick and place by sip
and puff, the scan period in real time, and a server lost and restarted mid-drive.
"""

from __future__ import annotations

import math
import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from adapter_process import (
    AdapterProcess,
    Script,
    aim_angles,
    obj,
    prepare,
    run_adapter,
)
from basket import assert_in_basket
from serve_process import ServeProcess, stop_process
from test_server import in_base, kitchen_at, remote_goal

from laserpick.adapters import GROUPS, shaped
from laserpick.client import Client

pytestmark = pytest.mark.timeout(400)


#: The dead-man's window for these servers (s): the widest `ServerSettings.watchdog_s` allows. The
#: adapters heartbeat every 0.15 s, but `make test` runs two workers beside the server and the
#: adapter on two cores, where a heartbeat came more than the default 0.5 s apart and halted
#: a stow. The dead-man at its default is `test_server.py`'s and `test_session.py`'s to test.
WATCHDOG_S = "2.0"


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServeProcess]:
    env = {"LASERPICK_SERVER__WATCHDOG_S": WATCHDOG_S}
    proc = ServeProcess(tmp_path_factory.mktemp("serve"), env=env).start()
    yield proc
    proc.close()


# --- pick and drop, one adapter each -------------------------------------------------------------


def one_switch_presses(script: Script, key: str, times: int = 1) -> None:
    """Wait until `key` is highlighted, then press `times`: each press held 0.15 s (more than
    the 0.1 s acceptance), each 0.15 s after the last release (more than the 0.1 s release
    time), all accepted within the 0.5 s that the highlight stays after the last one."""
    script.wait(f"highlight={key}", timeout=60)
    for i in range(times):
        script.tap("switch", 0.15 + 0.3 * i, 0.15)


def test_switch_one_switch_scanning_picks_and_drops(server: ServeProcess, tmp_path: Path) -> None:
    state = prepare(server.url, scene={"name": "isolation"})
    mug = obj(server.url, "mug_1")
    yaw, pitch = aim_angles(mug["center_base"])
    step = 0.02
    n_pitch = round((pitch - state["laser"]["pitch"]) / step)
    n_yaw = round((yaw - state["laser"]["yaw"]) / step)
    s = Script()
    s.tap("switch", 0.3, 0.15)  # start scanning
    one_switch_presses(s, "laser")
    one_switch_presses(s, "laser.up" if n_pitch > 0 else "laser.down", abs(n_pitch))
    if n_yaw:
        one_switch_presses(s, "laser.left" if n_yaw > 0 else "laser.right", abs(n_yaw))
    one_switch_presses(s, "laser.confirm")
    s.wait("state=grasps_ready", timeout=120)
    one_switch_presses(s, "laser.back")
    one_switch_presses(s, "grasps")
    one_switch_presses(s, "grasps.go")
    s.wait("state=idle", timeout=240)
    path = s.write(tmp_path / "one_switch.txt")
    adapter = run_adapter(
        [
            "switch",
            *["--url", server.url, "--source", f"script:{path}", "--mode", "one-switch"],
            *["--scan-period", "0.5", "--cycles", "0", "--step", str(step)],
        ],
        timeout=330,
    )
    out = adapter.text()
    assert "select grasps.go" in out and "Dropped in the basket" in out, out
    assert_in_basket(obj(server.url, "mug_1"))
    journal = Client(server.url).get("/journal", format="json")
    mine = [e for e in journal if e["source"] == "switch" and e["outcome"] == "ok"]
    assert sum(e["action"] == "laser/nudge" for e in mine) == abs(n_pitch) + abs(n_yaw)


def test_joystick_stick_picks_and_drops(server: ServeProcess, tmp_path: Path) -> None:
    state = prepare(server.url, scene={"name": "isolation"})
    mug = obj(server.url, "mug_1")
    yaw, pitch = aim_angles(mug["center_base"])
    dyaw, dpitch = yaw - state["laser"]["yaw"], pitch - state["laser"]["pitch"]
    rate, dead_zone, deflection = 0.4, 0.1, 0.6
    beam = rate * shaped(deflection, dead_zone)  # rad/s at this deflection
    s = Script()
    t_pitch, t_yaw = abs(dpitch) / beam, abs(dyaw) / beam
    s.at(0.5, f"axis y {math.copysign(deflection, dpitch)}")  # forward: beam up
    s.at(0.5 + t_pitch, "axis y 0")
    s.at(0.7 + t_pitch, f"axis x {-math.copysign(deflection, dyaw)}")  # right: beam right
    s.at(0.7 + t_pitch + t_yaw, "axis x 0")
    s.tap("confirm", 1.0 + t_pitch + t_yaw, 0.1)
    s.wait("state=grasps_ready", timeout=120)
    s.tap("confirm", 0.3, 0.1)  # with grasps ready, confirm means go
    s.wait("state=idle", timeout=240)
    path = s.write(tmp_path / "stick.txt")
    adapter = run_adapter(
        [
            "joystick",
            *["--url", server.url, "--source", f"script:{path}", "--preset", "stick"],
            *["--rate", str(rate), "--dead-zone", str(dead_zone)],
        ],
        timeout=330,
    )
    out = adapter.text()
    assert "go: picking" in out and "Dropped in the basket" in out, out
    assert_in_basket(obj(server.url, "mug_1"))


# --- pick and place on the kitchen, by sip and puff ----------------------------------------------


class SipPuff:
    """Writes sips and puffs (the sip-puff preset's defaults: hold 0.3 s, double 0.4 s)."""

    def __init__(self, script: Script, rate: float, hold: float = 0.3) -> None:
        self.s, self.rate, self.hold = script, rate, hold

    def double(self, times: int = 1) -> None:
        """Two quick puffs: the next mode."""
        for _ in range(times):
            t = self.s.t + 0.3
            self.s.tap("hard_puff", t, 0.1)
            self.s.tap("hard_puff", t + 0.25, 0.1)

    def tap(self, channel: str) -> None:
        """One short sip or puff; it acts when the 0.4 s double window has passed."""
        t = self.s.t + 0.3
        self.s.tap(channel, t, 0.1)
        self.s.t = t + 0.6

    def aim(self, dyaw: float, dpitch: float) -> None:
        """Hold to turn the beam: it moves `rate` rad/s from `hold` s into the sip or puff."""
        for channel, angle in (
            ("hard_puff" if dpitch > 0 else "hard_sip", dpitch),
            ("soft_sip" if dyaw > 0 else "soft_puff", dyaw),
        ):
            if abs(angle) < 1e-6:
                continue
            t = self.s.t + 0.3
            self.s.at(t, f"press {channel}")
            self.s.at(t + self.hold + abs(angle) / self.rate, f"release {channel}")


def test_sip_and_puff_picks_and_places_on_kitchen(server: ServeProcess, tmp_path: Path) -> None:
    """The TV remote from the 31 cm coffee table to 20 cm along it (as tests/test_server.py
    does by REST), by sips and puffs only: modes, aiming, confirming, going and placing."""
    state = prepare(server.url, scene={"yaml": kitchen_at("table_31")})
    remote = obj(server.url, "tv_remote")
    goal = remote_goal()
    y1, p1 = aim_angles(remote["center_base"])
    y2, p2 = aim_angles(in_base(goal, state["base_pose"]))
    y0, p0 = state["laser"]["yaw"], state["laser"]["pitch"]
    rate = 0.4
    s = Script()
    sp = SipPuff(s, rate)
    sp.double(3)  # aim -> grasp -> drive -> task
    sp.tap("soft_puff")  # task: pick and place
    sp.double()  # -> aim
    sp.aim(y1 - y0, p1 - p0)
    sp.double()  # -> grasp
    sp.tap("hard_puff")  # confirm the mark
    s.wait("state=grasps_ready", timeout=120)
    sp.tap("hard_puff")  # go
    s.wait("state=awaiting_place", timeout=180)
    sp.double(3)  # grasp -> drive -> task -> aim
    sp.aim(y2 - y1, p2 - p1)
    sp.double()  # -> grasp
    sp.tap("hard_puff")  # confirm the place mark
    s.wait("state=idle", timeout=180)
    path = s.write(tmp_path / "sip_puff.txt")
    adapter = run_adapter(
        [
            "joystick",
            *["--url", server.url, "--source", f"script:{path}", "--preset", "sip-puff"],
            *["--rate", str(rate)],
        ],
        timeout=330,
    )
    out = adapter.text()
    assert "task soft puff: pick and place" in out and "Placed. Ready." in out, out
    placed = obj(server.url, "tv_remote")
    assert np.linalg.norm(np.subtract(placed["position_world"][:2], goal[:2])) < 0.05, out
    assert abs(placed["position_world"][2] - 0.31) < 0.02


# --- losing the server mid-drive ----------------------------------------------------------------


def test_server_killed_mid_drive_reconnect_sends_no_unasked_motion(tmp_path: Path) -> None:
    """Drive, kill the server, restart it on the same port. The adapter says so, reconnects,
    and the new server's scooter stays put, although the script still holds drive and the
    stick forward, until the person lets go and asks again."""
    (tmp_path / "a").mkdir()
    first = ServeProcess(tmp_path / "a").start()
    s = Script()
    # The timeline starts once the adapter is connected: input before that is (rightly) not
    # obeyed, and on a loaded machine connecting takes over a second.
    s.wait("state=idle", timeout=60)
    s.at(0.5, "press drive")
    s.at(0.6, "axis y 0.8")  # held over the outage: the replay pauses while it lasts
    s.at(7.0, "axis y 0")
    s.at(7.1, "release drive")
    s.at(8.0, "press drive")  # asked again: now it may move
    s.at(8.1, "axis y 0.8")
    s.at(9.6, "axis y 0")
    s.at(9.7, "release drive")
    s.at(10.5, "quit")
    path = s.write(tmp_path / "drive.txt")
    adapter = AdapterProcess(
        ["joystick", "--url", first.url, "--source", f"script:{path}", "--speed", "0.2"]
    )
    second: ServeProcess | None = None
    try:
        i, _ = adapter.wait_line(r"^driving", timeout=60)
        time.sleep(1.0)
        moved = Client(first.url).state()["base_pose"]
        assert math.hypot(moved[0], moved[1]) > 0.03, f"the first server never drove: {moved}"
        os.kill(first.proc.pid, signal.SIGKILL)
        first.proc.wait(10)
        j, _ = adapter.wait_line(r"lost the server", timeout=10, after=i)
        (tmp_path / "b").mkdir()
        second = ServeProcess(tmp_path / "b", api_port=first.api_port).start()
        k, _ = adapter.wait_line(r"connected to", timeout=30, after=j)
        samples: list[tuple[float, list[float]]] = []
        while adapter.proc.poll() is None:
            pose = Client(second.url).state()["base_pose"]
            samples.append((time.monotonic(), pose))
            time.sleep(0.1)
        assert adapter.wait(30) == 0, adapter.text()
        final = Client(second.url).state()["base_pose"]
    finally:
        stop_process(adapter.proc)
        first.close()
        if second is not None:
            second.close()
    out = adapter.text()
    assert "centre the stick and release drive to resume" in out, out
    _, asked_at = adapter.wait_line(r"^driving", timeout=1, after=k)
    before = [pose for t, pose in samples if t < asked_at - 0.2]
    assert len(before) > 20, f"too few samples before the new drive ({len(before)}):\n{out}"
    still = max(math.hypot(p[0] - before[0][0], p[1] - before[0][1]) for p in before)
    assert still < 0.005, f"the new server's scooter moved {still:.3f} m unasked:\n{out}"
    assert math.hypot(final[0] - before[0][0], final[1] - before[0][1]) > 0.05, out


# --- scan timing, in real time --------------------------------------------------------------------


def test_scan_period_is_one_second_within_50_ms(server: ServeProcess, tmp_path: Path) -> None:
    s = Script()
    s.tap("switch", 0.2, 0.15)
    s.wait("highlight=cancel", timeout=30)
    s.at(0.1, "quit")
    path = s.write(tmp_path / "timing.txt")
    adapter = run_adapter(
        ["switch", "--url", server.url, "--source", f"script:{path}", "--scan-period", "1.0"],
        timeout=60,
    )
    shown = [(recv, stamp) for recv, stamp, text in adapter.lines if text.startswith("highlight")]
    assert [t for _, _, t in adapter.lines if t.startswith("highlight")] == [
        f"highlight {g.key}" for g in GROUPS
    ]
    stamps = np.diff([stamp for _, stamp in shown])
    received = np.diff([recv for recv, _ in shown])
    assert np.all(np.abs(stamps - 1.0) <= 0.050), stamps
    assert np.all(np.abs(received - 1.0) <= 0.100), received  # as the test process saw them
