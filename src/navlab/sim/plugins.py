"""Gazebo's ROS plugins as navlab nodes: diff_drive, laser, imu, joint states, ground truth, static tf.

Each plugin is a thin node around a :class:`~navlab.sim.simulation.Simulation`: it reads the plugin's
configuration from the robot description (``RobotModel``), runs on a timer in simulated time, and
publishes the ROS messages a Gazebo user expects on the topics named in the description. Constructors
follow every node's ``(executor, *, name=..., parameters=None, namespace="")``, then ``sim=`` and what
picks the plugin's configuration (``config=``, ``index=``).
"""

from __future__ import annotations

import functools
import math
from typing import Any, Generic, Protocol, TypeVar

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node
from navlab.description import DiffDriveConfig, ImuConfig, LidarConfig, Origin, RobotModel
from navlab.geometry import Tf, Vec, qmul, qrotate, quat_from_rpy, quat_from_yaw
from navlab.sim.diffdrive import (
    ODOM_COVARIANCE_DIAG,
    EncoderOdometry,
    command_in_force,
    noetic_wheel_commands,
    wheel_speeds,
)
from navlab.sim.errors import SimError
from navlab.sim.simulation import Simulation, lidar_angles

_ODOM_COV = msgs.covariance(ODOM_COVARIANCE_DIAG)
OPTICAL = quat_from_rpy(-math.pi / 2, 0.0, -math.pi / 2)  # camera body frame -> optical frame


class SensorDescription(Protocol):
    """What every sensor's description holds (``LidarConfig``, ``ImuConfig``, ``CameraConfig``, ...)."""

    name: str
    link: str
    update_rate: float  # Hz


C = TypeVar("C", bound=SensorDescription)


def _transform(stamp_ns: int, parent: str, child: str, xyz: Any, q: Any) -> Any:
    """``TransformStamped`` from a translation and a quaternion (x, y, z, w)."""
    return msgs.TransformStamped(  # positional: see navlab.msgs
        msgs.header(stamp_ns, parent), child, msgs.Transform(msgs.vector3(xyz), msgs.quaternion_msg(q))
    )


def _tf_tuple(xyz: Any, q: Any) -> Tf:
    """(x, y, z, qx, qy, qz, qw) as floats, the values a ``Transform`` message of ``xyz`` and ``q`` holds."""
    return (float(xyz[0]), float(xyz[1]), float(xyz[2]), float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def _origin_transform(stamp_ns: int, parent: str, child: str, origin: Origin) -> Any:
    return _transform(stamp_ns, parent, child, origin.xyz, quat_from_rpy(*origin.rpy))


def listened(node: Node, *pubs: Any) -> bool:
    """Whether any of ``pubs`` has a subscriber, or a recorder/viewer listens to ``node``'s executor: a sensor
    publishes only then, as Gazebo's sensors do."""
    return node.executor.has_listeners or any(p.get_subscription_count() for p in pubs)


class SensorPlugin(Node, Generic[C]):
    """What the sensor plugins share: the config, the node's name (default: the sensor's name + ``_plugin``),
    its frame (``frame_id``, else the link), a timer at the sensor's rate (at most once per physics step, as
    Gazebo's sensors) calling :meth:`update`, and, with ``static_frame``, the frame's static tf from its link
    when the frame is not a link (turned to the optical frame if ``optical``). A plugin adds its publishers in
    :meth:`setup`; with ``idle_unread`` the timer idles while :meth:`unread`.

    The sensor is ``config`` (its description), or the robot's sensor number ``index`` in the plugin's
    ``robot_sensors`` list (``lidars``, ``imus``)."""

    optical = False
    static_frame = True  # False where robot_state_publisher sends it (lidars, IMUs: plugins.static_transforms)
    idle_unread = False
    robot_sensors = ""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Simulation,
        config: C | None = None,
        index: int | None = None,
    ) -> None:
        if self.robot_sensors:
            config = robot_sensor(sim, self.robot_sensors, index)
        if config is None:
            raise SimError(f"{type(self).__name__}: no sensor config given")
        self.index = -1 if index is None else index
        super().__init__(executor, name=name or f"{config.name}_plugin", parameters=parameters, namespace=namespace)
        assert sim.robot is not None
        self.sim, self.cfg = sim, config
        self.frame_id = (getattr(config, "frame_id", "") or config.link).strip()
        kind = type(config).__name__.removesuffix("Config").lower()
        if not self.frame_id:
            raise SimError(f"{kind} {config.name!r}: no frame (frameName/bodyName) and no link to publish in")
        if not (math.isfinite(config.update_rate) and config.update_rate > 0):
            raise SimError(f"{kind} {config.name!r}: update rate {config.update_rate!r}: expected Hz > 0")
        if self.static_frame and self.frame_id not in sim.robot.links and hasattr(config, "origin"):
            o = config.origin
            q = quat_from_rpy(*o.rpy)
            q = qmul(q, OPTICAL) if self.optical else q
            self.send_static_transform([_transform(executor.now_ns, config.link, self.frame_id, o.xyz, q)])
        idle = self.unread if self.idle_unread else None
        period = max(1.0 / config.update_rate, sim.timestep)
        self.create_timer(period, self.update, idle=idle, idle_until_graph_changes=True)
        self.setup()

    def setup(self) -> None:
        """Create the plugin's publishers (``self.cfg`` its config)."""

    def read(self, *pubs: Any) -> bool:
        """Whether any of ``pubs`` has a subscriber, or a recorder/viewer listens (:func:`listened`)."""
        return listened(self, *pubs)

    def unread(self) -> bool:
        """Whether nobody reads what the plugin publishes (its timer then idles, with ``idle_unread``, until a
        subscription or a listener is added: the answer must depend on nothing else)."""
        return False

    def update(self) -> None:
        """One sensor update."""
        raise NotImplementedError


