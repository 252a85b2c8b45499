"""Accessibility input adapters: switches, joysticks and sip-and-puff, as separate programs.

`laserpick adapter switch` and `laserpick adapter joystick` are out-of-process clients of the
public API (`laserpick.client.Client`): they take the control lease, heartbeat, and send the
same REST commands any client may send (rule 2 of the design: one path for every input). A
clinic could write the same programs against `/docs` in any language.

Modules, each small:

- `sources.py`: input events, the scripted event file (`time event` lines) and its source;
- `devices.py`: live sources: the terminal keyboard (raw mode) and Linux evdev devices;
- `scanning.py`: switch timing (acceptance, release) and the scanning state machines;
- `switch.py`: the switch adapter (scan items -> API commands);
- `joystick.py`: the joystick adapter (stick and sip-and-puff presets);
- `connection.py`: the lease, the heartbeat, reconnection with backoff, dead-man driving;
- `announce.py`: what the adapter says, on stdout with a timestamp and through espeak-ng;
- `runner.py`: the loop that feeds timed input to a controller on an injectable clock;
- `launch.py`: `laserpick adapter ...` from parsed arguments.

Timing logic is pure (times are passed in, seconds on the adapter's monotonic clock), so the
tests drive it with a fake clock.
"""
