"""Four-wheel skid-steer robots' ``<gazebo>`` tags: ``libgazebo_ros_skid_steer_drive.so``, ``libgazebo_ros_control.so``
and the ODE contact tags of a link (``kp``, ``kd``, ``minDepth``, ``maxVel``, ``fdir1``).

ROS 1 (gazebo_ros_pkgs noetic-devel) names and defaults: the skid-steer plugin drives ``leftFrontJoint``,
``leftRearJoint`` (``left_front_joint``, ``left_rear_joint``) and their right twins at ``v -+ w wheelSeparation/2``
(``wheelSeparation`` 0.4 m, ``wheelDiameter`` 0.15 m, ``torque`` 5 N m, ``updateRate`` 100 Hz); its odometry is
the model's true pose (``covariance_x``/``_y`` 0.0001, ``covariance_yaw`` 0.01) and tf odom → base only with
``broadcastTF`` (default false).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from navlab.description.errors import DescriptionError
from navlab.description.gazebo_values import scoped
from navlab.description.model import ContactTags, DiffDriveConfig, RosControlConfig
from navlab.description.urdf import floats
from navlab.errors import did_you_mean

SKID_STEER_PLUGINS = ("libgazebo_ros_skid_steer_drive.so",)
ROS_CONTROL_PLUGINS = ("libgazebo_ros_control.so",)
SKID_KEYS = (
    "robotNamespace",
    "broadcastTF",
    "leftFrontJoint",
    "rightFrontJoint",
    "leftRearJoint",
    "rightRearJoint",
    "wheelSeparation",
    "wheelDiameter",
    "torque",
    "commandTopic",
    "odometryTopic",
    "odometryFrame",
    "robotBaseFrame",
    "updateRate",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
)
ROS_CONTROL_KEYS = ("robotNamespace", "controlPeriod", "robotParam", "robotSimType", "legacyModeNS", "eStopTopic")
#: contact tags of ``<gazebo reference="link">`` -> ContactTags field
CONTACT_TAGS = {"kp": "kp", "kd": "kd", "minDepth": "min_depth", "maxVel": "max_vel", "fdir1": "fdir1"}


def _text(plugin: ET.Element, key: str, default: str) -> str:
    el = plugin.find(key)
    return default if el is None or not (el.text or "").strip() else (el.text or "").strip()


def _number(plugin: ET.Element, key: str, default: float, where: str, *, positive: bool = True) -> float:
    v = floats(_text(plugin, key, repr(default)), 1, where, f"<{key}>")[0]
    if v < 0 or (positive and v == 0):
        raise DescriptionError(f"{where}/<{key}>: expected a number {'>' if positive else '>='} 0, got {v}")
    return v


def _unknown(plugin: ET.Element, known: tuple[str, ...], where: str, warnings: list[str]) -> None:
    for child in plugin:
        if isinstance(child.tag, str) and child.tag not in known:
            hint = did_you_mean(child.tag, known, template=" (did you mean <{}>?)")
            warnings.append(f"{where}: unknown parameter <{child.tag}> ignored{hint}")


def parse_skid_steer(plugin: ET.Element, where: str, warnings: list[str]) -> DiffDriveConfig:
    """``libgazebo_ros_skid_steer_drive.so``'s parameters as a four-wheel :class:`DiffDriveConfig`."""
    _unknown(plugin, SKID_KEYS, where, warnings)
    text = _text(plugin, "broadcastTF", "false").lower()
    if text not in ("true", "false", "1", "0"):
        raise DescriptionError(f"{where}/<broadcastTF>: expected true/false, got {text!r}")
    ns = _text(plugin, "robotNamespace", "")
    cov = tuple(
        _number(plugin, f"covariance_{k}", d, where, positive=False)
        for k, d in (("x", 0.0001), ("y", 0.0001), ("yaw", 0.01))
    )
    return DiffDriveConfig(
        left_joint=_text(plugin, "leftFrontJoint", "left_front_joint"),
        right_joint=_text(plugin, "rightFrontJoint", "right_front_joint"),
        extra_left_joints=(_text(plugin, "leftRearJoint", "left_rear_joint"),),
        extra_right_joints=(_text(plugin, "rightRearJoint", "right_rear_joint"),),
        wheel_separation=_number(plugin, "wheelSeparation", 0.4, where),
        wheel_diameter=_number(plugin, "wheelDiameter", 0.15, where),
        max_torque=_number(plugin, "torque", 5.0, where, positive=False),
        update_rate=_number(plugin, "updateRate", 100.0, where, positive=False) or 1000.0,
        command_topic=scoped(ns, _text(plugin, "commandTopic", "cmd_vel")),
        odometry_topic=scoped(ns, _text(plugin, "odometryTopic", "odom")),
        odometry_frame=_text(plugin, "odometryFrame", "odom"),
        robot_base_frame=_text(plugin, "robotBaseFrame", "base_footprint"),
        odometry_source="world",  # the plugin's odometry is the model's pose ("TODO create some non-perfect odometry")
        publish_tf=text in ("true", "1"),
        legacy_mode=False,
        drive="gazebo_ros_skid_steer_drive",
        odom_covariance=(cov[0], cov[1], cov[2]),
    )


def parse_ros_control(plugin: ET.Element, where: str, warnings: list[str]) -> RosControlConfig:
    """``libgazebo_ros_control.so``: its namespace and control period (s; 0 = Gazebo's physics step)."""
    _unknown(plugin, ROS_CONTROL_KEYS, where, warnings)
    sim_type = _text(plugin, "robotSimType", "gazebo_ros_control/DefaultRobotHWSim")
    if sim_type != "gazebo_ros_control/DefaultRobotHWSim":
        warnings.append(f"{where}: robotSimType {sim_type!r}: navlab simulates DefaultRobotHWSim")
    return RosControlConfig(
        namespace=_text(plugin, "robotNamespace", "/"),
        control_period=_number(plugin, "controlPeriod", 0.0, where, positive=False),
    )


def read_contact_tag(contact: ContactTags | None, el: ET.Element, where: str) -> ContactTags:
    """One ODE contact tag (``kp`` ... ``fdir1``; text or ROS 1's ``value=`` attribute) added to ``contact``."""
    out = contact or ContactTags()
    raw = (el.text or "").strip() or el.get("value", "")
    field_name = CONTACT_TAGS[el.tag]
    if field_name == "fdir1":
        x, y, z = floats(raw, 3, where, f"<{el.tag}>")
        if x * x + y * y + z * z < 1e-12:
            raise DescriptionError(f"{where}/<fdir1>: expected a non-zero direction, got {raw!r}")
        out.fdir1 = (x, y, z)
        return out
    v = floats(raw, 1, where, f"<{el.tag}>")[0]
    if v < 0:
        raise DescriptionError(f"{where}/<{el.tag}>: expected a number >= 0, got {v}")
    setattr(out, field_name, v)
    return out
