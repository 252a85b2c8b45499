"""Accessibility input adapters: switches, joysticks and sip-and-puff, as separate programs.

`laserpick adapter switch` and `laserpick adapter joystick` are out-of-process clients of the
public API (`laserpick.client.Client`): they take the control lease, heartbeat, and send the
same REST commands any client may send (one path for every input). A clinic could write the
same programs against `/docs` in any language. They read the server's limits (the largest
laser nudge) from `GET /health` when they connect.

Modules:

- `sources.py`: input events, the scripted event file (`time event` lines) and its source;
- `devices.py`: live sources: the terminal keyboard (cbreak mode) and Linux evdev devices;
- `switch_timing.py`: when a switch press counts (acceptance and release times);
- `scan_menu.py`: the groups and items the switch adapter scans;
- `scanning.py`: the scanning state machines (one-switch automatic, two-switch step);
- `switch.py`: the switch adapter (scan items -> API commands);
- `joystick.py`: the joystick presets' options, dead zone and rate aiming;
- `stick.py`, `sip_puff.py`: the joystick adapter's two presets;
- `commands.py`: commands that look at the server's state first (confirm or go, grasp steps);
- `connection.py`: the lease, the heartbeat, reconnection with backoff, dead-man driving;
- `announce.py`: what the adapter says, on stdout with a timestamp and through espeak-ng;
- `runner.py`: the loop that feeds timed input to a controller on an injectable clock;
- `launch.py`: `laserpick adapter ...` from parsed arguments.

Timing logic is pure (times are passed in, seconds on the adapter's monotonic clock), so the
tests drive it with a fake clock. Angles are rad, speeds m/s and rad/s.
"""

from laserpick.adapters.announce import Announcer
from laserpick.adapters.connection import Connection, MissingLimit, nudge_limit, reason, refusal
from laserpick.adapters.devices import (
    Binding,
    EvdevSource,
    KeyboardSource,
    normalize,
    parse_maps,
    split_keys,
)
from laserpick.adapters.joystick import JoystickOptions, RateAim, shaped
from laserpick.adapters.runner import Controller, Runner
from laserpick.adapters.scan_menu import GROUPS, Group, Item
from laserpick.adapters.scanning import (
    AutoScanner,
    Highlight,
    HoldEnd,
    HoldStart,
    Output,
    Pending,
    Selected,
    StepScanner,
    Stopped,
    Undone,
)
from laserpick.adapters.sip_puff import SipPuffAdapter
from laserpick.adapters.sources import (
    InputEvent,
    Quit,
    ScriptError,
    ScriptSource,
    Source,
    SourceError,
    Wait,
    load_script,
    parse_script,
)
from laserpick.adapters.stick import StickAdapter
from laserpick.adapters.switch import SwitchAdapter, SwitchOptions
from laserpick.adapters.switch_timing import ScanTiming, SwitchFilter

__all__ = [
    "GROUPS",
    "Announcer",
    "AutoScanner",
    "Binding",
    "Connection",
    "Controller",
    "EvdevSource",
    "Group",
    "Highlight",
    "HoldEnd",
    "HoldStart",
    "InputEvent",
    "Item",
    "JoystickOptions",
    "KeyboardSource",
    "MissingLimit",
    "Output",
    "Pending",
    "Quit",
    "RateAim",
    "Runner",
    "ScanTiming",
    "ScriptError",
    "ScriptSource",
    "Selected",
    "SipPuffAdapter",
    "Source",
    "SourceError",
    "StepScanner",
    "StickAdapter",
    "Stopped",
    "SwitchAdapter",
    "SwitchFilter",
    "SwitchOptions",
    "Undone",
    "Wait",
    "load_script",
    "normalize",
    "nudge_limit",
    "parse_maps",
    "parse_script",
    "reason",
    "refusal",
    "shaped",
    "split_keys",
]
