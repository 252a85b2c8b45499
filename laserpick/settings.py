"""The one settings object: every tunable default, named, with where it came from.

Values are read from `LASERPICK_*` environment variables; nested groups use a double
underscore, e.g. `LASERPICK_SIM__RATE_HZ=250` or `LASERPICK_SENSOR__DEPTH_NOISE_K=0.002`.
Hardware limits (joint ranges, speeds, stroke) are not settings: they are facts of the
robot and live in `laserpick.description.dims`.
"""

from __future__ import annotations

from functools import lru_cache

from pydantic import BaseModel, Field, SecretStr, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict


class SimSettings(BaseModel):
    """The MuJoCo loop."""

    rate_hz: float = Field(500.0, gt=0, description="Physics rate (Hz); the timestep is 1/rate.")
    impratio: float = Field(
        10.0, ge=1.0, description="Friction-to-normal impedance ratio; >= 10 holds a jaw grasp."
    )
    noslip_iterations: int = Field(
        2, ge=0, description="Noslip solver passes that stop objects creeping out of a grasp."
    )
    control_rate_hz: float = Field(
        100.0, gt=0, description="Arm controller rate (Hz): IK and trajectory setpoints."
    )


class SensorSettings(BaseModel):
    """The depth sensor noise model, fitted loosely to structured-light sensors."""

    depth_noise_k: float = Field(
        1.5e-3, ge=0, description="Depth noise sigma = k * z^2 (1/m): 1.5 mm at 1 m."
    )
    edge_dropout_jump: float = Field(
        0.04, ge=0, description="Depth jump (m) between neighbours that marks an edge pixel."
    )
    edge_dropout_prob: float = Field(
        0.5, ge=0, le=1, description="Chance that an edge pixel reads no depth."
    )
    specular_dropout: float = Field(
        0.5, ge=0, le=1, description="Fraction of a specular object's pixels that read no depth."
    )
    specular_blob_px: float = Field(
        12.0,
        gt=0,
        description="Size (px) of the blobs a specular object's missing depth comes in.",
    )
    ir_noise: float = Field(
        2.0, ge=0, description="Sigma of the IR image's intensity noise (grey levels)."
    )
    laser_spot_radius_px: float = Field(
        2.5, gt=0, description="Apparent radius of a laser dot in the IR image (px)."
    )
    capture_rate_hz: float = Field(
        2.0, gt=0, description="How often the live console captures all five cameras (Hz)."
    )
    seed: int = Field(0, description="Seed of the sensor noise generator.")


