"""Contacts on the arm and what it feels: the contacts on a set of geoms with their normal
forces, the force a UR5 reads from them, and the guard and protective stops they trigger.

Forces are in N, directions in `world`.
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np

from laserpick.description import dims
from laserpick.robot.interface import PROTECTIVE_STOP


class Contact(NamedTuple):
    """A contact on one of our geoms (the arm's, or what the hand holds)."""

    normal: float  #: the normal force's size (N)
    ours: int  #: our geom
    other: int  #: the geom it touches
    on_ours: np.ndarray  #: (3,) the contact's normal force on our geom (N, `world`)


def contacts_on(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray, *, from_outside: bool = False
) -> list[Contact]:
    """Each contact touching any of `geoms` (a mask over the model's geoms), with its normal
    force on our geom; from_outside: only those between one of `geoms` and one not among
    them."""
    d = data
    if d.ncon == 0:
        return []
    # Every motion checks this every control tick: find the few contacts that touch
    # `geoms` in one vectorized pass, and ask MuJoCo for the force of those only.
    pairs = d.contact.geom  # (ncon, 2)
    a, b = geoms[pairs[:, 0]], geoms[pairs[:, 1]]
    out = []
    force = np.zeros(6)
    for i in np.flatnonzero((a != b) if from_outside else (a | b)):
        mujoco.mj_contactForce(model, d, int(i), force)
        # The contact frame's first row is the normal from geom1 to geom2: the normal
        # force pushes geom2 along it, and geom1 the other way.
        on_second = d.contact.frame[i, :3] * force[0]
        (ours, other), on_ours = (pairs[i], -on_second) if a[i] else (pairs[i, ::-1], on_second)
        out.append(Contact(abs(float(force[0])), int(ours), int(other), on_ours))
    return out


def arm_contacts(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    arm_geoms: np.ndarray,
    pad_geoms: np.ndarray,
    grip_closed: bool,
) -> list[Contact]:
    """The contacts from outside on the arm and the gripper (`arm_geoms`, a mask over the
    model's geoms), and on what a closed gripper holds, as `contacts_on` gives them
    (`felt_force` says what they add up to). The grip itself (the pads, `pad_geoms`, on the
    held object) is internal and not counted: counted, it would trip every guarded place."""
    if not grip_closed or data.ncon == 0:
        return contacts_on(model, data, arm_geoms)
    pairs = data.contact.geom
    on_pad = pad_geoms[pairs]
    touched = np.where(on_pad[:, 0], pairs[:, 1], pairs[:, 0])[on_pad.any(axis=1)]
    if len(touched) == 0:
        return contacts_on(model, data, arm_geoms)
    # The held object: every geom of the bodies the pads touch.
    held = np.isin(model.geom_bodyid, model.geom_bodyid[touched])
    return contacts_on(model, data, arm_geoms | held, from_outside=True)


def felt_force(model: mujoco.MjModel, contacts: list[Contact]) -> float:
    """What the UR5's joint-current force estimate, or a wrist force sensor, reads of
    `contacts` (N): the normal forces on each body of the arm (and on what the hand holds)
    added as vectors, and the bodies' net forces' sizes added up. Forces that cancel within a
    body (a finger pressed from both sides at once) are felt by no sensor, so sizes are not
    added contact by contact. Friction is left out, as when the guards' limits (25 N on an
    approach, 150 N anywhere) were set: a finger brushing a mug's handle reads 25-28 N with
    it."""
    if not contacts:
        return 0.0
    body = model.geom_bodyid[[c.ours for c in contacts]]
    net = np.zeros((model.nbody, 3))
    np.add.at(net, body, np.array([c.on_ours for c in contacts]))
    return float(np.linalg.norm(net[np.unique(body)], axis=1).sum())


def contact_report(model: mujoco.MjModel, contacts: list[Contact], felt: float) -> str:
    """'{N} N on the arm, most where {body} met {body}': what a guarded stop says, with
    `felt` (N) the `felt_force` that stopped it."""
    worst = max(contacts, key=lambda c: c.normal)
    body = model.geom_bodyid
    ours_name, other_name = (
        model.body(int(body[g])).name or "the world" for g in (worst.ours, worst.other)
    )
    return f"{felt:.0f} N on the arm, most where {ours_name} met {other_name}"


def contact_stop(
    model: mujoco.MjModel, contacts: list[Contact], guard_force: float | None
) -> str | None:
    """Why a motion must stop for `contacts`, or None: the force from outside on the arm
    passes the motion's guard (N), or on any motion the protective stop's limit. The UR5
    controller stops every motion it feels pushed back that hard, planned around what it was
    shown or not."""
    total = felt_force(model, contacts)
    if guard_force is not None and total > guard_force:
        return f"unexpected contact: {contact_report(model, contacts, total)}"
    if total > dims.UR5_PROTECTIVE_STOP_FORCE:
        return PROTECTIVE_STOP + contact_report(model, contacts, total)
    return None