class SimPlugin(Node):
    """What the non-sensor plugins share: every node's constructor ``(executor, *, name, parameters, namespace)``
    then ``sim=`` (a simulation with its robot loaded), ``name`` defaulting to the class's ``default_name``;
    ``self.sim`` and ``self.robot`` (its ``RobotModel``). A plugin declares its parameters and creates its
    publishers, subscriptions and timers in :meth:`setup`, or, when it takes more arguments, in its own
    ``__init__`` after this one."""

    default_name = ""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Simulation,
    ) -> None:
        super().__init__(executor, name=name or self.default_name, parameters=parameters, namespace=namespace)
        assert sim.robot is not None
        self.sim: Simulation = sim
        self.robot: RobotModel = sim.robot
        self.setup()

    def setup(self) -> None:
        """Declare the parameters, create the publishers, subscriptions and timers."""


def robot_sensor(sim: Simulation, kind: str, index: int | None) -> Any:
    """The robot's sensor number ``index`` of ``kind`` (``lidars``, ``imus``: a ``RobotModel`` list)."""
    sensors = getattr(sim.robot, kind, None) or []
    if index is None or not 0 <= index < len(sensors):
        raise SimError(f"no {kind.removesuffix('s')} number {index} on this robot")
    return sensors[index]


def base_frame_link(sim: Simulation, frame: str) -> str:
    """The robot link that carries ``frame`` (the root link when no link has that name)."""
    assert sim.robot is not None
    return frame if frame in sim.robot.links else sim.robot.root_link


