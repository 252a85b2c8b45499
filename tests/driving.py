"""Driving the scooter through a session as a user does, for tests and bench scripts."""

from __future__ import annotations

from laserpick.server.session import Actor, Session


def drive_straight(session: Session, actor: Actor, v: float, distance: float) -> None:
    """`distance` m straight at `v` m/s (forward when positive), then a pause of 1 s. Each
    command is held 0.3 s and sent again every 0.1 s of robot time, as a joystick does."""
    robot = session.robot
    for _ in range(round(distance / abs(v * 0.1))):
        session.drive(actor, v, 0.0, 0.3)
        robot.sleep(0.1)
    for _ in range(10):
        session.drive(actor, 0.0, 0.0, 0.3)
        robot.sleep(0.1)


def drive_back_and_in(session: Session, actor: Actor) -> None:
    """1 m back at 0.4 m/s and in again, pausing 1 s between and after: the scooter stands
    where it started, and with the arm stowed the session keeps its views of the way in."""
    drive_straight(session, actor, -0.4, 1.0)
    drive_straight(session, actor, 0.4, 1.0)
