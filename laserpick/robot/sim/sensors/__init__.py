"""The five simulated depth sensors (paper 004, section 5.1): depth and IR frames.

Each capture renders every camera once with MuJoCo's offscreen renderer in segmentation mode,
which gives, from one pass, the z-buffer (metric depth) and a geom id per pixel. A noise model
fitted loosely to structured-light sensors (Occipital Structure) then turns the exact depth
into what the pipeline gets, and an IR intensity image is synthesised with the laser dots in it.

What the sensors see, by geom group (see `laserpick.robot.sim.objects.groups`):

* 0 surfaces and opaque objects, 1 the robot: seen, with noise.
* 2 transparent objects: not seen at all. Structured light passes through clear plastic, so
  the depth image shows the table behind them (and so does the laser, see `laser.py`).
* 3 specular objects: seen with about `specular_dropout` of their pixels missing, in blobs.
* 4 and 5 (markers, sites): hidden.

Noise model, in this order, per camera and capture (parameters in `SensorSettings`):

1. Edge dropouts: a pixel whose exact depth differs from a 4-neighbour's by more than
   `edge_dropout_jump` (m) is dropped with chance `edge_dropout_prob`, as a structured-light
   sensor loses the pattern at depth discontinuities.
2. Specular dropouts: a smooth random field (Gaussian noise on a grid of `specular_blob_px`
   cells, interpolated bilinearly) is thresholded per specular geom at its `specular_dropout`
   quantile over that geom's pixels, so each shiny object loses that fraction of its pixels in
   blobs about a cell across, like the highlights that blind a real sensor.
3. Depth noise: Gaussian, sigma = `depth_noise_k` * z^2 (m), the structured-light law.
   The per-pixel standard normals (for this, the edge dropouts and the IR noise) are slices at
   random offsets of one pool drawn at the first capture, because drawing 300k fresh normals
   costs ~5 ms each time; pixels within a frame stay independent.
4. Range: readings below `dims.DEPTH_MIN` or beyond `dims.DEPTH_MAX` become 0 (missing).

The IR image: a surface's brightness falls with the square of distance and with the cosine of
the angle between its normal and the viewing ray (from the depth image's gradients), scaled by a
per-geom reflectance from its colour, plus `ir_noise`. It is 0 where no surface lies within
range, and mostly 25-165 elsewhere, so a saturated laser dot stands out. Each laser hit that a
camera sees unoccluded is drawn as a Gaussian dot saturated (255) out to
`laser_spot_radius_px`. The IR image shows surfaces where depth dropped out (edges, specular
blobs): the IR camera sees them; only the pattern decoding failed there.

Frames: `DepthFrame.K` follows OpenCV (pixel centres at integer coordinates, x right, y down),
so the principal point is ((W-1)/2, (H-1)/2): MuJoCo renders the optical axis through the
centre of the image, i.e. the corner between the four middle pixels. `T_base_cam` is the
optical frame in `base`: MuJoCo's camera frame (looking along -z, +y up) times diag(1, -1, -1).

Threading: the OpenGL context belongs to the thread that creates it, and this class creates
it lazily on the first capture. Use one `DepthCameras` from one thread only (the capture
thread); it raises if called from another. MuJoCo's GL backend must be chosen before mujoco
is first imported (`laserpick.robot.gl_backend`). If the GL setup fails, every capture of the
process raises `RenderingUnavailable` without trying again (a second try can abort it).
"""

from laserpick.robot.sim.sensors.cameras import CAM_TO_OPTICAL, DepthCameras
from laserpick.robot.sim.sensors.ir import (
    IR_AMBIENT,
    IR_GAIN,
    IR_MAX_SCENE,
    IR_REF_Z,
    IR_STEP,
    LASER_VISIBLE_TOL,
    IrShading,
    draw_laser_dots,
)
from laserpick.robot.sim.sensors.noise import NOISE_POOL, SensorNoise, noisy_depth
from laserpick.robot.sim.sensors.render import (
    DEPTH_GEOMGROUP,
    LABEL_GEOMGROUP,
    RenderingUnavailable,
    SegmentationRenderer,
    render_option,
)

__all__ = [
    "CAM_TO_OPTICAL",
    "DEPTH_GEOMGROUP",
    "IR_AMBIENT",
    "IR_GAIN",
    "IR_MAX_SCENE",
    "IR_REF_Z",
    "IR_STEP",
    "LABEL_GEOMGROUP",
    "LASER_VISIBLE_TOL",
    "NOISE_POOL",
    "DepthCameras",
    "IrShading",
    "RenderingUnavailable",
    "SegmentationRenderer",
    "SensorNoise",
    "draw_laser_dots",
    "noisy_depth",
    "render_option",
]
