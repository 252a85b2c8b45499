"""The MuJoCo loop: `Simulation` owns MjData and steps it, in real time in its own thread or
headless by its caller; other threads send it commands and read its `Snapshot`s.

Beside it: the contacts on the arm and the force it feels (the guard and protective stops),
the scooter's drive with its stop when driving pushes the still arm into something, the
gripper's drive and its status, and the snapshot every chunk publishes.
"""

from laserpick.robot.sim.loop.contacts import (
    Contact,
    arm_contacts,
    contact_report,
    contact_stop,
    contacts_on,
    felt_force,
)
from laserpick.robot.sim.loop.drive import DRIVE_STOP, DRIVE_STOP_CLEARS, BaseDrive
from laserpick.robot.sim.loop.gripper import GripperDrive
from laserpick.robot.sim.loop.simulation import Simulation
from laserpick.robot.sim.loop.snapshot import Snapshot, take_snapshot

__all__ = [
    "DRIVE_STOP",
    "DRIVE_STOP_CLEARS",
    "BaseDrive",
    "Contact",
    "GripperDrive",
    "Simulation",
    "Snapshot",
    "arm_contacts",
    "contact_report",
    "contact_stop",
    "contacts_on",
    "felt_force",
    "take_snapshot",
]
