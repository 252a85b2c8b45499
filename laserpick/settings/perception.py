"""Perception: laser spots, fusion, segmentation, views kept on the way (004, 000, 002)."""

from __future__ import annotations

from pydantic import BaseModel, Field

__all__ = ["PerceptionSettings"]


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
    fragment_gap_ratio: float = Field(
        1.5,
        ge=0,
        description=(
            "A cluster too small to be an object (under 500 / pixel_stride^2 points) joins the"
            " target when this many times the local spacing of the target's points (the"
            " distance to their 4th nearest neighbour) from it: where the cameras see a"
            " surface from afar or at a grazing angle its points thin out and the 5 mm"
            " clustering splits it. 0 turns it off. Ours."
        ),
    )
    fragment_gap_max: float = Field(
        0.01,
        ge=0,
        description=(
            "The farthest (m) a fragment may lie from the target and join it, however sparse"
            " the points: twice 004's 5 mm. Ours."
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
