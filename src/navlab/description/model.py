"""The robot model that description loading produces and the simulator consumes.

Plain dataclasses, in SI units and REP-103 frames. Poses are ``(xyz, rpy)`` of a child frame in
its parent frame (URDF ``<origin>`` semantics). Loading (xacro/URDF/<gazebo>) fills these; the
MuJoCo builder in ``navlab.sim`` reads them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal, TypeGuard, get_args

import numpy as np

from navlab.geometry import Pose6, compose6, matrix_from_pose6, pose6_from_matrix

if TYPE_CHECKING:
    from navlab.description.sensor_model import SensorSuite

Vec3 = tuple[float, float, float]

GeometryKind = Literal["box", "cylinder", "sphere", "mesh"]


def is_geometry_kind(kind: str) -> TypeGuard[GeometryKind]:
    """Whether ``kind`` names a geometry (box, cylinder, sphere, mesh)."""
    return kind in get_args(GeometryKind)


@dataclass(frozen=True)
class Origin:
    """A pose of a child frame in its parent: translation (m) and roll-pitch-yaw (rad, fixed axes)."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)

    def as_pose6(self) -> Pose6:
        """(x, y, z, roll, pitch, yaw)."""
        return (*self.xyz, *self.rpy)

    @classmethod
    def from_pose6(cls, pose: Pose6 | tuple[float, ...]) -> Origin:
        """An origin from (x, y, z, roll, pitch, yaw)."""
        p = tuple(float(v) for v in pose)
        return cls(xyz=(p[0], p[1], p[2]), rpy=(p[3], p[4], p[5]))

    @classmethod
    def from_matrix(cls, m: np.ndarray) -> Origin:
        """An origin from a 4×4 homogeneous matrix."""
        return cls.from_pose6(pose6_from_matrix(m))

    def matrix(self) -> np.ndarray:
        """4×4 homogeneous ``parent_T_child``."""
        return matrix_from_pose6(self.as_pose6())

    def then(self, child: Origin) -> Origin:
        """``self ∘ child``: the pose of ``child`` (given in this frame) in this frame's parent."""
        return Origin.from_pose6(compose6(self.as_pose6(), child.as_pose6()))


@dataclass(frozen=True)
class Geometry:
    """A shape. ``size``: box full extents (x, y, z); cylinder (radius, length) along z; sphere (radius,).

    Meshes: ``mesh_path`` is an absolute path to an STL or OBJ file, already resolved from
    ``package://``/``file://``/``model://`` (a COLLADA ``.dae`` is converted to a cached OBJ and named
    in ``mesh_source``); ``mesh_scale`` includes any COLLADA unit scale. ``convex`` is filled by the
    world loader for collision meshes (None: not checked).
    """

    kind: GeometryKind
    size: tuple[float, ...] = ()
    mesh_path: Path | None = None
    mesh_scale: Vec3 = (1.0, 1.0, 1.0)
    # Added by the description/world loaders:
    mesh_source: Path | None = None  # the file the description named (e.g. a .dae converted to mesh_path)
    convex: bool | None = None  # meshes: True if the mesh is its own convex hull; False: needs decomposition


@dataclass(frozen=True)
class Inertial:
    """Mass (kg), centre of mass origin, and inertia tensor (kg m², about the COM in ``origin``'s frame)."""

    mass: float
    origin: Origin = Origin()
    ixx: float = 0.0
    ixy: float = 0.0
    ixz: float = 0.0
    iyy: float = 0.0
    iyz: float = 0.0
    izz: float = 0.0


@dataclass(frozen=True)
class Shape:
    """A collision or visual element: geometry at an origin in the link frame."""

    geometry: Geometry
    origin: Origin = Origin()
    rgba: tuple[float, float, float, float] | None = None
    name: str = ""


@dataclass
class Link:
    """A rigid body. ``mu1``/``mu2`` are Gazebo's friction coefficients (None: simulator default); ``contact``
    the rest of its ``<gazebo reference>`` ODE contact tags (None: Gazebo's defaults)."""

    name: str
    inertial: Inertial | None = None
    collisions: list[Shape] = field(default_factory=list)
    visuals: list[Shape] = field(default_factory=list)
    mu1: float | None = None
    mu2: float | None = None
    contact: ContactTags | None = None


@dataclass
class ContactTags:
    """Gazebo/ODE contact tags of a link (``<gazebo reference="link">``); None = not given (ODE's default).

    ``kp`` contact stiffness (N/m), ``kd`` contact damping (N s/m), ``min_depth`` penetration allowed before the
    contact pushes back (m), ``max_vel`` the fastest the contact corrects penetration (m/s), ``fdir1`` the
    direction of ``mu1`` in the link frame (mu2 acts across it)."""

    kp: float | None = None
    kd: float | None = None
    min_depth: float | None = None
    max_vel: float | None = None
    fdir1: tuple[float, float, float] | None = None


JointType = Literal["fixed", "continuous", "revolute", "prismatic", "floating", "planar"]


def is_joint_type(kind: str) -> TypeGuard[JointType]:
    """Whether ``kind`` is a URDF joint type."""
    return kind in get_args(JointType)


@dataclass
class Joint:
    """A URDF joint: ``origin`` is the child frame in the parent link frame; ``axis`` in the child frame."""

    name: str
    type: JointType
    parent: str
    child: str
    origin: Origin = Origin()
    axis: Vec3 = (1.0, 0.0, 0.0)
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    damping: float = 0.0
    friction: float = 0.0