class DiffDrivePlugin(SimPlugin):
    """``libgazebo_ros_diff_drive``: ``cmd_vel`` → wheel velocity targets (torque-limited), odometry and tf.

    Every ``1/update_rate`` s: stop the wheels if navlab's ``cmd_timeout`` watchdog is set (s > 0) and no
    command came within it (ROS 1's plugin has none: the last command holds), set the
    wheel targets (``max_accel``, m/s² at the wheel rim, applied by Noetic's rule for ``wheelAcceleration``:
    ``noetic_wheel_commands``), then publish ``nav_msgs/Odometry`` on ``odometry_topic`` in
    ``odometry_frame`` — integrated from the wheel encoders, or with ``odometry_source: world`` the
    true pose — and the tf ``odometry_frame → robot_base_frame``.
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "diff_drive",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Simulation,
        config: DiffDriveConfig,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace or config.namespace, sim=sim)
        self.cfg = config
        self.base_link = base_frame_link(sim, config.robot_base_frame)
        if self.base_link != config.robot_base_frame:
            self.get_logger().warning(
                f"robotBaseFrame {config.robot_base_frame!r} is not a link; odometry follows "
                f"the root link {self.base_link!r}"
            )
        self.cmd = (0.0, 0.0)
        self.last_cmd_ns: int | None = None
        self.wheel_targets = (0.0, 0.0)
        self.instructed = (0.0, 0.0)  # Noetic's wheel_speed_instr_ (rad/s here)
        self.max_wheel_accel = config.max_accel / (config.wheel_diameter / 2)  # rad/s² of the wheel joints
        self._near = 0.01 / (config.wheel_diameter / 2)  # rad/s: 1 cm/s at the rim (noetic_wheel_commands)
        self.odometry = EncoderOdometry(config.wheel_separation, config.wheel_diameter, config.legacy_mode)
        # Encoder scale errors (navlab's odometry_noise): wheel angles are read as if the wheels were
        # slightly larger or smaller than described, so encoder odometry drifts as a real robot's does.
        noise = config.odometry_noise
        self.encoder_scale = 1.0 + self.rng.normal(0.0, noise, 2) if noise > 0 else None
        self.odometry.reset(*self._encoders())
        self.last_ns = executor.now_ns
        self.odom_pub = self.create_publisher(msgs.Odometry, config.odometry_topic, 10)
        self.create_subscription(msgs.Twist, config.command_topic, self.on_cmd_vel, 10)
        self.create_timer(max(1.0 / config.update_rate, sim.timestep), self.update)  # Gazebo: at most every step

    def _encoders(self) -> tuple[float, float]:
        """Wheel angles (rad) as the encoders report them."""
        left, right = self.sim.wheel_angles()
        if self.encoder_scale is None:
            return left, right
        return left * float(self.encoder_scale[0]), right * float(self.encoder_scale[1])

    def on_cmd_vel(self, msg: Any) -> None:
        """Store the commanded body velocity (m/s, rad/s); applied at the next update."""
        self.cmd = (float(msg.linear.x), float(msg.angular.z))
        self.last_cmd_ns = self.get_clock().now_ns()

    def update(self) -> None:
        """One plugin update: wheel targets, odometry, tf."""
        now = self.executor.now_ns
        dt = (now - self.last_ns) / 1e9
        self.last_ns = now
        cfg, sim = self.cfg, self.sim
        v, w = self.cmd
        if cfg.cmd_timeout > 0 and not command_in_force(now, self.last_cmd_ns, cfg.cmd_timeout):
            v, w = 0.0, 0.0
        left, right = wheel_speeds(v, w, cfg.wheel_separation, cfg.wheel_diameter, legacy_mode=cfg.legacy_mode)
        measured = (sim.joint_velocity(cfg.left_joint), sim.joint_velocity(cfg.right_joint))
        self.wheel_targets, self.instructed = noetic_wheel_commands(
            (left, right), measured, self.instructed, self.max_wheel_accel, dt, near=self._near
        )
        sim.set_wheel_velocity_targets(*self.wheel_targets)
        self.publish_odometry(now, dt)

    def publish_odometry(self, now: int, dt: float) -> None:
        """Odometry message and odom → base tf at time ``now``."""
        cfg = self.cfg
        quat: Vec  # (x, y, z, w)
        position: Vec
        world = cfg.odometry_source == "world"
        if world:
            pose = self.sim.link_pose(self.base_link)
            position, quat = pose.position, pose.quaternion
        else:
            x, y, yaw, v, w = self.odometry.update(*self._encoders(), dt)
            position = (x, y, 0.0)
            quat = quat_from_yaw(yaw)
        if not cfg.publish_odom:  # Noetic's <publishTf>false: no odometry topic and no tf
            return
        # the message only when anyone reads it (the mapping launch's nodes take odometry from tf)
        pub = self.odom_pub
        if listened(self, pub):
            lin: Vec
            ang: Vec
            if world:
                lin, ang = self.sim.link_velocity(self.base_link)
            else:
                lin, ang = (v, 0.0, 0.0), (0.0, 0.0, w)
            frames = (cfg.odometry_frame, cfg.robot_base_frame)
            pub.publish(msgs.odometry(now, *frames, position, quat, lin, ang, _ODOM_COV.copy(), _ODOM_COV.copy()))
        if cfg.publish_tf:
            tf = _tf_tuple(position, quat) if world else (x, y, 0.0, *quat)  # floats already: the same tuple
            self.send_transform_tuples(now, ((cfg.odometry_frame, cfg.robot_base_frame, tf),))


class LidarPlugin(SensorPlugin[LidarConfig]):
    """``gazebo_ros_laser``: a ``sensor_msgs/LaserScan`` every ``1/update_rate`` s on the configured topic,
    for the robot's lidar number ``index`` (default name: the sensor's name + ``_plugin``)."""

    static_frame = False
    robot_sensors = "lidars"

    def setup(self) -> None:
        cfg = self.cfg
        n = cfg.samples
        self.angle_increment = float(np.diff(lidar_angles(cfg))[0]) if n > 1 else 0.0
        self.pub = self.create_publisher(msgs.LaserScan, cfg.topic, 10)
        self._empty = np.zeros(0, dtype=np.float32)
        # the scan's fixed fields, converted once, in the message's order: angle_min, angle_max, angle_increment,
        # time_increment, scan_time, range_min, range_max
        self._fields = (
            float(cfg.min_angle),
            float(cfg.max_angle),
            self.angle_increment,
            0.0,
            1.0 / cfg.update_rate,
            float(cfg.range_min),
            float(cfg.range_max),
        )

    def update(self) -> None:
        """Cast the rays and publish the scan."""
        ranges = self.sim.scan(self.index, rng=self.rng)
        # positional (see navlab.msgs): header, the fixed fields, ranges, intensities
        self.pub.publish(
            msgs.LaserScan(msgs.header(self.executor.now_ns, self.frame_id), *self._fields, ranges, self._empty)
        )


class JointStatePlugin(SimPlugin):
    """``gazebo_ros_joint_state_publisher``: ``/joint_states`` (position and velocity of the moving joints)
    every ``1/publish_frequency`` s (Hz, default 30; 0 = none), read from the simulator."""

    default_name = "joint_state_publisher"

    def setup(self) -> None:
        rate = float(self.declare_parameter("publish_frequency", 30.0))
        self.joints = [j.name for j in self.robot.joints if j.name in set(self.sim.joint_names())]
        self.pub = self.create_publisher(msgs.JointState, "joint_states", 10)
        if rate > 0 and self.joints:
            self.create_timer(1.0 / rate, self.update)

    def update(self) -> None:
        """Publish the joints' state; to the robot_state_publisher's joint handler directly when it is the topic's
        only reader (no other subscriber, no listener): it gets the message's stamp, names and positions."""
        qpos, qvel = self.sim.joint_addresses(self.joints)  # looked up now: a spawn recompiles the model
        d = self.sim.data
        subs = self.pub.topic.subscriptions
        if len(subs) == 1 and not self.executor.has_listeners:
            reader = getattr(subs[0].callback, "__self__", None)
            if isinstance(reader, RobotStatePublisher) and subs[0].callback == reader._on_joint_states:
                self.pub.topic.count += 1
                reader.publish_joints(self.executor.now_ns, self.joints, d.qpos[qpos].tolist())
                return
        # positional: header, name, position, velocity, effort (see navlab.msgs)
        head = msgs.header(self.executor.now_ns, "")
        self.pub.publish(msgs.JointState(head, list(self.joints), d.qpos[qpos], d.qvel[qvel], np.zeros(len(qpos))))


