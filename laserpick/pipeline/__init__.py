"""Perception and decisions as plain functions: arrays and small dataclasses in, the same out.
It sees only what a real robot's sensors give (depth and IR frames, joint angles) and the
robot's description; it imports neither the simulator nor the robot.

The flow of a pick: `perceive` (fuse the depth frames, find the laser mark, segment the
target) -> `find_grasps` (candidates by strategy, among them GPD's `detect_grasps`; the
reachability filter; 004's score and clusters) -> `plan_first` (the best grasp's pick
planned alone, then the transit searched toward all the others at once, until one plans;
`plan_pick` plans one grasp's; checked with a `CollisionChecker`). A place asks `place_target`
for where to set the object down. Frames: `base` (x forward, y left, z up), metres, radians.
"""

from laserpick.pipeline.approach import centroid_approach
from laserpick.pipeline.cloud import fuse, ray_hit, voxel_downsample
from laserpick.pipeline.collision import CollisionChecker
from laserpick.pipeline.first_plan import plan_first
from laserpick.pipeline.gpd import detect_grasps
from laserpick.pipeline.grasp_choice import GraspSet, find_grasps
from laserpick.pipeline.joint_search import joint_path
from laserpick.pipeline.laser_mark import detect_mark
from laserpick.pipeline.lines import cartesian_line
from laserpick.pipeline.motion_limits import motion_limits, timed
from laserpick.pipeline.perceive import Perception, perceive
from laserpick.pipeline.plan import PickPlan, plan_pick
from laserpick.pipeline.projector import highlight_disc, highlight_points
from laserpick.pipeline.reach import reachable
from laserpick.pipeline.recall import Recalled, ViewMemory
from laserpick.pipeline.segment import segment_target
from laserpick.pipeline.selection import GraspClusters, GraspCursor, group, score
from laserpick.pipeline.surface import place_target, surface_height

__all__ = [
    "CollisionChecker",
    "GraspClusters",
    "GraspCursor",
    "GraspSet",
    "Perception",
    "PickPlan",
    "Recalled",
    "ViewMemory",
    "cartesian_line",
    "centroid_approach",
    "detect_grasps",
    "detect_mark",
    "find_grasps",
    "fuse",
    "group",
    "highlight_disc",
    "highlight_points",
    "joint_path",
    "motion_limits",
    "perceive",
    "place_target",
    "plan_first",
    "plan_pick",
    "ray_hit",
    "reachable",
    "score",
    "segment_target",
    "surface_height",
    "timed",
    "voxel_downsample",
]
