"""Motion: Jeeves' approach (003) and the planning and execution of picks and places."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field, model_validator

__all__ = ["ApproachSettings", "MotionSettings"]


class ApproachSettings(BaseModel):
    """Jeeves' gain-scheduled centroid approach (paper 003 section IV). The paper gives the
    schedule's distances (20 cm, 7 cm) but not its gains; ours are chosen for a scooter."""

    grasp_spot: tuple[float, float] = Field(
        (1.55, -0.30),
        description="Where in `base` (m) the target should end up: before the arm, 41 cm ahead"
        " of its mount. At 1.45 an object 15 cm behind a 75 cm table's edge (003's far row)"
        " brought the edge 16 cm before the mount, and the stowed arm could not rise past it.",
    )
    kv: float = Field(0.8, gt=0, description="Kv, distance gain (1/s).")
    kw_far: float = Field(1.2, ge=0, description="Kw beyond far_distance (1/s).")
    kw_mid: float = Field(0.3, ge=0, description="Kw between near and far distance (1/s).")
    far_distance: float = Field(0.20, gt=0, description="Gain change, 003: 20 cm (m).")
    near_distance: float = Field(0.07, gt=0, description="Kw is 0 inside this, 003: 7 cm (m).")
    tolerance: float = Field(0.02, gt=0, description="Close enough to stop (m).")
    v_max: float = Field(0.3, gt=0, description="Approach speed limit (m/s).")
    w_max: float = Field(0.5, gt=0, description="Approach turn-rate limit (rad/s).")