class PerceptionSettings(BaseModel):
    """Fusion, laser detection, segmentation and surface parameters (papers 004, 000, 002)."""

    pixel_stride: int = Field(
        2, ge=1, le=8, description="Use every n-th pixel of each depth image when fusing."
    )
    workspace_min: tuple[float, float, float] = Field(
        (0.3, -1.2, -0.05), description="Workspace crop box, lower corner in `base` (m)."
    )
    workspace_max: tuple[float, float, float] = Field(
        (2.6, 1.2, 1.9), description="Workspace crop box, upper corner in `base` (m)."
    )
    voxel_size: float = Field(
        0.0, ge=0, description="Voxel downsampling edge (m); 0 keeps every point."
    )
    laser_threshold: int = Field(
        250, ge=1, le=255, description="IR intensity of a laser dot (0-255)."
    )
    laser_pair_px: float = Field(
        40.0, gt=0, description="Largest image distance (px) between the two beams' spots."
    )
    laser_match_m: float = Field(
        0.02, gt=0, description="Views agree on a mark when their 3D points lie this close (m)."
    )
    laser_spot_min_px: int = Field(
        3,
        ge=1,
        description=(
            "Fewest saturated pixels a laser spot has; smaller specks are noise. The simulated"
            " dot (SensorSettings.laser_spot_radius_px 2.5 px) saturates about 20."
        ),
    )
    laser_depth_window_px: int = Field(
        4,
        ge=1,
        description=(
            "Half-size (px) of the largest window searched for valid depth around a laser spot"
            " whose own pixel read none; no depth within it fails the spot. 004 section 5.2."
        ),
    )
    laser_beam_separation: float = Field(
        0.015,
        gt=0,
        description=(
            "Distance (m) between the dual pointer's parallel beams; the confirming beam lies"
            " this far to the aiming beam's left. 004 section 4 (the device of description/dims)."
        ),
    )
    laser_origin: tuple[float, float, float] = Field(
        (0.55, 0.12, 0.95),
        description=(
            "Roughly where the seated user holds the pointer, in `base` (m): only the beams'"
            " rough heading from it is used, to tell the aiming beam (the right one) from the"
            " confirming one. 004 section 4; the simulated hand position, description/dims."
        ),
    )
    plane_distance: float = Field(
        0.015, gt=0, description="RANSAC plane distance threshold (m). 004 section 6.1."
    )
    plane_max_tilt_deg: float = Field(
        5.0, ge=0, description="Largest angle of a removed plane from horizontal. 004 6.1."
    )
    plane_min_inliers: int = Field(
        13000,
        ge=1,
        description=(
            "Inliers a plane needs to be removed, at 004's density: five Structure sensors at"
            " full 640x480 resolution. Ours are the same sensors (640x480, same mounts), fused"
            " at every pixel_stride-th pixel, so segment.py needs 13000 / pixel_stride^2"
            " (3250 at stride 2). 004 6.1. We count only inliers whose normal faces up"
            " (within plane_candidate_tilt_deg of vertical): a band through a wall, or through"
            " object tops that line up, is not a surface."
        ),
    )
    plane_max_removed: float = Field(
        0.70, gt=0, le=1, description="Largest fraction of the cloud removed as planes. 004 6.1."
    )
    cluster_tolerance: float = Field(
        0.005, gt=0, description="Euclidean cluster extraction distance (m). 004 section 6.1."
    )
    cluster_min_points: int = Field(
        500,
        ge=1,
        description=(
            "A smaller target cluster falls back to the ball, at 004's full-resolution density;"
            " scaled like plane_min_inliers: 500 / pixel_stride^2 (125 at stride 2). 004 6.1."
        ),
    )
    fallback_ball_radius: float = Field(
        0.1, gt=0, description="Radius of the fallback ball around the mark (m). 004 6.1."
    )
    merged_fraction: float = Field(
        0.9,
        gt=0,
        le=1,
        description=(
            "A segment holding more of the points near the mark than this has merged with its"
            " support. 002 II.C."
        ),
    )
    merged_radius: float = Field(
        0.08, gt=0, description="Radius taken around the mark when the segment merged (m). 002."
    )
    grid_cell_xy: float = Field(
        0.01, gt=0, description="EL-E occupancy grid cell, x and y (m). 000 section 4.2.2."
    )
    grid_cell_z: float = Field(
        0.0025, gt=0, description="EL-E occupancy grid cell, z (m). 000 section 4.2.2."
    )
    grid_surface_margin: float = Field(
        0.0025,
        ge=0,
        description=(
            "The grid method keeps points this far (m, one grid layer) above EL-E's z_top:"
            " our depth noise above z_top otherwise joins all objects into one component."
            " Ours, on 000 4.2.2."
        ),
    )
    grid_min_object_length: float = Field(
        0.01,
        gt=0,
        description="Shorter grid components (m, along max variance) are surface noise. 000 4.2.2.",
    )
    grid_max_object_length: float = Field(
        0.5, gt=0, description="Longer grid components (m) are too large to grasp. 000 4.2.2."
    )
    histogram_bin: float = Field(
        0.0025, gt=0, description="Surface height histogram bin (m). 000 section 4.2.1."
    )
    histogram_cut: float = Field(
        0.2, gt=0, le=1, description="Bins above n_max times this are surface. 000 4.2.1."
    )
    flat_fraction: float = Field(
        0.25,
        gt=0,
        le=1,
        description=(
            "Occupied share of the volume of interest's cross-section that makes a flat"
            " surface. 000 4.4.3."
        ),
    )
    place_edge_margin: float = Field(
        0.10, ge=0, description="A place mark moves at least this far behind the edge (m). 000 4.5."
    )
    plane_candidate_tilt_deg: float = Field(
        30.0,
        gt=0,
        le=90,
        description=(
            "RANSAC draws its hypotheses only from points whose normal lies within this angle of"
            " vertical (image-space normals scatter by ~12 deg on a table). Ours, for speed."
        ),
    )
    ransac_iterations: int = Field(
        200, ge=1, description="Plane hypotheses per RANSAC round. Ours."
    )
    ransac_sample: int = Field(
        2000, ge=10, description="Points RANSAC scores hypotheses on before the full count. Ours."
    )
    cluster_crop_radius: float = Field(
        0.3,
        gt=0,
        description=(
            "Only points this close to the mark (m) are clustered; household objects are smaller."
            " It is also the neighbourhood whose points 002's 90 % rule counts. Ours."
        ),
    )
    regrow_min_height: float = Field(
        0.003,
        ge=0,
        description=(
            "Removed plane points this far above their plane (m, ~2.5 sigma of the depth noise"
            " on a table 0.9 m from the sensors) rejoin the clustering, so objects keep their"
            " bottom 1.5 cm and flat objects (a phone, a toothbrush) survive plane removal."
            " Ours."
        ),
    )
    occlusion_gap: float = Field(
        0.015,
        ge=0,
        description=(
            "A cluster this close (m) to the target that overlaps it seen from above is the"
            " same object split by an overhang the downward-looking sensors cannot see under."
            " Ours."
        ),
    )
    cluster_noise_points: int = Field(
        10,
        ge=1,
        description="Clusters smaller than this are depth noise, never the target. Ours.",
    )
    mark_object_distance: float = Field(
        0.02,
        gt=0,
        description=(
            "A mark on a support plane with no cluster this close (m) has no object at it. Ours."
        ),
    )
    mark_max_gap: float = Field(
        0.05, gt=0, description="A mark farther than this (m) from every point sees nothing. Ours."
    )
    voi_half_width: float = Field(
        0.2,
        gt=0,
        description=(
            "Half the side of the square volume of interest around a mark (m): 000 4.4.3's"
            " 1/4 of the cross-section equals 400 cm^2, so the section is 40 cm x 40 cm."
        ),
    )
    voi_below: float = Field(
        0.35,
        gt=0,
        description=(
            "The volume of interest reaches this far below the mark (m): down to the support"
            " under a mark on a 30 cm object, and above the floor under a table. Ours."
        ),
    )
    voi_above: float = Field(
        0.10, ge=0, description="The volume of interest reaches this far above the mark (m). Ours."
    )
    flat_band: float = Field(
        0.10,
        gt=0,
        description="Points within z_top +- this (m) occupy the flat-surface grid. 000 4.4.3.",
    )
    surface_band: float = Field(
        0.02,
        gt=0,
        description="Points in [z_top - this, z_top] (m) are the surface region. 000 4.3.2.",
    )
    mark_on_surface_tol: float = Field(
        0.01,
        gt=0,
        description=(
            "A place mark lies on the surface when within this (m) of its height; EL-E's VOI"
            " test alone also accepts a mark on a cup standing on a table. Ours."
        ),
    )
    recall_spacing: float = Field(
        0.15,
        gt=0,
        description="While the scooter drives, a view is kept each time it has gone this far"
        " (m) since the last (`pipeline.recall`). Ours.",
    )
    recall_turn_deg: float = Field(
        15.0, gt=0, description="... or turned this far (deg) since the last view. Ours."
    )
    recall_views: int = Field(
        8,
        ge=0,
        description="Views of the drive kept: with the spacing, the last 1.2 m of the way in,"
        " where the blind spots of the parked scooter were in view. 0 keeps none. Ours.",
    )
    recall_max_age: float = Field(
        60.0, gt=0, description="A view older than this (s of robot time) is forgotten. Ours."
    )


