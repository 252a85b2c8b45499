"""`laserpick adapter switch|joystick`: build the source, controller and link from the parsed
arguments (see `laserpick.cli`), and run them.

Default bindings (change evdev ones with `--map CODE=NAME`):

    switch    keyboard: space = switch, enter = select (also 1, 2)
              evdev: KEY_SPACE KEY_1 BTN_0 BTN_LEFT BTN_SOUTH BTN_TRIGGER = switch;
                     KEY_ENTER KEY_2 BTN_1 BTN_RIGHT BTN_EAST BTN_THUMB = select
    stick     keyboard: arrows = stick (held), shift+arrows = drive + stick, c or enter =
              confirm, g or tab = grasp, b = grasp_prev, x or backspace = cancel, m = mode
              evdev: ABS_X/ABS_HAT0X = x, ABS_Y/ABS_HAT0Y = y (inverted: forward is +);
                     BTN_SOUTH BTN_TRIGGER = confirm; BTN_EAST BTN_THUMB = grasp;
                     BTN_WEST = grasp_prev; BTN_TL BTN_TR BTN_THUMB2 = drive;
                     BTN_NORTH BTN_TOP = cancel; BTN_START BTN_SELECT = mode
    sip-puff  keyboard: up/down/left/right (held) = hard puff / hard sip / soft sip / soft
              puff; 8/2/4/6 = the same as taps
              evdev: KEY_1 BTN_0 BTN_TRIGGER = hard_puff; KEY_2 BTN_1 BTN_THUMB = soft_puff;
                     KEY_3 BTN_2 BTN_THUMB2 = soft_sip; KEY_4 BTN_3 BTN_TOP = hard_sip
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path
from types import FrameType

from laserpick.adapters.announce import Announcer
from laserpick.adapters.connection import Connection
from laserpick.adapters.devices import Binding, EvdevSource, KeyboardSource, parse_maps
from laserpick.adapters.joystick import JoystickOptions
from laserpick.adapters.runner import Controller, Runner, open_record
from laserpick.adapters.sip_puff import SipPuffAdapter
from laserpick.adapters.sources import Source, SourceError, load_script
from laserpick.adapters.stick import StickAdapter
from laserpick.adapters.switch import SwitchAdapter, SwitchOptions
from laserpick.adapters.switch_timing import ScanTiming

PASSWORD_ENV = "LASERPICK_OPERATOR_PASSWORD"
EXIT_USAGE = 2


def _buttons(codes: str, name: str) -> dict[str, Binding]:
    return {code: Binding(button=name) for code in codes.split()}


SWITCH_KEYS = {
    "space": Binding(button="switch"),
    "1": Binding(button="switch"),
    "enter": Binding(button="select"),
    "2": Binding(button="select"),
}
SWITCH_EVDEV = {
    **_buttons("KEY_SPACE KEY_1 BTN_0 BTN_LEFT BTN_SOUTH BTN_TRIGGER", "switch"),
    **_buttons("KEY_ENTER KEY_2 BTN_1 BTN_RIGHT BTN_EAST BTN_THUMB", "select"),
}
_STICK_DIRS = {"up": ("y", 1.0), "down": ("y", -1.0), "left": ("x", -1.0), "right": ("x", 1.0)}
STICK_KEYS = {
    **{k: Binding(axis=a, value=v) for k, (a, v) in _STICK_DIRS.items()},
    **{f"shift+{k}": Binding(button="drive", axis=a, value=v) for k, (a, v) in _STICK_DIRS.items()},
    **{k: Binding(button="confirm", tap=True) for k in ("c", "enter")},
    **{k: Binding(button="grasp", tap=True) for k in ("g", "tab")},
    "b": Binding(button="grasp_prev", tap=True),
    **{k: Binding(button="cancel", tap=True) for k in ("x", "backspace")},
    "m": Binding(button="mode", tap=True),
}
STICK_EVDEV = {
    "ABS_X": Binding(axis="x", value=1.0),
    "ABS_HAT0X": Binding(axis="x", value=1.0),
    "ABS_Y": Binding(axis="y", value=-1.0),
    "ABS_HAT0Y": Binding(axis="y", value=-1.0),
    **_buttons("BTN_SOUTH BTN_TRIGGER", "confirm"),
    **_buttons("BTN_EAST BTN_THUMB", "grasp"),
    **_buttons("BTN_WEST", "grasp_prev"),
    **_buttons("BTN_TL BTN_TR BTN_THUMB2", "drive"),
    **_buttons("BTN_NORTH BTN_TOP", "cancel"),
    **_buttons("BTN_START BTN_SELECT", "mode"),
}
_SIP = {"up": "hard_puff", "down": "hard_sip", "left": "soft_sip", "right": "soft_puff"}
_SIP_TAPS = {"8": "hard_puff", "2": "hard_sip", "4": "soft_sip", "6": "soft_puff"}
SIP_KEYS = {
    **{k: Binding(button=v) for k, v in _SIP.items()},
    **{k: Binding(button=v, tap=True) for k, v in _SIP_TAPS.items()},
}
SIP_EVDEV = {
    **_buttons("KEY_1 BTN_0 BTN_TRIGGER", "hard_puff"),
    **_buttons("KEY_2 BTN_1 BTN_THUMB", "soft_puff"),
    **_buttons("KEY_3 BTN_2 BTN_THUMB2", "soft_sip"),
    **_buttons("KEY_4 BTN_3 BTN_TOP", "hard_sip"),
}


def _fail(msg: str) -> int:
    print(f"laserpick: {msg}", file=sys.stderr, flush=True)
    return EXIT_USAGE


def make_source(
    spec: str,
    controller: Controller,
    *,
    keys: dict[str, Binding],
    evdev: dict[str, Binding],
    maps: list[str],
    tap_s: float,
) -> Source:
    """The source named by `--source`. Raises SourceError."""
    kind, _, arg = spec.partition(":")
    if kind == "script" and arg:
        return load_script(Path(arg), buttons=controller.buttons, axes=controller.axes)
    if kind == "keyboard" and not arg:
        return KeyboardSource(keys, tap_s=tap_s)
    if kind == "evdev" and arg:
        bindings = {**evdev, **parse_maps(maps, controller.buttons, controller.axes)}
        return EvdevSource(arg, bindings)
    raise SourceError(f"--source {spec!r}: use evdev:NAME_OR_PATH, keyboard or script:FILE")


def make_controller(
    args: argparse.Namespace, link: Connection, say: Announcer
) -> tuple[Controller, dict[str, Binding], dict[str, Binding], float]:
    """The adapter's controller for the parsed arguments, with its keyboard and evdev
    bindings and the keyboard's tap length (s). Raises ValueError for bad options."""
    options: SwitchOptions | JoystickOptions
    if args.adapter == "switch":
        timing = ScanTiming(args.scan_period, args.cycles, args.accept, args.release, args.delay)
        options = SwitchOptions(args.mode, timing, args.step, args.speed, args.turn)
    else:
        options = JoystickOptions(
            preset=args.preset,
            dead_zone=args.dead_zone,
            rate=args.rate,
            speed=args.speed,
            turn=args.turn,
            step=args.step,
            hold=args.hold,
            double=args.double,
        )
    for name in ("step", "speed", "turn"):
        if not getattr(args, name) > 0:
            raise ValueError(f"--{name} must be more than 0")
    if isinstance(options, SwitchOptions):
        tap_s = max(0.15, args.accept + 0.05)
        return SwitchAdapter(options, link, say), SWITCH_KEYS, SWITCH_EVDEV, tap_s
    if options.preset == "stick":
        return StickAdapter(options, link, say), STICK_KEYS, STICK_EVDEV, 0.1
    return SipPuffAdapter(options, link, say), SIP_KEYS, SIP_EVDEV, 0.1


def run(args: argparse.Namespace) -> int:
    """Run `laserpick adapter <args.adapter>` until its input ends; the exit code."""
    say = Announcer(speak=args.speak)
    link = Connection(
        args.url,
        name=args.name or f"{args.adapter} adapter",
        source=args.adapter,
        announcer=say,
        password=os.environ.get(PASSWORD_ENV),
    )
    try:
        controller, keys, evdev, tap_s = make_controller(args, link, say)
        source = make_source(
            args.source, controller, keys=keys, evdev=evdev, maps=args.map, tap_s=tap_s
        )
    except (ValueError, SourceError) as exc:
        return _fail(str(exc))

    def on_term(_signum: int, _frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, on_term)  # a clean stop: no drive left, the lease given back
    record = open_record(args.record)
    try:
        return Runner(source, controller, link, say, record=record).run()
    except KeyboardInterrupt:
        say.note("stopped")
        return 0
    finally:
        if record is not None:
            record.close()
        say.close()
