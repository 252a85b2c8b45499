"""Behaviours: how the executed pick, carry, basket drop, place and approach move and feel
(`laserpick.behaviours`). Hardware facts (the gripper's stroke and speed, the basket's size)
live in `laserpick.description.dims`; planning limits in `MotionSettings`."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, Field

__all__ = ["BehaviourSettings"]


class BehaviourSettings(BaseModel):
    """The executed behaviours' tunables. Ours unless a field names a paper."""

    # --- guarded motion ---------------------------------------------------------------------
    start_tolerance: float = Field(
        0.02,
        gt=0,
        description="How far (rad, largest joint) the arm may be from a trajectory's start"
        " when the trajectory is sent; farther, it is waited for (`start_wait`): the"
        " controller refuses a start 0.05 rad off. Ours.",
    )
    start_wait: float = Field(
        1.0,
        ge=0,
        description="How long (s, robot time) the arm is waited for to reach a trajectory's"
        " start. Ours.",
    )
    start_stuck: float = Field(
        0.05,
        gt=0,
        description="Still this far (rad, largest joint) from a trajectory's start after"
        " `start_wait`, the arm is held back (by contact): the motion is not sent. Ours.",
    )
    motion_slack: float = Field(
        3.0,
        ge=0,
        description="Extra time (s) a motion may take beyond its planned duration before it"
        " counts as failed and the arm is halted. Ours.",
    )
    back_step: float = Field(
        0.1,
        gt=0,
        description="Spacing (rad, largest joint) of the waypoints kept on the way back from"
        " a protective stop (a trajectory is sampled densely). Ours.",
    )
    workspace_x: float = Field(
        1.25,
        description="Beyond this x (m, `base`) the hand is over the workspace in front of the"
        " scooter: sent to ready with no cloud, a hand there below the ready height first"
        " rises straight up to it. Ours.",
    )

    # --- Jeeves' centroid approach ----------------------------------------------------------
    approach_period: float = Field(
        0.25,
        gt=0,
        description="Time (s) between the centroid approach's control steps, each of which"
        " re-perceives the target (the loop of 003 section IV; the period is ours).",
    )
    approach_max_steps: int = Field(
        240,
        ge=1,
        description="Control steps of the centroid approach before it gives up: a minute at"
        " `approach_period`. Ours.",
    )

    # --- the basket drop --------------------------------------------------------------------
    drop_heights: tuple[float, ...] = Field(
        (0.06, 0.10, 0.14, 0.20, 0.26),
        description="TCP heights (m) over the basket's rim to let go at: the low ones for most"
        " objects, the high ones for a tall object held near its top, which hangs deep below"
        " the hand. Ours.",
    )
    drop_lows: tuple[float, ...] = Field(
        (0.04, 0.08),
        description="Heights (m) of a held object's lowest point over the basket's floor where"
        " the arm lays it in (`laid_in_candidates`), when too few postures of the fixed grid"
        " hold it wholly over the opening: 4 cm keeps the object's 1 cm points and the 1 cm"
        " clearance off the floor's 1.3 cm keep-out. Ours.",
    )
    drop_tries: int = Field(
        3,
        ge=1,
        description="Drop postures tried in turn when no path to the better ones is found;"
        " where fewer than this hold the whole object over the opening, the laid-in and"
        " tilted postures are ranked too. Ours.",
    )
    fall_step: float = Field(
        0.04,
        gt=0,
        description="Falls (m) that differ by less than this rank alike when a drop posture is"
        " chosen: a long fall bounces the object out of the basket. Ours.",
    )
    overhang_fall_step: float = Field(
        0.08,
        gt=0,
        description="Where no posture holds the whole object over the basket's opening,"
        " upright and tilted postures rank together: by the fall in steps of this (m), then"
        " by the reach past the opening (`overhang_step`). Ours: let go upright 12 cm past a"
        " wall, a cereal box lay across both walls; tilted 3.7 cm past, from as high, it"
        " fell in.",
    )
    overhang_step: float = Field(
        0.01,
        gt=0,
        description="Steps (m) of the reach past the basket's opening by which drop postures"
        " rank after the coarse fall (`overhang_fall_step`). Ours: ranked by the reach alone,"
        " a cereal box went from 6 cm higher and bounced out.",
    )

    # --- carrying ---------------------------------------------------------------------------
    rise_max: float = Field(
        0.20,
        ge=0,
        description="Highest extra lift (m) that brings the arm, the hand and what it holds"
        " clear of what is around them before a planned move: a planner cannot start among"
        " obstacles. Ours.",
    )
    rise_step: float = Field(0.05, gt=0, description="Step (m) of that lift. Ours.")
    rise_out: float = Field(
        0.05,
        ge=0,
        description="How far (m) a step of that lift also reaches out, away from the arm's"
        " mount, where straight up would bring the arm near something: raised straight, a"
        " hand 23 cm before the mount swings the elbow back into the sensor post. Ours.",
    )
    withdraw_steep: float = Field(
        float(np.radians(30.0)),
        gt=0,
        description="A grasp whose approach leans farther than this (rad) from the vertical is"
        " from the side, and is drawn back out level after the lift, out of a shelf's gap"
        " before the arm swings anywhere. Ours.",
    )
    withdraw_turns: tuple[float, ...] = Field(
        tuple(float(t) for t in np.radians([0.0, 15.0, -15.0, 30.0, -30.0])),
        description="Turns (rad) about the vertical of the level way back from a side grasp,"
        " tried in order where straight back along the approach is not clear: drawn straight"
        " back out of the 69 cm shelf, the elbow met the sensor post; turned 15 deg, it"
        " cleared it. Ours.",
    )
    tuck_searches: int = Field(
        2,
        ge=1,
        description="Path searches for the tucked pose before the held object is raised in"
        " front instead: each search is random, and a second finds ways a first did not."
        " Ours.",
    )
    hold_turns: tuple[float, ...] = Field(
        (0.0, np.pi, np.pi / 2, -np.pi / 2),
        description="Turns (rad) of the last wrist joint tried, in order, for a pose the arm"
        " holds an object in on the way (tucked in, raised in front): an object held by one"
        " end reaches back along the hand, into the upper arm's margin at one turn and clear"
        " of it at another. Ours.",
    )
    support_scatter: float = Field(
        0.01,
        ge=0,
        description="Height (m) above the surface an object stood on up to which points are"
        " the surface's own, not the object's: seen points scatter by a few millimetres"
        " (`carried_shape` fills down to this height). Ours.",
    )

    # --- leaving a placed object ------------------------------------------------------------
    leave_level: float = Field(
        float(np.radians(20.0)),
        ge=0,
        description="A hand that let go within this (rad) of level, with a clear way back, is"
        " first lowered `leave_drop`: a pad under a lip of the object leaves it rather than"
        " drag it off its spot on the way back. Ours.",
    )
    leave_drop: float = Field(
        0.005,
        ge=0,
        description="How far (m) the open hand is lowered before it leaves what it let go of"
        " (see `leave_level` and `pads_clear`). Ours.",
    )
    leave_speed: float = Field(
        0.02,
        gt=0,
        description="Speed (m/s) of that lowering and of easing the pads off sideways: lowered"
        " at the approach's 8 cm/s onto a jar's shoulder, a finger met it with 140 N before"
        " the guard stopped it. Ours.",
    )
    leave_settle: float = Field(
        0.3,
        ge=0,
        description="Time (s) the lowered hand is given to get there (the servos lag the"
        " trajectory's clock), and over which the pads are read. Ours.",
    )
    pads_clear: float = Field(
        0.2,
        ge=0,
        description="An open hand whose pads feel more than this (N) before it leaves is"
        " lowered (`leave_drop`), then eased sideways (`leave_shift`). Far under the hold"
        " force: the simulated pads read exactly nothing when they touch nothing; a real"
        " gripper's reading needs it above its noise. Ours.",
    )
    feel_period: float = Field(
        0.05,
        gt=0,
        description="Time (s) between the pad readings taken while the hand stands still: one"
        " reading flickers. Ours.",
    )
    leave_shift: float = Field(
        0.015,
        ge=0,
        description="How far (m) the open hand is eased sideways along its closing axis, one"
        " way and, where the pads still feel something, the other: risen straight up, a"
        " hand took a pill bottle that leaned on one pad by its cap's lip up with it. Ours.",
    )
    leave_touches: int = Field(
        2,
        ge=0,
        description="How often the open hand drawing back from what it set down may stop"
        " where a pad touches it (`leave_nudge`) and ease the pads off sideways, before it"
        " draws back unguarded. Ours.",
    )
    leave_nudge: float = Field(
        0.5,
        gt=0,
        description="Force (N) over what the pads bore at the start that stops that easing:"
        " the way into the object is found by touch, and stopped before it pushes the object"
        " over. Ours.",
    )

    # --- the place and the put-back ---------------------------------------------------------
    place_yaws: tuple[float, ...] = Field(
        tuple(float(t) for t in np.radians([0, 30, -30, 60, -60, 90, -90, 135, -135, 180])),
        description="Turns (rad) about the vertical tried, in order, where the object cannot"
        " be set down as held: turned, it still stands upright where it would have stood"
        " (the grasp's orientation is kept, 004 section 7.3; the turns are ours).",
    )
    put_back_moved: float = Field(
        0.005,
        ge=0,
        description="How far (m) the scooter may have gone since a pick for the object still"
        " to be put back the way it came: parked, the odometry stays put. Ours.",
    )
    put_back_turned: float = Field(
        float(np.radians(0.5)),
        ge=0,
        description="How far (rad) the scooter may have turned since a pick for the object"
        " still to be put back the way it came. Ours.",
    )
