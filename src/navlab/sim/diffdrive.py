"""Differential-drive kinematics and wheel-encoder odometry (pure: numbers in, numbers out).

Frames: the robot base frame has x forward, y left (REP-103); odometry is in the odometry frame,
which starts at the base frame's pose when the odometry is (re)set.

ROS 1's ``gazebo_ros_diff_drive`` semantics kept here:

- ``legacyMode`` (ROS 1 default **true**): the joint named in ``<leftJoint>`` gets the speed the
  *right* wheel needs when turning (``v + w b/2``) and ``<rightJoint>`` the left's, and encoder
  odometry turns the other way to match. Robots written for it name their wheels "the other way
  round" and turn correctly only so; ``legacyMode false`` is the textbook assignment.
- No command timeout: the last ``cmd_vel`` applies until another arrives (one ``rostopic pub -1``
  keeps the robot going). navlab's ``cmd_timeout`` (s, off unless set) is a watchdog on top.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from navlab.sim.errors import SimError

#: Gazebo ROS 1 diff_drive's fixed covariances (pose and twist diagonals: x y z roll pitch yaw)
ODOM_COVARIANCE_DIAG = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def _check_geometry(separation: float, diameter: float) -> None:
    if not (math.isfinite(separation) and separation > 0 and math.isfinite(diameter) and diameter > 0):
        raise SimError(
            f"diff drive: wheel separation {separation} m and wheel diameter {diameter} m: expected finite numbers > 0"
        )


def wheel_speeds(
    v: float, w: float, separation: float, diameter: float, *, legacy_mode: bool = False
) -> tuple[float, float]:
    """(left joint, right joint) angular velocities (rad/s) for body speed ``v`` (m/s) and yaw rate ``w``
    (rad/s). ``legacy_mode`` (ROS 1's ``<legacyMode>``): the two joints' turning terms are swapped."""
    _check_geometry(separation, diameter)
    r = diameter / 2.0
    turn = w * separation / 2.0
    if legacy_mode:
        return (v + turn) / r, (v - turn) / r
    return (v - turn) / r, (v + turn) / r


def command_in_force(now_ns: int, last_cmd_ns: int | None, timeout: float) -> bool:
    """Whether the last ``cmd_vel`` still applies at ``now_ns``: always with ``timeout`` <= 0 (ROS 1's
    plugin: the last command holds until a new one), else for ``timeout`` s after it arrived."""
    if timeout <= 0:
        return True
    return last_cmd_ns is not None and now_ns - last_cmd_ns <= timeout * 1e9


def ramp(current: float, target: float, max_accel: float, dt: float) -> float:
    """Move ``current`` toward ``target`` by at most ``max_accel * dt`` (``max_accel`` <= 0: jump)."""
    if max_accel <= 0 or dt <= 0:
        return target
    step = max_accel * dt
    return current + max(-step, min(step, target - current))


def noetic_wheel_commands(
    targets: tuple[float, float],
    measured: tuple[float, float],
    instructed: tuple[float, float],
    max_accel: float,
    dt: float,
    near: float,
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The wheel velocity commands ROS Noetic's gazebo_ros_diff_drive sets with ``wheelAcceleration``.

    All speeds in the same unit (navlab: rad/s of the joints). With no limit (``max_accel`` 0), or when
    *either* wheel's measured speed is within ``near`` (0.01 m/s at the rim) of its target, both wheels
    get their targets; otherwise each wheel's instructed speed moves by its measured error, clipped to
    ``max_accel * dt`` — the plugin's own rule, quirks included (the instructed speed integrates the
    error, and is not reset when the targets are set directly). Returns (commands, instructed speeds)."""
    if max_accel <= 0 or abs(targets[0] - measured[0]) < near or abs(targets[1] - measured[1]) < near:
        return targets, instructed
    step = max_accel * dt
    ramped = (
        instructed[0] + max(-step, min(step, targets[0] - measured[0])),
        instructed[1] + max(-step, min(step, targets[1] - measured[1])),
    )
    return ramped, ramped


@dataclass
class EncoderOdometry:
    """Integrates wheel angles into a planar pose (midpoint rule), like Gazebo's ``odometrySource encoder``.

    ``update(left, right, dt)`` takes the wheel joint angles (rad, unwrapped) and the time since the
    previous call (s), and returns ``(x, y, yaw, v, w)``: pose in the odometry frame (m, rad) and
    body velocities (m/s, rad/s).
    """

    separation: float
    diameter: float
    legacy_mode: bool = False  # ROS 1 <legacyMode>: the yaw change is (left - right) / separation
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    _left: float | None = None
    _right: float | None = None

    def __post_init__(self) -> None:
        _check_geometry(self.separation, self.diameter)

    def reset(self, left: float, right: float, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> None:
        """Start integrating from pose (x, y, yaw) at these wheel angles."""
        self._left, self._right = left, right
        self.x, self.y, self.yaw = x, y, yaw

    def update(self, left: float, right: float, dt: float) -> tuple[float, float, float, float, float]:
        """Advance with new wheel angles; returns (x, y, yaw, v, w)."""
        if self._left is None or self._right is None:
            self.reset(left, right, self.x, self.y, self.yaw)
        assert self._left is not None and self._right is not None  # set by reset
        r = self.diameter / 2.0
        sl = (left - self._left) * r
        sr = (right - self._right) * r
        self._left, self._right = left, right
        ds = 0.5 * (sl + sr)
        dyaw = ((sl - sr) if self.legacy_mode else (sr - sl)) / self.separation
        mid = self.yaw + 0.5 * dyaw
        self.x += ds * math.cos(mid)
        self.y += ds * math.sin(mid)
        self.yaw = math.atan2(math.sin(self.yaw + dyaw), math.cos(self.yaw + dyaw))
        if dt > 0:
            return self.x, self.y, self.yaw, ds / dt, dyaw / dt
        return self.x, self.y, self.yaw, 0.0, 0.0
