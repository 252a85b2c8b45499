"""Named dimensions and hardware limits of the simulated robot: the one place they live.

Everything is SI (metres, radians, seconds, kilograms, newtons). Poses are given in the
scooter's `base` frame: x forward, y left, z up, origin on the floor under the centre of
the rear axle. The model builder, the controllers and the safety checks all read from here,
so a limit is never restated elsewhere.

Sources: UR5 DH parameters and datasheet (Universal Robots); Robotiq 2F-85 datasheet;
paper 004 (Wang et al.) section 3 and 5.1 for the scooter, sensors, laser and projector.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# --- UR5 arm ---------------------------------------------------------------------------------

#: Standard DH parameters of the UR5 (metres and radians), joints 1..6.
UR5_D = (0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823)
UR5_A = (0.0, -0.425, -0.39225, 0.0, 0.0, 0.0)
UR5_ALPHA = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)

UR5_JOINT_NAMES = (
    "shoulder_pan",
    "shoulder_lift",
    "elbow",
    "wrist_1",
    "wrist_2",
    "wrist_3",
)
#: Joint position limits (rad): +-2pi everywhere except the elbow, +-pi.
UR5_Q_MIN = np.array(
    [-2 * math.pi, -2 * math.pi, -math.pi, -2 * math.pi, -2 * math.pi, -2 * math.pi]
)
UR5_Q_MAX = -UR5_Q_MIN
#: Maximum joint speed of the UR5 (rad/s), all joints.
UR5_QD_MAX = 3.14
#: Joint acceleration limit used for time parametrization (rad/s^2).
UR5_QDD_MAX = 3.0
#: Link masses (kg) from the UR5 datasheet: base, shoulder, upper arm, forearm, wrist 1, 2, 3.
UR5_LINK_MASSES = (4.0, 3.7, 8.393, 2.275, 1.219, 1.219, 0.1879)
#: Capsule radii (m) of the collision geometry of each link.
UR5_LINK_RADII = (0.075, 0.06, 0.054, 0.045, 0.045, 0.045, 0.04)
#: Peak joint torques (N m): 150 for the base joints, 28 for the wrists (datasheet sizes).
UR5_TORQUE_MAX = (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)
#: Force from outside on the arm, the hand or what it holds (N) beyond which the controller
#: makes a protective stop on any motion: a UR controller's default safety limit (150 N).
#: The guarded approach and lowering stop far sooner (`MotionSettings.guard_force`).
UR5_PROTECTIVE_STOP_FORCE = 150.0

#: Folded down and back along the scooter's right side, gripper down: out of the depth
#: cameras' view of the workspace (only right_55 sees part of it) and clear of the basket (rad).
UR5_HOME_Q = np.array([-2.6, 0.6, -2.4, 0.23, -1.5708, 0.0])
#: The way out of the stowed pose and back: just ahead of the scooter's front right corner,
#: elbow still down as at home, gripper down, the TCP at about (1.20, -0.55, 0.80) in `base`.
#: The space beside the scooter is space no depth camera sees. The straight joint move from
#: home keeps the hand (TCP) within 0.34 m of the scooter's side and 0.15 m of its front; the
#: straight moves on to the ready poses turn the elbow over in front, the hand up to 1.22 m
#: high and 0.66 m ahead. All three are clear of the scooter. The move to ready straight from
#: home would turn it over out to the side instead, the hand 0.57 m out and 0.68 m ahead,
#: where the cameras do not see (rad).
UR5_UNSTOW_Q = np.array([-1.773, -0.338, -1.967, 0.734, -1.571, -0.203])
#: Holding an object while the user drives and marks where it goes (pick and place): folded
#: back along the scooter's right side, gripper down, the TCP at about (0.90, -0.65, 0.95) in
#: `base`. The upper arm stays behind the sensor posts (x <= 1.10) and the whole arm within
#: x <= 1.23 and y >= -0.71, and an object up to 25 cm long and 5 cm in radius hangs clear of
#: the arm and the scooter (found by a search over the side, nearest the high ready pose).
UR5_CARRY_Q = np.array([-2.432, -1.182, 0.68, 2.074, 1.571, 1.211])
#: Where the empty arm waits between picks: the carry pose, on the ready poses' elbow-up
#: branch. From the stowed pose the elbow turns over (3.3 rad, 7.6 s to ready at the limits
#: near people); from here it does not (4.0 s). Out of the cameras' view of the workspace and
#: within the footprint the scooter drives with while it carries (rad).
UR5_STANDBY_Q = UR5_CARRY_Q
#: The way out of standing by where neither ready pose is clear (a shelf's boards, a high
#: table): the hand where the unstow pose holds it, ahead of the scooter's front right
#: corner, gripper down, but elbow up. From standing by the way to a ready pose is direct
#: (4.0 s); through here it is 4.4 s (rad).
UR5_STANDBY_EXIT_Q = np.array([-1.722, -1.524, 1.479, 1.616, 1.571, 1.211])
#: Raised in front, elbow up, gripper pointing down with the TCP at about (1.50, -0.30, 0.85)
#: in `base`: the transit pose between home and any grasp above the workspace. Far enough
#: forward that the elbow clears the right sensor housings by 3 cm (rad).
UR5_READY_Q = np.array([-0.308, -1.453, 1.299, 1.725, 1.571, 1.263])
#: Like ready, 15 cm higher (TCP at about (1.45, -0.30, 1.00)): the transit pose over a
#: high table, where the ready pose's hand would be among the objects (rad).
UR5_HIGH_READY_Q = np.array([-0.36, -1.444, 0.877, 2.138, 1.571, 1.211])

# --- Gripper (Robotiq 2F-85-like parallel jaw) ------------------------------------------------

GRIPPER_STROKE = 0.085  #: full opening between the pads (m)
GRIPPER_FORCE_MAX = 100.0  #: closing force limit per finger (N); the 2F-85 does 20-235 N
GRIPPER_SPEED = 0.15  #: finger closing speed (m/s), the 2F-85's upper figure
GRIPPER_BASE_LENGTH = 0.10  #: flange to finger root (m), the gripper body
GRIPPER_FINGER_LENGTH = 0.05  #: finger root to fingertip (m)
GRIPPER_PAD_DEPTH = 0.022  #: pad extent along the approach axis (m)
GRIPPER_PAD_WIDTH = 0.022  #: pad extent along the hand axis (m)
GRIPPER_PAD_THICKNESS = 0.008  #: pad thickness along the closing axis (m)
GRIPPER_FINGER_THICKNESS = 0.008  #: finger plate along the closing axis, outside the pad (m)
GRIPPER_FINGER_WIDTH = 0.024  #: finger plate extent along the hand axis (m)
GRIPPER_BODY_WIDTH = 0.09  #: palm housing across the closing axis (m)
GRIPPER_BODY_DEPTH = 0.06  #: palm housing along the hand axis (m)
#: Palm housing along the approach axis, behind the finger roots (m): the gripper body less
#: its 1 cm coupling to the flange.
GRIPPER_PALM_LENGTH = 0.09
#: Flange to TCP (m): the TCP sits midway between the pad centres.
GRIPPER_TCP_OFFSET = GRIPPER_BASE_LENGTH + GRIPPER_FINGER_LENGTH - GRIPPER_PAD_DEPTH / 2
GRIPPER_MASS = 0.9  #: kg, the 2F-85 datasheet
PAD_FRICTION = (1.5, 0.02, 0.001)  #: sliding, torsional, rolling: rubber pads
#: A finger gap below this (m) with the gripper commanded closed means it closed on nothing.
GRIPPER_EMPTY_GAP = 0.003
#: Summed pad contact normal force (N) above which the gripper counts as holding.
GRIPPER_HOLD_FORCE = 2.0


@dataclass(frozen=True)
class HandGeometry:
    """The open gripper as boxes, for grasp detection and the grasp tests (m), in a hand
    frame: x the hand axis, y the closing axis (between the fingers), z the approach.

    Two fingers, each a box from the inner pad face (at +-width_max / 2 from the hand centre
    when open) outward by pad_thickness + finger_thickness, finger_length deep along the
    approach and finger_width along the hand axis, with a pad pad_depth x pad_width at its
    tip; behind the finger roots a palm box palm_width (closing) x palm_depth (hand axis) x
    palm_length (approach). The TCP lies midway between the pads' centres, pad_depth / 2
    behind the fingertips.
    """

    width_max: float  #: the stroke: the opening between the pads (m)
    finger_length: float  #: finger root to fingertip (m)
    pad_depth: float  #: pad extent along the approach axis (m)
    pad_width: float  #: pad extent along the hand axis (m)
    pad_thickness: float  #: pad thickness along the closing axis (m)
    finger_thickness: float  #: finger plate along the closing axis, outside the pad (m)
    finger_width: float  #: finger plate extent along the hand axis (m)
    palm_width: float  #: palm across the closing axis (m)
    palm_depth: float  #: palm along the hand axis (m)
    palm_length: float  #: palm along the approach axis, behind the finger roots (m)


#: The gripper above, as boxes.
GRIPPER_HAND = HandGeometry(
    width_max=GRIPPER_STROKE,
    finger_length=GRIPPER_FINGER_LENGTH,
    pad_depth=GRIPPER_PAD_DEPTH,
    pad_width=GRIPPER_PAD_WIDTH,
    pad_thickness=GRIPPER_PAD_THICKNESS,
    finger_thickness=GRIPPER_FINGER_THICKNESS,
    finger_width=GRIPPER_FINGER_WIDTH,
    palm_width=GRIPPER_BODY_WIDTH,
    palm_depth=GRIPPER_BODY_DEPTH,
    palm_length=GRIPPER_PALM_LENGTH,
)

# --- Scooter (Merits Pioneer 10-like) ---------------------------------------------------------

SCOOTER_LENGTH = 1.2
SCOOTER_WIDTH = 0.6
SCOOTER_REAR_OVERHANG = 0.15  #: rear axle to the back edge (m)
SCOOTER_DECK_HEIGHT = 0.30  #: top of the deck above the floor (m)
SCOOTER_DECK_THICKNESS = 0.12
WHEEL_RADIUS = 0.13
WHEEL_WIDTH = 0.08
WHEEL_TRACK = 0.56  #: distance between the rear wheel centres (m)
CASTER_X = 0.95  #: front caster position (m)
CASTER_RADIUS = 0.08
SEAT_X = 0.15
SEAT_HEIGHT = 0.62  #: seat cushion top (m)
SEAT_BACK_HEIGHT = 1.05
TILLER_X = 0.86  #: steering column position at the handlebars (m)
#: The steering column leans back: its foot on the deck is this far ahead of its top (m).
TILLER_FOOT_AHEAD = 0.04
TILLER_RADIUS = 0.04
HANDLEBAR_HEIGHT = 0.92
HANDLEBAR_WIDTH = 0.55
#: Basket on the handlebars: centre (m, base frame), inner size (m), wall thickness (m).
BASKET_CENTER = np.array([0.99, 0.13, 0.80])
BASKET_INNER = np.array([0.20, 0.32, 0.16])
BASKET_WALL = 0.008
#: The top of the basket's floor (m, base frame z).
BASKET_FLOOR = BASKET_CENTER[2] - BASKET_INNER[2] / 2
#: m. The basket's floor is thicker than its walls: a thin, light object let go above it
#: (a remote, a tissue packet) falls 5 mm per 2 ms physics step, and through a floor as thin
#: as the walls in one step. Its top is at the walls' foot.
BASKET_FLOOR_THICKNESS = 0.03
SCOOTER_MASS = 110.0

#: Base drive limits: linear and angular speed and acceleration.
BASE_V_MAX = 1.0  #: m/s (a scooter can do more; this is the indoor limit)
BASE_W_MAX = 1.0  #: rad/s
BASE_A_MAX = 0.6  #: m/s^2
BASE_ALPHA_MAX = 1.5  #: rad/s^2

#: Arm mount: the UR5 base frame in `base` (m). Front of the scooter, right of the tiller,
#: low enough to reach the floor and high enough for a 100 cm shelf.
ARM_MOUNT_POS = np.array([1.14, -0.30, 0.50])
#: rad. The DH base frame's -x is the direction the stretched arm points at q = 0, so a half
#: turn makes shoulder_pan = 0 face forward.
ARM_MOUNT_YAW = math.pi

# --- Depth sensors (004 section 5.1) ---------------------------------------------------------


@dataclass(frozen=True)
class CameraMount:
    """A depth sensor on the scooter: position in `base` (m), pitch down and yaw inward (rad)."""

    name: str
    pos: tuple[float, float, float]
    pitch_down: float
    yaw: float  #: rotation about +z; positive turns left


SENSOR_X = 1.08  #: the sensor posts stand beside the basket, cameras just ahead of it (m)
SENSOR_LOW_HEIGHT = 1.14
SENSOR_HIGH_HEIGHT = 1.56
SENSOR_GROUP_SPACING = 0.63
SENSOR_INWARD = math.radians(20.0)
_Y = SENSOR_GROUP_SPACING / 2
CAMERA_MOUNTS = (
    # Left group (y > 0) turns right (negative yaw) to look inward; right group mirrors it.
    CameraMount("left_25", (SENSOR_X, _Y, SENSOR_LOW_HEIGHT), math.radians(25), -SENSOR_INWARD),
    CameraMount(
        "left_55", (SENSOR_X, _Y, SENSOR_LOW_HEIGHT - 0.06), math.radians(55), -SENSOR_INWARD
    ),
    CameraMount("right_25", (SENSOR_X, -_Y, SENSOR_LOW_HEIGHT), math.radians(25), SENSOR_INWARD),
    CameraMount(
        "right_55", (SENSOR_X, -_Y, SENSOR_LOW_HEIGHT - 0.06), math.radians(55), SENSOR_INWARD
    ),
    # The fifth sensor stands higher, on the left post, to see shelf tops and tall tables.
    CameraMount(
        "high_44", (SENSOR_X - 0.1, _Y, SENSOR_HIGH_HEIGHT), math.radians(44), -SENSOR_INWARD
    ),
)
#: Structure-sensor-like intrinsics: 640x480, about 58 deg x 45 deg field of view.
DEPTH_WIDTH = 640
DEPTH_HEIGHT = 480
DEPTH_FOVY = math.radians(45.0)  #: vertical field of view; horizontal follows from square pixels
DEPTH_MIN = 0.35  #: m, nearest valid depth
DEPTH_MAX = 3.5  #: m, farthest valid depth

# --- Projector and laser ------------------------------------------------------------------

#: The projector hangs on a bracket from the tall left sensor post over the scooter's middle,
#: aimed down and to the right at the workspace in front of the arm. Its short throw (38 deg
#: vertical) lights the whole reachable 46 cm table top (x 1.32-1.78, y -0.58-0.28 m).
PROJECTOR_POS = (0.98, 0.05, 1.38)
PROJECTOR_PITCH_DOWN = math.radians(59.0)
PROJECTOR_YAW = math.radians(-20.0)
PROJECTOR_WIDTH = 1280  #: pixels (EPSON H801A-like WXGA panel)
PROJECTOR_HEIGHT = 800
PROJECTOR_FOVY = math.radians(38.0)

#: The laser pointer is held by the seated user, roughly at hand height in front of the seat.
LASER_ORIGIN = (0.55, 0.12, 0.95)
LASER_BEAM_SEPARATION = 0.015  #: m between the two parallel beams
LASER_MAX_RANGE = 5.0  #: m
LASER_YAW_LIMIT = math.radians(80.0)
LASER_PITCH_MIN = math.radians(-85.0)  #: negative = down
LASER_PITCH_MAX = math.radians(30.0)
