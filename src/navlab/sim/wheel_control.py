"""ros_control's ``diff_drive_controller`` on effort-driven wheels: the speed controller of the paper's
future work, selectable instead of the ``gazebo_ros_diff_drive`` plugin.

The pure parts — :class:`SpeedLimiter` (ROS's velocity/acceleration/jerk limiter) and
:class:`WheelOdometry` (odometry from the wheel encoders, with a rolling mean of the velocities) —
sit beside :class:`DiffDriveController`, the node that every ``control_period`` s reads the wheel
joints, limits the commanded body velocity, turns it into wheel speeds and drives each wheel with a
velocity PID (:mod:`navlab.sim.pid`) acting on effort (the MuJoCo actuators become torque motors
capped at the motor's torque). Odometry (``nav_msgs/Odometry``) and tf ``odom_frame_id →
base_frame_id`` go out at ``publish_rate``.

Selected in the ``gazebo`` node by parameters in ros_control's YAML layout::

    mobile_base_controller:
      type: diff_drive_controller/DiffDriveController
      left_wheel: left_wheel_hinge
      right_wheel: right_wheel_hinge
      linear: {x: {has_velocity_limits: true, max_velocity: 0.5, has_acceleration_limits: true, max_acceleration: 1.0}}
    gazebo_ros_control:
      control_period: 0.01
      pid_gains: {left_wheel_hinge: {p: 1.0, i: 5.0, d: 0.0, i_clamp: 5.0}, right_wheel_hinge: {...}}
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import mujoco
import numpy as np

from navlab import msgs
from navlab.core import Executor
from navlab.description import DiffDriveConfig
from navlab.sim.errors import SimError
from navlab.sim.pid import Pid, PidGains
from navlab.sim.plugins import SimPlugin
from navlab.sim.ros_control import wheel_names
from navlab.sim.simulation import Simulation

CONTROLLER_TYPE = "diff_drive_controller/DiffDriveController"
#: navlab's default wheel PID when ``gazebo_ros_control/pid_gains`` names none (N m per rad/s, N m per rad)
DEFAULT_PID = {"p": 1.0, "i": 5.0, "d": 0.0, "i_clamp": 5.0}
_LIMIT_KEYS = {
    "has_velocity_limits": False,
    "max_velocity": 0.0,
    "min_velocity": None,
    "has_acceleration_limits": False,
    "max_acceleration": 0.0,
    "min_acceleration": None,
    "has_jerk_limits": False,
    "max_jerk": 0.0,
    "min_jerk": None,
}
#: diff_drive_controller's parameters (ROS 1 names) and navlab's defaults (ROS's where ROS has one)
CONTROLLER_DEFAULTS: dict[str, Any] = {
    "type": CONTROLLER_TYPE,
    "left_wheel": None,  # a joint or a list of joints (a skid-steer side); default: the robot's diff-drive left joint
    "right_wheel": None,
    "publish_rate": 50.0,
    "pose_covariance_diagonal": [0.001, 0.001, 1000000.0, 1000000.0, 1000000.0, 1000.0],
    "twist_covariance_diagonal": [0.001, 0.001, 1000000.0, 1000000.0, 1000000.0, 1000.0],
    "cmd_vel_timeout": 0.5,
    "base_frame_id": "",  # default: the robot's base frame (robotBaseFrame)
    "odom_frame_id": "odom",
    "enable_odom_tf": True,
    "wheel_separation": 0.0,  # 0: from the robot description
    "wheel_radius": 0.0,
    "wheel_separation_multiplier": 1.0,
    "wheel_radius_multiplier": 1.0,
    "left_wheel_radius_multiplier": 1.0,
    "right_wheel_radius_multiplier": 1.0,
    "velocity_rolling_window_size": 10,
    "open_loop": False,
    "publish_cmd": False,
    "allow_multiple_cmd_vel_publishers": True,
    **{f"linear.x.{k}": v for k, v in _LIMIT_KEYS.items()},
    **{f"angular.z.{k}": v for k, v in _LIMIT_KEYS.items()},
}


class SpeedLimiter:
    """``diff_drive_controller``'s speed limiter for one axis: jerk, then acceleration, then velocity.

    Limits are m/s (rad/s), m/s², m/s³; a ``min_*`` of None mirrors its ``max_*`` (ROS's default).
    """

    def __init__(self, params: dict[str, Any], *, where: str = "limiter") -> None:
        def limit(key: str) -> tuple[bool, float, float]:
            on = bool(params.get(f"has_{key}_limits", False))
            hi = float(params.get(f"max_{key}", 0.0))
            lo_raw = params.get(f"min_{key}")
            lo = -hi if lo_raw is None else float(lo_raw)
            if on and not (math.isfinite(hi) and math.isfinite(lo) and lo <= hi):
                raise SimError(f"{where}: min_{key} {lo} and max_{key} {hi}: expected finite numbers, min <= max")
            return on, lo, hi

        self.velocity = limit("velocity")
        self.acceleration = limit("acceleration")
        self.jerk = limit("jerk")

    def limit(self, v: float, v0: float, v1: float, dt: float) -> float:
        """Limited command ``v`` given the last two commands ``v0`` (previous) and ``v1`` (before it)."""
        on, lo, hi = self.jerk
        if on and dt > 0:
            dv, dv0 = v - v0, v0 - v1
            dt2 = 2.0 * dt * dt
            da = min(max(dv - dv0, lo * dt2), hi * dt2)
            v = v0 + dv0 + da
        on, lo, hi = self.acceleration
        if on and dt > 0:
            v = v0 + min(max(v - v0, lo * dt), hi * dt)
        on, lo, hi = self.velocity
        if on:
            v = min(max(v, lo), hi)
        return v


class WheelOdometry:
    """Odometry from wheel joint angles (rad) as ``diff_drive_controller`` integrates it.

    Pose in the odometry frame (m, rad): exact arc integration (second-order Runge-Kutta for straight
    motion); body velocities (m/s, rad/s) as rolling means over ``window`` updates.
    """

    def __init__(self, separation: float, left_radius: float, right_radius: float, window: int = 10) -> None:
        for key, v in (
            ("wheel_separation", separation),
            ("left wheel radius", left_radius),
            ("right wheel radius", right_radius),
        ):
            if not (math.isfinite(v) and v > 0):
                raise SimError(f"diff_drive_controller: {key} {v}: expected a finite number > 0")
        if window < 1:
            raise SimError(f"diff_drive_controller: velocity_rolling_window_size {window}: expected >= 1")
        self.separation, self.left_radius, self.right_radius = separation, left_radius, right_radius
        self.x = self.y = self.yaw = 0.0
        self.linear = self.angular = 0.0
        self._lin: deque[float] = deque(maxlen=window)
        self._ang: deque[float] = deque(maxlen=window)
        self._last: tuple[float, float] | None = None

    def update(self, left: float, right: float, dt: float) -> None:
        """Advance with the wheel angles ``left``/``right`` (rad) read ``dt`` s after the previous ones."""
        if self._last is None:
            self._last = (left, right)
            return
        dl = (left - self._last[0]) * self.left_radius
        dr = (right - self._last[1]) * self.right_radius
        self._last = (left, right)
        ds, dyaw = 0.5 * (dl + dr), (dr - dl) / self.separation
        if abs(dyaw) < 1e-6:
            mid = self.yaw + 0.5 * dyaw
            self.x += ds * math.cos(mid)
            self.y += ds * math.sin(mid)
        else:
            r = ds / dyaw
            self.x += r * (math.sin(self.yaw + dyaw) - math.sin(self.yaw))
            self.y -= r * (math.cos(self.yaw + dyaw) - math.cos(self.yaw))
        self.yaw = math.atan2(math.sin(self.yaw + dyaw), math.cos(self.yaw + dyaw))
        if dt > 0:
            self._lin.append(ds / dt)
            self._ang.append(dyaw / dt)
            self.linear = sum(self._lin) / len(self._lin)
            self.angular = sum(self._ang) / len(self._ang)


def use_effort_actuators(sim: Simulation, max_torque: float) -> list[int]:
    """Turn the wheel velocity actuators into torque motors (ctrl = N m, capped at ``max_torque``), in
    the compiled model and in its spec (so a recompile after spawning keeps them); their ids."""
    names = sim.info.wheel_actuators
    if not names:
        raise SimError("diff_drive_controller: this robot has no diff-drive wheels")
    ids = []
    for name in names:
        act = sim.spec.actuator(name)
        act.set_to_motor()
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = np.array([-max_torque, max_torque])
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        i = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        m = sim.model
        m.actuator_gaintype[i] = mujoco.mjtGain.mjGAIN_FIXED
        m.actuator_gainprm[i, :] = 0.0
        m.actuator_gainprm[i, 0] = 1.0
        m.actuator_biastype[i] = mujoco.mjtBias.mjBIAS_NONE
        m.actuator_biasprm[i, :] = 0.0
        m.actuator_ctrllimited[i] = 0
        m.actuator_forcelimited[i] = 1
        m.actuator_forcerange[i] = (-max_torque, max_torque)
        sim.data.ctrl[i] = 0.0
        ids.append(i)
    return ids


def _diag(values: Any, key: str) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64).ravel()
    if v.shape != (6,) or not np.isfinite(v).all() or (v < 0).any():
        raise SimError(f"diff_drive_controller {key}: expected 6 numbers >= 0 (x y z roll pitch yaw), got {values!r}")
    return msgs.covariance(tuple(float(x) for x in v))


class DiffDriveController(SimPlugin):
    """``diff_drive_controller/DiffDriveController`` with ``gazebo_ros_control``'s per-wheel velocity PID on
    effort, or (``velocity_interface``: ``hardware_interface/VelocityJointInterface`` without ``pid_gains``) the
    joints' velocity motors capped at their effort limit, as DefaultRobotHWSim drives them. Each side may have
    several wheels (``left_wheel: [front_left_wheel, rear_left_wheel]``): they get the same speed and odometry
    reads each side's mean position. Subscribes ``cmd_vel`` (the plugin's command topic), publishes ``odom``
    and tf; see the module."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "mobile_base_controller",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Simulation,
        config: DiffDriveConfig,
        pid_gains: dict[str, Any] | None = None,
        control_period: float = 0.01,
        velocity_interface: bool = False,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace or config.namespace, sim=sim)
        p = self.declare_parameters(CONTROLLER_DEFAULTS)
        self.check_parameters()
        where = f"{self.fully_qualified_name}"
        if p["type"] != CONTROLLER_TYPE:
            raise SimError(f"{where}: type {p['type']!r}: navlab simulates {CONTROLLER_TYPE!r}")
        self.cfg, self.p = config, p
        lefts, rights = config.wheel_joints()
        self.sides = (
            wheel_names(p["left_wheel"], f"{where} left_wheel") if p["left_wheel"] else lefts,
            wheel_names(p["right_wheel"], f"{where} right_wheel") if p["right_wheel"] else rights,
        )
        if (len(self.sides[0]), len(self.sides[1])) != (len(lefts), len(rights)):
            raise SimError(
                f"{where}: left_wheel {list(self.sides[0])} and right_wheel {list(self.sides[1])}: the "
                f"robot drives {len(lefts)} + {len(rights)} wheels"
            )
        self.joints = (*self.sides[0], *self.sides[1])
        for joint in self.joints:
            if joint not in sim.joint_names():
                raise SimError(
                    f"{where}: wheel joint {joint!r} is not a moving joint of the robot "
                    f"(joints: {', '.join(sim.joint_names())})"
                )
        for key in ("publish_rate", "cmd_vel_timeout"):
            if not (math.isfinite(p[key]) and p[key] > 0):
                raise SimError(f"{where} {key}: expected a number > 0, got {p[key]!r}")
        if not (math.isfinite(control_period) and 0 < control_period <= 0.1):
            raise SimError(f"gazebo_ros_control control_period {control_period!r}: expected 0 < s <= 0.1")
        separation = (p["wheel_separation"] or config.wheel_separation) * p["wheel_separation_multiplier"]
        radius = (p["wheel_radius"] or config.wheel_diameter / 2) * p["wheel_radius_multiplier"]
        self.separation = separation
        self.radii = (radius * p["left_wheel_radius_multiplier"], radius * p["right_wheel_radius_multiplier"])
        self.odometry = WheelOdometry(separation, *self.radii, int(p["velocity_rolling_window_size"]))
        self.limit_lin = SpeedLimiter(_axis(p, "linear.x"), where=f"{where} linear.x")
        self.limit_ang = SpeedLimiter(_axis(p, "angular.z"), where=f"{where} angular.z")
        self.pose_cov = _diag(p["pose_covariance_diagonal"], "pose_covariance_diagonal")
        self.twist_cov = _diag(p["twist_covariance_diagonal"], "twist_covariance_diagonal")
        self.base_frame = p["base_frame_id"] or config.robot_base_frame
        self.odom_frame = p["odom_frame_id"]
        gains = pid_gains or {}
        unknown = sorted(set(gains) - set(self.joints))
        if unknown:
            raise SimError(f"gazebo_ros_control pid_gains: {unknown} are not the controller's wheels {self.joints}")
        self.velocity_interface = velocity_interface and not gains
        self.pids = tuple(
            Pid(PidGains.from_params(gains.get(j, DEFAULT_PID), where=f"pid_gains.{j}"), output_limit=config.max_torque)
            for j in self.joints
        )
        self.actuators = [] if self.velocity_interface else use_effort_actuators(sim, config.max_torque)
        self.period = control_period
        self.cmd = (0.0, 0.0)
        self.last_cmd_ns: int | None = None
        self.history = [(0.0, 0.0), (0.0, 0.0)]  # the last two limited commands (v, w)
        self.wheel_targets = (0.0, 0.0)  # rad/s
        self.last_ns = executor.now_ns
        self.odometry.update(*self._angles(), 0.0)
        self.odom_pub = self.create_publisher(msgs.Odometry, config.odometry_topic, 10)
        self.cmd_pub = (
            self.create_publisher(msgs.Twist, "mobile_base_controller/cmd_vel_out", 10) if p["publish_cmd"] else None
        )
        self.create_subscription(msgs.Twist, config.command_topic, self.on_cmd_vel, 10)
        self.create_timer(control_period, self.update)
        self.create_timer(1.0 / p["publish_rate"], self.publish_odometry)

    def _angles(self) -> tuple[float, float]:
        """Each side's mean wheel angle (rad), as diff_drive_controller averages a side's wheels."""
        pos = self.sim.joint_position
        return tuple(sum(map(pos, side)) / len(side) for side in self.sides)  # type: ignore[return-value]

    def on_cmd_vel(self, msg: Any) -> None:
        """Store the commanded body velocity (m/s, rad/s); non-finite commands are refused, as ROS does."""
        v, w = float(msg.linear.x), float(msg.angular.z)
        if not (math.isfinite(v) and math.isfinite(w)):
            self.get_logger().warning(f"ignoring a non-finite cmd_vel ({v}, {w})")
            return
        self.cmd = (v, w)
        self.last_cmd_ns = self.get_clock().now_ns()

    def update(self) -> None:
        """One control cycle: encoders → odometry; limited command → wheel targets → PID torques."""
        now = self.get_clock().now_ns()
        dt = (now - self.last_ns) / 1e9
        self.last_ns = now
        self.odometry.update(*self._angles(), dt)
        v, w = self.cmd
        if self.last_cmd_ns is None or now - self.last_cmd_ns > self.p["cmd_vel_timeout"] * 1e9:
            v, w = 0.0, 0.0  # brake: ROS's controller zeroes the command after cmd_vel_timeout
        (v0, w0), (v1, w1) = self.history
        v = self.limit_lin.limit(v, v0, v1, dt)
        w = self.limit_ang.limit(w, w0, w1, dt)
        self.history = [(v, w), (v0, w0)]
        half = w * self.separation / 2.0
        self.wheel_targets = ((v - half) / self.radii[0], (v + half) / self.radii[1])
        if self.velocity_interface:
            self.sim.set_wheel_velocity_targets(*self.wheel_targets)
        else:
            n = len(self.sides[0])
            targets = [self.wheel_targets[0]] * n + [self.wheel_targets[1]] * (len(self.joints) - n)
            for target, joint, pid, act in zip(targets, self.joints, self.pids, self.actuators, strict=True):
                self.sim.data.ctrl[act] = pid.compute(target - self.sim.joint_velocity(joint), dt)
        if self.cmd_pub is not None:
            self.cmd_pub.publish(msgs.twist(v, w))

    def publish_odometry(self) -> None:
        """``nav_msgs/Odometry`` in ``odom_frame_id`` and, with ``enable_odom_tf``, the tf to the base."""
        now = self.get_clock().now_ns()
        o = self.odometry
        if self.p["open_loop"]:
            v, w = self.history[0]
        else:
            v, w = o.linear, o.angular
        self.odom_pub.publish(
            msgs.Odometry(
                header=msgs.header(now, self.odom_frame),
                child_frame_id=self.base_frame,
                pose=msgs.PoseWithCovariance(pose=msgs.pose_from_2d(o.x, o.y, o.yaw), covariance=self.pose_cov.copy()),
                twist=msgs.TwistWithCovariance(twist=msgs.twist(v, w), covariance=self.twist_cov.copy()),
            )
        )
        if self.p["enable_odom_tf"]:
            self.send_transform(msgs.transform_stamped(now, self.odom_frame, self.base_frame, o.x, o.y, o.yaw))


def _axis(p: dict[str, Any], prefix: str) -> dict[str, Any]:
    return {k[len(prefix) + 1 :]: v for k, v in p.items() if k.startswith(prefix + ".")}


def controller_selected(params: dict[str, Any]) -> bool:
    """Whether the ``gazebo`` node's parameters name a ``mobile_base_controller`` (flattened keys)."""
    return any(k.startswith("mobile_base_controller.") for k in params)