class GraspSettings(BaseModel):
    """Grasp selection parameters (paper 004 section 7) and the hand geometry the pipeline uses.

    The hand geometry mirrors the gripper in `laserpick.description.dims` (a test holds them equal);
    it is repeated here because pipeline/ may not import robot/.
    """

    width_min: float = Field(0.0, ge=0, description="Gripper's smallest opening W_min (m).")
    width_max: float = Field(0.085, gt=0, description="Gripper's stroke W_max (m). 2F-85.")
    finger_length: float = Field(
        0.05, gt=0, description="Finger length l, the reach of Cs (m). Eq. 6 of 004."
    )
    width_margin: float = Field(
        0.015, ge=0, description="W_d, the distance kept from the stroke's ends (m). 004 eq. 3."
    )
    joint_distance_max: float = Field(
        7.695,
        gt=0,
        description=(
            "J_m of 004 eq. 4 (rad): pi * sqrt(6), the largest joint-space distance between two"
            " configurations once each joint's difference is wrapped to [-pi, pi]."
        ),
    )
    mark_distance: float = Field(
        0.05, ge=0, description="th, the mark distance free of penalty (m). 004 eq. 7."
    )
    cluster_distance: float = Field(
        0.02,
        gt=0,
        description="Largest distance between two grasps of one cluster (m). 004 section 7.2.",
    )
    # Hand geometry for grasp detection (collision boxes); description/dims.py and robot/model.py.
    pad_depth: float = Field(
        0.022, gt=0, description="Pad extent along the approach axis (m). description/dims.py."
    )
    pad_width: float = Field(
        0.022, gt=0, description="Pad extent along the hand axis (m). description/dims.py."
    )
    pad_thickness: float = Field(
        0.008, gt=0, description="Pad thickness along the closing axis (m). description/dims.py."
    )
    finger_thickness: float = Field(
        0.008,
        gt=0,
        description="Finger plate thickness along the closing axis, outside the pad (m). "
        "robot/model.py.",
    )
    finger_width: float = Field(
        0.024,
        gt=0,
        description="Finger plate extent along the hand axis (m). robot/model.py.",
    )
    palm_width: float = Field(
        0.09, gt=0, description="Palm housing across the closing axis (m). description/dims.py."
    )
    palm_depth: float = Field(
        0.06, gt=0, description="Palm housing along the hand axis (m). description/dims.py."
    )
    palm_length: float = Field(
        0.09,
        gt=0,
        description="Palm housing along the approach axis, behind the finger roots (m). "
        "robot/model.py (GRIPPER_BASE_LENGTH less the 1 cm coupling).",
    )
    side_clearance: float = Field(
        0.004,
        ge=0,
        lt=0.02,
        description="Gap (m) kept between every seen point and the fingers' inner faces and"
        " sides and the palm's sides: GPD's detector tests a hand this much larger on each"
        " side, whose opening is this much narrower on each side; a vertical grasp needs the"
        " object this much narrower than the opening on each side. A depth camera sees a box's"
        " edge up to a few mm short of where it is, and the arm tracks its path to a few mm;"
        " with no gap a finger slid down an edge it had missed by 0.4 mm. Ours.",
    )
    free_space_tolerance: float = Field(
        0.006,
        gt=0,
        description="A depth reading shows a point free when it lies this far (m) beyond it:"
        " about three times the sensors' noise at 1.2 m. Ours.",
    )
    free_space_share: float = Field(
        0.9,
        ge=0,
        le=1,
        description="Share of a grasp's finger probes the cameras must have seen free; 0 turns"
        " the free-space test off. Ours (pipeline/free_space.py).",
    )
    # GPD candidate generation (004 section 6.2; ten Pas et al. 2017 and GPD's defaults).
    gpd_samples: int = Field(
        500, ge=1, description="Points sampled from the target to seed candidates. GPD default."
    )
    gpd_orientations: int = Field(
        8, ge=1, description="Hand rotations about the curvature axis per sample. GPD default."
    )
    gpd_finger_placements: int = Field(
        10, ge=1, description="Lateral hand offsets along the closing axis per rotation. GPD."
    )
    gpd_tilts_deg: tuple[float, ...] = Field(
        (-60.0, -30.0, 30.0, 60.0),
        description="Tilts (deg) of the hand about its closing axis, leaning the approach toward"
        " the curvature axis, tried when no untilted grasp is reachable: a low object lying"
        " pointed at the robot under a shelf's board is then taken from the front and above,"
        " across its girth. GPD 2's extra hand axes; ours for the angles.",
    )
    gpd_nn_radius: float = Field(
        0.01,
        gt=0,
        description="Neighbourhood radius (m) whose normals give a sample's local frame. GPD.",
    )
    gpd_frame_neighbours: int = Field(
        32, ge=3, description="Most neighbours used for a local frame (speed cap). Ours."
    )
    gpd_init_bite: float = Field(
        0.01,
        ge=0,
        description="How far (m) the fingertips reach past the sample before deepening. GPD.",
    )
    gpd_clearance: float = Field(
        0.002,
        ge=0,
        description="Gap (m) kept before the first contact when pushing the hand in. Ours.",
    )
    gpd_friction_deg: float = Field(
        20.0,
        gt=0,
        lt=90,
        description="Friction cone half-angle (deg) of the antipodal test. GPD's friction_coeff.",
    )
    gpd_contact_band: float = Field(
        0.003,
        gt=0,
        description="Points this close (m) to a finger's extreme contact count as contacts. "
        "GPD's extremal_thresh.",
    )
    gpd_min_contacts: int = Field(
        6, ge=1, description="Antipodal contact points needed on each side. GPD's min_viable."
    )
    gpd_tangent_deg: float = Field(
        10.0,
        gt=0,
        lt=90,
        description="A pad meets the object along its face where the object's normals at the"
        " pad's extreme lie within this angle (deg) of the closing axis"
        " (grasp_detect.closing_region). Ours.",
    )
    gpd_patch_offset: float = Field(
        0.007,
        ge=0,
        description="How far (m) along the hand axis the middle of the patch where a pad meets"
        " the object may lie from the pad's middle for the grasp to count as centred"
        " (grasp_detect.closing_region), and be offered before those that do not"
        " (selection.group): a pad that meets it only at its edge lets it spin out. Ours.",
    )
    gpd_recentre: float = Field(
        0.022,
        ge=0,
        description="How far (m) past each side of the pads a hand that is not centred"
        " (gpd_patch_offset) looks for where its pads would meet the object along their face;"
        " it is tried again turned about its axis and moved along it onto that patch"
        " (grasp_detect.patch_moves). 0 turns this off. Ours: one pad width.",
    )
    gpd_collision_voxel: float = Field(
        0.0,
        ge=0,
        description="The scene around the target is thinned to one point per voxel of this edge"
        " (m) for the collision test, for speed (2x at 5 mm), at the cost of missing points up"
        " to a voxel inside a hand box; 0 keeps every point (exact). Ours.",
    )
    gpd_min_points: int = Field(
        10, ge=1, description="Object points needed between the pads. Ours."
    )


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
    tcp_speed: float = Field(0.25, gt=0, description="TCP speed limit near people (m/s).")
    carry_joint_speed: float = Field(
        0.5,
        gt=0,
        le=3.14,
        description="Joint speed limit (rad/s) while carrying an object: a swinging object"
        " held by a rim or an edge turns in the pads. Ours.",
    )
    approach_speed: float = Field(
        0.08, gt=0, description="TCP speed (m/s) on the last, guarded approach to a grasp. Ours."
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
    cartesian_step: float = Field(
        0.01, gt=0, description="Waypoint spacing (m) of straight-line Cartesian paths."
    )
    rrt_max_samples: int = Field(
        2000, ge=10, description="Samples before the joint-space planner gives up."
    )
    rrt_step: float = Field(0.3, gt=0, description="RRT-Connect extension step (rad).")
    rrt_max_failed: int = Field(
        6,
        ge=1,
        description="Failed joint-space searches in one pick before no more grasps are tried:"
        " each takes seconds, and a user should not wait minutes for a 'no'. Ours.",
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


class ServerSettings(BaseModel):
    """The operator session and its API (safety timings, input limits)."""

    lease_timeout_s: float = Field(
        5.0, gt=0, description="The control lease lapses after this long without a heartbeat (s)."
    )
    watchdog_s: float = Field(
        0.5,
        gt=0,
        le=2.0,
        description="Arm or base motion halts when the controller is silent this long (s)."
        " Issue 5.",
    )
    events_hz: float = Field(
        30.0, ge=1.0, le=100.0, description="State frames per second on the events websocket."
    )
    max_body_bytes: int = Field(
        8_000_000, gt=0, description="Largest request body (bytes): a scene with its meshes."
    )
    max_nudge: float = Field(
        0.2, gt=0, description="Largest laser nudge per command (rad), about 11 degrees."
    )
    max_reach: float = Field(
        5.0, gt=0, description="Aim points farther than this from `base`'s origin are refused (m)."
    )
    cloud_voxel: float = Field(
        0.01, gt=0, description="Voxel (m) the cloud is thinned to for GET /cloud."
    )
    seed: int = Field(0, description="Seed of the session's random draws (planner, sampling).")


class Settings(BaseSettings):
    """All of laserpick's tunable defaults."""

    model_config = SettingsConfigDict(env_prefix="LASERPICK_", env_nested_delimiter="__")

    sim: SimSettings = SimSettings()
    sensor: SensorSettings = SensorSettings()
    perception: PerceptionSettings = PerceptionSettings()
    grasp: GraspSettings = GraspSettings()
    approach: ApproachSettings = ApproachSettings()
    motion: MotionSettings = MotionSettings()
    server: ServerSettings = ServerSettings()
    operator_password: SecretStr | None = Field(
        None,
        description="Password for taking control (LASERPICK_OPERATOR_PASSWORD). Required to"
        " bind anything but the loopback interface.",
    )


@lru_cache(maxsize=1)
def get_settings() -> Settings:
    """The process-wide settings, read once from the environment."""
    return Settings()
