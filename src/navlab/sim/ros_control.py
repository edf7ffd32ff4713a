"""``gazebo_ros_control``'s side of a ros_control YAML: which controllers it names and the drive it describes.

A Jackal-shaped control YAML (``rosparam load control.yaml`` into the ``gazebo`` node)::

    jackal_joint_publisher: {type: joint_state_controller/JointStateController, publish_rate: 50}
    jackal_velocity_controller:
      type: diff_drive_controller/DiffDriveController
      left_wheel: [front_left_wheel, rear_left_wheel]
      right_wheel: [front_right_wheel, rear_right_wheel]
      wheel_separation_multiplier: 1.5

Controllers are found by their ``type`` (navlab starts every controller the YAML holds, as the spawner of a
robot's control launch does). For a robot whose description has only the ``gazebo_ros_control`` plugin, the
diff-drive controller's wheels make the drive: ``wheel_separation`` and ``wheel_radius`` come from the URDF when
the YAML gives none (the distance between the first left and right wheel joints; the first left wheel link's
collision cylinder or sphere radius), as diff_drive_controller reads them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from navlab.description import DiffDriveConfig, RobotModel
from navlab.sim.errors import SimError

DIFF_DRIVE_TYPE = "diff_drive_controller/DiffDriveController"
JOINT_STATE_TYPE = "joint_state_controller/JointStateController"
LEGACY_NAME = "mobile_base_controller"  # navlab's name before controllers were found by type (type optional)


@dataclass
class Controllers:
    """The controllers of a ros_control YAML: the diff-drive controller's name (None: none) and the joint
    state controller's publish rate (Hz; None: none)."""

    diff_drive: str | None = None
    joint_state_rate: float | None = None
    names: tuple[str, ...] = ()
    ignored: tuple[str, ...] = ()  # controllers of other types (``name (type)``): navlab does not simulate them


def find_controllers(params: dict[str, Any]) -> Controllers:
    """Controllers among flattened parameters (``ctrl.type`` keys)."""
    out = Controllers()
    found, ignored = [], []
    names = list(params)
    for key in names:
        ctrl, dot, leaf = key.rpartition(".")
        if leaf != "type" or not dot or "." in ctrl:
            continue
        kind = params[key]
        if kind == DIFF_DRIVE_TYPE and out.diff_drive is None:
            out.diff_drive = ctrl
        elif kind == JOINT_STATE_TYPE:
            rate = float(params.get(f"{ctrl}.publish_rate", 50.0))
            if not rate > 0:
                raise SimError(f"{ctrl}.publish_rate {rate!r}: expected Hz > 0")
            out.joint_state_rate = rate
        elif isinstance(kind, str) and "/" in kind:  # a ros_control type navlab does not simulate
            ignored.append(f"{ctrl} ({kind})")
        else:
            continue
        found.append(ctrl)
    if out.diff_drive is None and any(k.startswith(LEGACY_NAME + ".") for k in names):
        out.diff_drive = LEGACY_NAME
        found.append(LEGACY_NAME)
    out.names, out.ignored = tuple(found), tuple(ignored)
    return out


def wheel_names(value: Any, where: str) -> tuple[str, ...]:
    """A ``left_wheel``/``right_wheel`` value (a joint name or a list of them) as a tuple."""
    names = [value] if isinstance(value, str) else list(value) if isinstance(value, list | tuple) else []
    if not names or not all(isinstance(n, str) and n for n in names):
        raise SimError(f"{where}: expected a joint name or a list of joint names, got {value!r}")
    return tuple(names)


def _joint_xyz(robot: RobotModel, joint: str) -> np.ndarray:
    """Position (m) of a joint's frame in the root link's frame."""
    by_child = {j.child: j for j in robot.joints}
    j = next((j for j in robot.joints if j.name == joint), None)
    if j is None:
        raise SimError(f"diff_drive_controller: wheel joint {joint!r} is not a joint of robot {robot.name!r}")
    m = j.origin.matrix()
    link = j.parent
    while link in by_child:
        m = by_child[link].origin.matrix() @ m
        link = by_child[link].parent
    return m[:3, 3]


def _wheel_radius(robot: RobotModel, joint: str) -> float:
    j = next(j for j in robot.joints if j.name == joint)
    for shape in robot.links[j.child].collisions:
        if shape.geometry.kind in ("cylinder", "sphere"):
            return float(shape.geometry.size[0])
    raise SimError(
        f"diff_drive_controller: wheel_radius not given and wheel link {j.child!r} has no cylinder or "
        "sphere collision to read it from"
    )


def drive_from_controller(robot: RobotModel, params: dict[str, Any]) -> DiffDriveConfig:
    """The drive a diff-drive controller's parameters describe on a ``gazebo_ros_control`` robot."""
    lefts = wheel_names(params.get("left_wheel"), "diff_drive_controller left_wheel")
    rights = wheel_names(params.get("right_wheel"), "diff_drive_controller right_wheel")
    separation = float(params.get("wheel_separation") or 0.0)
    if not separation:
        separation = float(np.linalg.norm((_joint_xyz(robot, lefts[0]) - _joint_xyz(robot, rights[0]))[:2]))
    radius = float(params.get("wheel_radius") or 0.0) or _wheel_radius(robot, lefts[0])
    efforts = [j.effort for j in robot.joints if j.name in (*lefts, *rights) and j.effort]
    return DiffDriveConfig(
        left_joint=lefts[0],
        right_joint=rights[0],
        extra_left_joints=lefts[1:],
        extra_right_joints=rights[1:],
        wheel_separation=separation,
        wheel_diameter=2.0 * radius,
        max_torque=float(min(efforts)) if efforts else DiffDriveConfig.max_torque,
        command_topic="cmd_vel",
        odometry_topic="odom",
        odometry_frame=str(params.get("odom_frame_id", "odom")),
        robot_base_frame=str(params.get("base_frame_id") or "base_link"),
        odometry_source="encoder",
        publish_tf=bool(params.get("enable_odom_tf", True)),
        legacy_mode=False,
        drive="gazebo_ros_control",
    )