class RobotStatePublisher(SimPlugin):
    """``robot_state_publisher``: subscribes ``/joint_states`` and publishes each moving joint's tf (parent link →
    child link) at the message's stamp; fixed joints and sensor frames once, as static tf. ``publish_tf``
    (default true; navlab's switch): the moving joints' tf."""

    default_name = "robot_state_publisher"

    def setup(self) -> None:
        self.publish_tf = self.declare_parameter("publish_tf", True)
        self.joints = {
            j.name: (j, _joint_constants(tuple(j.origin.rpy), tuple(j.origin.xyz), tuple(j.axis)))
            for j in self.robot.joints
            if j.type != "fixed"
        }
        self.send_static_transform(static_transforms(self.sim, self.executor.now_ns))
        self.create_subscription(msgs.JointState, "joint_states", self._on_joint_states, 10)

    def _on_joint_states(self, msg: Any) -> None:
        position = msg.position.tolist() if isinstance(msg.position, np.ndarray) else msg.position
        self.publish_joints(msgs.stamp_ns(msg), msg.name, position)

    def publish_joints(self, stamp: int, names: Any, position: Any) -> None:
        """The moving joints' tf at ``stamp`` (ns) from joint ``names`` and their ``position`` (rad or m)."""
        if not self.publish_tf:
            return
        out = []
        joints = self.joints
        for name, q in zip(names, position, strict=False):
            known = joints.get(name)
            if known is not None:
                joint, consts = known
                xyz, quat = _motion(joint.type, consts, float(q))
                out.append((joint.parent, joint.child, (*xyz, *quat)))  # floats already (_joint_constants)
        if out:
            self.send_transform_tuples(stamp, out)


