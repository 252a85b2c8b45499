"""GPD-style grasp candidates (paper 004 section 6.2; ten Pas et al., "Grasp Pose Detection
in Point Clouds", 2017), geometric part only: sample the target, build a local frame at each
sample, rotate and slide the hand there, push it in until just before contact, and keep the
collision-free hands whose pads close antipodally on the object. GPD's learned classifier is
not reproduced; the antipodal test (GPD's own labelling rule) stands in for it.

Frames: everything is in `base` (x forward, y left, z up), metres. A hand frame has the hand
axis (x), the closing axis (y, between the fingers) and the approach axis (z, palm toward the
object); a point's hand coordinates are (h, c, a) along those axes. The TCP lies midway between
the pads' centres, pad_depth / 2 behind the fingertips.

Hand model: the gripper's boxes, `description.dims.GRIPPER_HAND` (`HandGeometry`): two
fingers, each a box from the inner pad face (at +-width_max / 2 from the hand centre when
open) outward by pad + plate thickness, finger_length deep along the approach and
finger_width along the hand axis; behind the finger roots a palm box palm_width x palm_depth
x palm_length. The detector tests that hand grown by side_clearance on its sides
(cleared_hand), so a real hand clears what was seen.

Speed: every (sample, orientation) pair is one "frame". Scene points are binned by their
closing coordinate per frame (np.minimum.at), so each finger placement's deepest collision-free
depth is a min over a few bins rather than a pass over the points. Bin edges are placed on the
fingers' inner faces, so the faces that touch the object are exact; the outer faces and the
palm's sides are conservative by less than one bin (width_max / placements / 4, ~2 mm).

Three shortcuts make it 15-50x faster (bench/grasp_detect_speed.py) without changing the
result beyond float32 rounding of the coordinates (~1e-8 m):
- The antipodal test is bounded first (antipodal_possible): a frame whose pads could not
  hold enough contacts at any depth and placement needs no collision test. On the captured
  objects that is 88-100 % of the frames (a clean synthetic cylinder: only 15 %).
- Collisions are bounded with voxels (pruned_tips, a branch and bound): each voxel's
  representative is a scene point, so it bounds the stops from above; its radius bounds its
  other points' depths from below; only the voxels that could still lower a free placement's
  stop are opened. deepest_tips is the direct computation it reproduces.
- numpy is used in cache-sized blocks with the long axis innermost, selecting before
  computing, with np.take rather than fancy indexing: on a small machine, large temporaries
  and 2-D fancy indexing cost more than the arithmetic. np.minimum.at itself is cheap
  (numpy >= 1.25 has a fast path for it; sorting for np.minimum.reduceat is slower).

Modules: `frames` (samples, local frames, orientations), `neighbourhoods` (points near each
sample, in its frame), `closing_grid` (the hand's depth per placement, directly),
`voxel_pruning` (the same, bounded with voxels), `antipodal` (the closing region and the
antipodal test), `hand` (the cleared hand, its regions and poses), `candidates` (what passed),
`recentre` (the second pass), `square` (the last: pads square to the faces they meet),
`detector` (`detect_grasps`).
"""

from laserpick.pipeline.gpd.candidates import HandCandidates
from laserpick.pipeline.gpd.detector import CandidateSearch, detect_grasps
from laserpick.pipeline.gpd.hand import cleared_hand

__all__ = ["CandidateSearch", "HandCandidates", "cleared_hand", "detect_grasps"]
