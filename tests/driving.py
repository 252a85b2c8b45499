"""Driving the scooter through a session as a user does, for tests and bench scripts."""

from __future__ import annotations

from laserpick.server.session import Actor, Session


def drive_back_and_in(session: Session, actor: Actor) -> None:
    """1 m back at 0.4 m/s and in again, pausing 1 s between and after: the scooter stands
    where it started, and with the arm stowed the session keeps its views of the way in."""
    robot = session.robot
    for v in (-0.4, 0.4):
        for _ in range(25):
            session.drive(actor, v, 0.0, 0.3)
            robot.sleep(0.1)
        for _ in range(10):
            session.drive(actor, 0.0, 0.0, 0.3)
            robot.sleep(0.1)


def drive_back(session: Session, actor: Actor, distance: float) -> None:
    """`distance` m straight back at 0.4 m/s, then a pause of 1 s."""
    robot = session.robot
    for _ in range(round(distance / 0.04)):
        session.drive(actor, -0.4, 0.0, 0.3)
        robot.sleep(0.1)
    for _ in range(10):
        session.drive(actor, 0.0, 0.0, 0.3)
        robot.sleep(0.1)