def joint_motion(joint: Any, q: float) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """Pose (xyz, quaternion x y z w) of a joint's child frame in its parent link at joint position ``q``."""
    consts = _joint_constants(tuple(joint.origin.rpy), tuple(joint.origin.xyz), tuple(joint.axis))
    return _motion(joint.type, consts, q)


def _motion(
    kind: str, consts: tuple[tuple, tuple, tuple], q: float
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """:func:`joint_motion` from a joint's type and :func:`_joint_constants`."""
    q0, (ox, oy, oz), (ax, ay, az) = consts
    if kind == "prismatic":  # translate along the axis, expressed in the parent via the origin
        tx, ty, tz = qrotate(q0, (ax * q, ay * q, az * q))
        return (ox + tx, oy + ty, oz + tz), q0
    c, s = math.cos(q / 2), math.sin(q / 2)
    return (ox, oy, oz), qmul(q0, (s * ax, s * ay, s * az, c))


@functools.lru_cache(maxsize=256)
def _joint_constants(rpy: tuple, xyz: tuple, axis: tuple) -> tuple[tuple, tuple, tuple]:
    """(origin quaternion x y z w, origin translation, unit axis) of a joint, as float tuples."""
    ax, ay, az = (float(v) for v in axis)
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    return quat_from_rpy(*rpy), tuple(float(v) for v in xyz), (ax / norm, ay / norm, az / norm)


def static_transforms(sim: Simulation, stamp_ns: int) -> list[Any]:
    """Fixed joints (parent → child) and sensor frames that are not links (link → frame), as tf."""
    assert sim.robot is not None
    robot = sim.robot
    out = [_origin_transform(stamp_ns, j.parent, j.child, j.origin) for j in robot.joints if j.type == "fixed"]
    sensors: list[LidarConfig | ImuConfig] = [*robot.lidars, *robot.imus]
    for cfg in sensors:
        frame = cfg.frame_id or cfg.link
        if frame != cfg.link and frame not in robot.links:
            out.append(_origin_transform(stamp_ns, cfg.link, frame, cfg.origin))
    return out


class GroundTruthPlugin(SimPlugin):
    """``libgazebo_ros_p3d``: the true pose and twist of a link, ``nav_msgs/Odometry`` (for evaluation only).

    Parameters (p3d's): ``bodyName`` (the link; default the robot's root link), ``topicName``
    (``/ground_truth/odom``), ``frameName`` (``world``), ``updateRate`` (Hz, 50).
    """

    default_name = "ground_truth"

    def setup(self) -> None:
        self.base_frame = self.declare_parameter("bodyName", self.robot.root_link)
        topic = self.declare_parameter("topicName", "/ground_truth/odom")
        self.frame = self.declare_parameter("frameName", "world")
        rate = float(self.declare_parameter("updateRate", 50.0))
        self.link = base_frame_link(self.sim, self.base_frame)
        self.pub = self.create_publisher(msgs.Odometry, topic, 10)
        self.create_timer(1.0 / rate, self.update, idle=self._unread, idle_until_graph_changes=True)

    def _unread(self) -> bool:
        """Whether nobody subscribes or listens (a recorder, ``topic echo``): the timer then idles."""
        return not listened(self, self.pub)

    def update(self) -> None:
        """Publish the true pose, when anyone subscribes or listens: 50 messages a second that nobody read were
        ~5 % of a navigation run's CPU (navlab bench nav), and their timer events a fifth of its events."""
        if self._unread():
            return
        state = self.sim.link_state(self.link)  # position, quaternion (x, y, z, w), linear, angular velocity
        self.pub.publish(
            msgs.odometry(self.executor.now_ns, self.frame, self.base_frame, *state, np.zeros(36), np.zeros(36))
        )
