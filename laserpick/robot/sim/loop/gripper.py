"""The simulated 2F-85's drive: where it sends the fingers, and whether it is still moving.

The drive is a position servo on one finger (the other is mirrored by the linkage) whose
force is capped at `dims.GRIPPER_FORCE_MAX`; the setpoint ramps at `dims.GRIPPER_SPEED`
toward the last command, as the 2F-85 moves its fingers. A 2F-85 closing on something
reports the object (its gOBJ status) once the grip force is reached, and opening, lets go at
once. So here: closing, the fingers count as still once the setpoint stands far enough past
them for the force limit (it goes on toward shut, which keeps the grip at its limit as the
object settles in the pads); opening starts from where the finger stands, not from the
setpoint wound past it, which held the squeeze on for a third of a second after "open".
"""

from __future__ import annotations

from laserpick.description import dims

__all__ = ["GripperDrive"]

#: How near (m, one finger's travel) the fingers count as having reached an opening.
REACHED = 0.0005
#: Past the setpoint error at the force limit, the share that counts as at the limit.
SQUEEZE_MARGIN = 1.05


class GripperDrive:
    """The finger setpoint (m, one finger's travel from the hand's centre, 0 to half the
    stroke) and the last command.

    kp: the finger servo's stiffness (N/m): with the force limit it says how far past the
    finger the setpoint stands at the full grip."""

    def __init__(self, kp: float) -> None:
        self.squeeze = SQUEEZE_MARGIN * dims.GRIPPER_FORCE_MAX / kp
        self.reset()

    def reset(self) -> None:
        """Open, at rest."""
        self.closed = False
        self.target = dims.GRIPPER_STROKE / 2
        self.setpoint = self.target

    def command(self, close: bool, finger: float) -> None:
        """Close (to the force limit) or open fully; `finger` (m) is where the finger stands."""
        self.closed = close
        self.target = 0.0 if close else dims.GRIPPER_STROKE / 2
        if not close:
            self.setpoint = max(self.setpoint, finger)

    def tick(self, dt: float) -> float:
        """Advance the setpoint by `dt` (s) toward the command and return it (m)."""
        step = dims.GRIPPER_SPEED / 2 * dt
        self.setpoint += min(max(self.target - self.setpoint, -step), step)
        return self.setpoint

    def moving(self, finger: float) -> bool:
        """Whether the fingers are still on their way: closing, until they are shut or the
        grip is at its force limit on something; opening, until they stand fully open."""
        if self.closed:
            return self.setpoint > max(self.target, finger - self.squeeze) + REACHED
        return self.setpoint < self.target or finger < self.target - REACHED