@dataclass
class DiffDriveConfig:
    """Gazebo's differential-drive plugin (ROS 1 ``libgazebo_ros_diff_drive`` and ROS 2 spellings)."""

    left_joint: str = "left_wheel_hinge"
    right_joint: str = "right_wheel_hinge"
    wheel_separation: float = 0.34
    wheel_diameter: float = 0.15
    max_torque: float = 5.0  # N m per wheel
    max_accel: float = 0.0  # m/s² at the wheel rim (as Gazebo applies wheelAcceleration); 0 = unlimited
    update_rate: float = 100.0  # Hz
    command_topic: str = "cmd_vel"
    odometry_topic: str = "odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_source: Literal["encoder", "world"] = "world"
    publish_tf: bool = True  # <publishOdomTF>: tf odom -> base
    publish_odom: bool = True  # Noetic's <publishTf>: false publishes neither the odometry topic nor its tf
    publish_wheel_tf: bool = False
    # navlab extension (not a Gazebo tag; gazebo node parameter cmd_timeout): s without cmd_vel before the
    # wheels are stopped; 0 = off, as in ROS 1's plugin (the last command holds until a new one)
    cmd_timeout: float = 0.0
    namespace: str = ""
    # Kinetic's <legacyMode> (the joints' turning roles swapped); Noetic's plugin has no such option, so the
    # tags never set it (a <legacyMode> tag is ignored with a warning); kept for Python callers
    legacy_mode: bool = False
    # navlab extension (not a Gazebo tag): relative error of each wheel's encoder scale, drawn once per
    # run from N(0, odometry_noise) with the run's seed; 0 = exact encoders. Makes odometry drift.
    odometry_noise: float = 0.0
    # the wheels driven with left_joint / right_joint (a skid-steer robot's rear wheels); empty: none
    extra_left_joints: tuple[str, ...] = ()
    extra_right_joints: tuple[str, ...] = ()
    # what drives the wheels: the gazebo_ros_diff_drive or gazebo_ros_skid_steer_drive plugin, or ros_control's
    # diff_drive_controller (gazebo_ros_control)
    drive: Literal["gazebo_ros_diff_drive", "gazebo_ros_skid_steer_drive", "gazebo_ros_control"] = (
        "gazebo_ros_diff_drive"
    )
    # odometry covariance diagonal (x, y, yaw) when the plugin names one (skid steer's covariance_x/y/yaw)
    odom_covariance: tuple[float, float, float] | None = None

    def wheel_joints(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """(left side, right side) joint names: ``left_joint`` + ``extra_left_joints``, likewise right."""
        return (self.left_joint, *self.extra_left_joints), (self.right_joint, *self.extra_right_joints)


@dataclass
class RosControlConfig:
    """``libgazebo_ros_control.so``: controllers come from a ros_control YAML loaded into its namespace."""

    namespace: str = "/"
    control_period: float = 0.0  # s; 0 = every physics step


@dataclass
class LidarConfig:
    """A ray/gpu_ray sensor with a ROS laser plugin. ``origin`` is the sensor in ``link``'s frame."""

    link: str
    origin: Origin = Origin()
    update_rate: float = 10.0  # Hz
    samples: int = 360
    min_angle: float = -3.141592653589793
    max_angle: float = 3.141592653589793
    range_min: float = 0.1
    range_max: float = 10.0
    range_resolution: float = 0.01
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    topic: str = "scan"
    frame_id: str = ""  # defaults to the link name
    name: str = "laser"


@dataclass
class ImuConfig:
    """An imu sensor with a ROS IMU plugin. Noise std devs: rad/s (gyro), m/s² (accel)."""

    link: str
    origin: Origin = Origin()
    update_rate: float = 100.0
    topic: str = "imu"
    frame_id: str = ""
    gyro_noise_stddev: float = 0.0
    accel_noise_stddev: float = 0.0
    name: str = "imu"


@dataclass
class P3dConfig:
    """A ``libgazebo_ros_p3d`` plugin: the true pose of ``link`` as nav_msgs/Odometry on ``topic``."""

    link: str
    topic: str
    frame_id: str = "world"
    update_rate: float = 1000.0  # Hz (0 in the tag: every physics step)
    name: str = "p3d"


def _sensor_suite() -> SensorSuite:
    from navlab.description.sensor_model import SensorSuite  # it imports Origin from here

    return SensorSuite()


@dataclass
class RobotModel:
    """A whole robot: links by name, joints in file order, the root link, and its plugins."""

    name: str
    links: dict[str, Link]
    joints: list[Joint]
    root_link: str
    diff_drive: DiffDriveConfig | None = None
    ros_control: RosControlConfig | None = None
    lidars: list[LidarConfig] = field(default_factory=list)
    imus: list[ImuConfig] = field(default_factory=list)
    ground_truths: list[P3dConfig] = field(default_factory=list)  # p3d plugins
    sensors: SensorSuite = field(default_factory=lambda: _sensor_suite())  # cameras, 3D lidars, ranges, bumpers
    warnings: list[str] = field(default_factory=list)
    source: Path | None = None
    urdf_xml: str = ""  # the expanded URDF (after xacro), for robot_description
