"""Grasp detection and selection (paper 004 section 7, GPD)."""

from __future__ import annotations

from pydantic import BaseModel, Field

__all__ = ["GraspSettings"]


class GraspSettings(BaseModel):
    """Grasp detection (GPD) and selection parameters (paper 004 sections 6.2 and 7).

    The hand's geometry is not a setting: it is the gripper's, `description.dims.GRIPPER_HAND`.
    """

    width_min: float = Field(
        0.0, ge=0, description="W_min of 004 eq. 3, the smallest opening (m); W_max is the stroke."
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
    side_clearance: float = Field(
        0.004,
        ge=0,
        lt=0.02,
        description="Gap (m) kept between every seen point and the fingers' inner faces and"
        " sides and the palm's sides: GPD's detector tests a hand this much larger on each"
        " side, whose opening is this much narrower on each side; a vertical grasp needs the"
        " object this much narrower than the opening on each side. A depth camera sees a box's"
        " edge up to a few mm short of where it is, and the arm tracks its path to a few mm."
        " Ours.",
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
    balance_lever: float = Field(
        0.02,
        ge=0,
        description="Farthest (m) a grasp may hold the object's seen middle from the line"
        " between its fingers, as gravity sees it (`pipeline.balance`), and still count as"
        " across the middle: grasps farther off are offered after the others, and where GPD's"
        " reachable grasps are all farther off, its pass on the target completed by symmetry"
        " runs too. A person holds a remote across its middle. 0 turns it off. Ours.",
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
        " (gpd.antipodal.closing_region). Ours.",
    )
    gpd_patch_offset: float = Field(
        0.007,
        ge=0,
        description="How far (m) along the hand axis the middle of the patch where a pad meets"
        " the object may lie from the pad's middle for the grasp to count as centred"
        " (gpd.antipodal.closing_region), and be offered before those that do not"
        " (selection.group): a pad that meets it only at its edge lets it spin out. Ours.",
    )
    gpd_recentre: float = Field(
        0.022,
        ge=0,
        description="How far (m) past each side of the pads a hand that is not centred"
        " (gpd_patch_offset) looks for where its pads would meet the object along their face;"
        " it is tried again turned about its axis and moved along it onto that patch"
        " (gpd.recentre.patch_moves). 0 turns this off. Ours: one pad width.",
    )
    gpd_square: bool = Field(
        True,
        description="Turn each hand whose pads meet the object's faces at a slant about its"
        " approach square to them (gpd.square): pads on a box's sides at a slant hold it on"
        " two diagonal edges, about which it turns while carried. Ours.",
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