class MotionSettings(BaseModel):
    """Planning and execution of picks and places (004 section 7.3-7.4; 000 section 4.6; 002)."""

    joint_speed: float = Field(
        1.0,
        gt=0,
        le=3.14,
        description="Joint speed limit (rad/s) near people; the UR5 can do 3.14. 004 issue text.",
    )
    joint_accel: float = Field(1.5, gt=0, le=3.0, description="Joint acceleration (rad/s^2).")
    joint_jerk: float = Field(
        15.0,
        gt=0,
        description="Joint jerk limit (rad/s^3): full acceleration is reached in 0.1 s. Ours:"
        " the UR5's datasheet gives none, and a trajectory without one jumps in acceleration.",
    )
    tcp_speed: float = Field(0.25, gt=0, description="TCP speed limit near people (m/s).")
    carry_turn_speed: float = Field(
        0.75,
        gt=0,
        description="How fast (rad/s) the hand may turn while it carries an object (the TCP"
        " frame's angular speed): an object held by a rim or an edge swings and turns in the"
        " pads. Ours: the carries of `isolation` at a 0.5 rad/s joint limit turned the hand"
        " at up to 1.5 rad/s; with the joints at 0.75 rad/s and no such cap a tissue packet"
        " fell from the hand (docs/behaviours.md, Time).",
    )
    approach_speed: float = Field(
        0.08, gt=0, description="TCP speed (m/s) on the last, guarded approach to a grasp. Ours."
    )
    lift_speed: float = Field(
        0.15,
        gt=0,
        description="TCP speed (m/s) of the lift after the grasp (not the re-grip's first"
        " `regrip_lift`) and of drawing the held object back out from a side grasp. Ours:"
        " at 0.15 rather than the approach's 0.08, `isolation` kept all 90 objects and the"
        " lift took 0.22 s less.",
    )
    approach_distance: float = Field(
        0.10, gt=0, description="Pre-grasp stand-off along the approach axis (m). 004 section 7."
    )
    regrip_lift: float = Field(
        0.02, ge=0, description="Lift (m) before closing again: the re-grip of 002."
    )
    lift: float = Field(0.10, gt=0, description="Lift (m) after the grasp. 000 section 4.6.")
    lift_low: float = Field(
        0.05,
        gt=0,
        description="Lift (m) after the grasp where the full `lift` is blocked, as under a"
        " shelf's board: enough to take the object off its support. Ours.",
    )
    lift_least: float = Field(
        0.03,
        gt=0,
        description="Lift (m) after the grasp where even `lift_low` is blocked: 1 cm over the"
        " re-grip's, off the support, to be drawn back level out of the gap (a hand reaching"
        " 30 deg down into the 69 cm shelf met the board above with its wrist at 4 cm). Ours.",
    )
    guard_force: float = Field(
        25.0,
        gt=0,
        description="Contact force (N) on the arm or the hand's outside that stops a guarded"
        " approach, as a protective stop would. Ours.",
    )
    backoff: float = Field(0.05, gt=0, description="Retreat (m) after an unexpected contact.")
    clearance: float = Field(
        0.01, ge=0, description="Clearance (m) kept between the arm's spheres and the cloud."
    )
    blend_tolerance: float = Field(
        0.002,
        gt=0,
        description="How far (rad, joint space) a blended corner may stray from the checked"
        " path without a check of its own: no sphere of the arm's collision model moves more"
        " than 1.3 m per rad of joint space, 2.6 mm here, a quarter of `clearance`.",
    )
    blend_checked: float = Field(
        0.5,
        gt=0,
        description="How far (rad, joint space) a blended corner may stray from a planned path"
        " where the blend passes the collision check of the path's legs.",
    )
    cartesian_step: float = Field(
        0.01, gt=0, description="Waypoint spacing (m) of straight-line Cartesian paths."
    )
    rrt_max_samples: int = Field(
        2000, ge=10, description="Samples before the joint-space planner gives up."
    )
    rrt_step: float = Field(
        0.3, gt=0, description="RRT-Connect extension step (rad, largest joint; ours)."
    )
    planner: Literal["ompl", "ours"] = Field(
        "ours",
        description="The joint-space search of every way but a pick's to its pre-grasp"
        " (`pick_planner`): our RRT-Connect with random shortcuts, or OMPL's RRT-Connect and"
        " path simplifier; both ask our collision check. Ours: OMPL's"
        " searches are quicker on recorded problems, but in the bench its tighter carries"
        " brought held objects against the scooter (docs/pipeline.md compares them).",
    )
    pick_planner: Literal["ompl", "ours"] = Field(
        "ompl",
        description="The search for a pick's way to its pre-grasp (`first_plan.plan_first`);"
        " `planner` is every other search's. Ours: OMPL's, which carries nothing there. On"
        " eleven recorded in-situ picks its searches took 12.3 s of CPU against 22.2 s with"
        " ours; on in-situ 7301-7310 the pick planned in 0.97 s a try against 1.14 s, one"
        " task more done (docs/pipeline.md).",
    )
    quicken_paths: bool = Field(
        True,
        description="Make each searched joint path quicker to run by partial shortcuts"
        " (pipeline/quicken.py): a search's path wanders in joints no obstacle needed, and"
        " the carry's turn cap makes a wandering wrist slow. Ours: without them, `isolation`'s"
        " carry took 8.59 s rather than 7.61 s (docs/pipeline.md).",
    )
    search_time: float = Field(
        60.0,
        gt=0,
        description="Wall-clock cap (s) of one OMPL search, on top of its rrt_max_samples,"
        " which alone keeps runs the same: the slowest recorded search that used all its"
        " samples took 30 s on a loaded 2-core machine.",
    )
    grasps_together: bool = Field(
        True,
        description="Once the first grasp's short search found no way, search the transit"
        " toward the other grasps' pre-grasps at once (short, one search for each way out),"
        " then toward all of them (full), and take the grasp it reaches, rather than a"
        " search for each grasp, best first; where those find no way, the failed searches"
        " left (rrt_max_failed) go to the grasps one by one. Ours: grasp by grasp, a pick"
        " whose best grasps have no way spends a search on each before one that has; on 17"
        " fresh in-situ seeds the pick planned in 0.70 s a try against 1.19 s, one task of"
        " 156 fewer done; on 8 fresh pick-place seeds 1.72 s against 2.18 s, three tasks of"
        " 96 fewer (docs/pipeline.md).",
    )
    rrt_max_failed: int = Field(
        6,
        ge=1,
        description="Failed joint-space searches in one pick before no more grasps are tried:"
        " each takes seconds, and a user should not wait minutes for a 'no'; a full OMPL"
        " search toward several grasps counts one for each it found no way to. Ours.",
    )
    place_below: float = Field(
        0.02,
        ge=0,
        description="How far (m) below the computed resting pose the guarded descent of a"
        " place may go to meet the surface; the hand opens where it does (EL-E 000 section"
        " 4.5). Met nowhere, the place failed and the hand keeps the object. Ours: a"
        " release 1 cm above the rest let a can lying on its side roll 3 cm off its mark.",
    )
    place_above: float = Field(
        0.06,
        gt=0,
        description="How far (m) above the computed resting pose a place's descent may meet"
        " something and still take it for the surface, and let go: an object that slid"
        " down in the pads meets the surface early (a cereal box slid 3.6 cm). Met higher,"
        " it is something on the surface the cameras missed, and the hand keeps the object"
        " and rises. Ours: a plush toy let go on a glass cup's rim, 10 cm above the"
        " counter, fell and landed upside down.",
    )
    place_contact_force: float = Field(
        10.0,
        gt=0,
        description="Contact force (N) on the hand or the held object that ends a place's"
        " descent: the surface was met. EL-E felt 2 N at its fingers; an arm's"
        " joint-current estimate is coarser. Ours.",
    )

    place_ease: float = Field(
        0.001,
        ge=0,
        description="How far (m) the hand rises, once a place's descent has felt the"
        " surface, before it opens: the guard stops it pressing the object into the"
        " surface. Ours: opened pressing, a mug held by its handle followed one opening"
        " pad 3.6 cm and was lifted on it; eased 1 mm off first, the same grasp let go of"
        " it where it stood. 2 mm lifted a banana 1 mm clear, and let go, it rolled over.",
    )

    @model_validator(mode="after")
    def _lifts_in_order(self) -> MotionSettings:
        """Each lift tried after a blocked one is lower, and the least still rises above the
        re-grip's (a lower one would put the object back down)."""
        if not self.regrip_lift < self.lift_least <= self.lift_low <= self.lift:
            raise ValueError(
                "need regrip_lift < lift_least <= lift_low <= lift (m), got"
                f" {self.regrip_lift}, {self.lift_least}, {self.lift_low}, {self.lift}"
            )
        return self
