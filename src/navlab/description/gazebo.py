"""``<gazebo>`` extension tags → plugin configs (diff drive, lidar, imu) and link friction.

Both the ROS 1 (``gazebo_ros_pkgs`` for Gazebo classic, camelCase: ``wheelSeparation``) and the
ROS 2 (``gazebo_ros_pkgs`` for ROS 2, snake_case: ``wheel_separation`` plus ``<ros><remapping>``)
spellings are read. An unknown plugin, sensor type or tag is reported in the returned warnings and
the rest of the robot loads.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from typing import Literal

from navlab.description.errors import DescriptionError
from navlab.description.gazebo_sensors import IMU_MODEL_PLUGINS, parse_imu, parse_lidar, parse_p3d, sensor_plugin
from navlab.description.gazebo_sensors3d import read_sensor3d
from navlab.description.gazebo_values import number, parse_bool, plugin_file, plugin_rate, ros_remaps, scoped
from navlab.description.materials import gazebo_material
from navlab.description.model import DiffDriveConfig, ImuConfig, LidarConfig, Link, Origin, P3dConfig, RosControlConfig
from navlab.description.sensor_model import SensorSuite
from navlab.description.skid_steer import (
    CONTACT_TAGS,
    ROS_CONTROL_PLUGINS,
    SKID_STEER_PLUGINS,
    parse_ros_control,
    parse_skid_steer,
    read_contact_tag,
)
from navlab.description.urdf import floats
from navlab.errors import did_you_mean

DIFF_DRIVE_PLUGINS = ("libgazebo_ros_diff_drive.so",)
LASER_PLUGINS = (
    "libgazebo_ros_laser.so",
    "libgazebo_ros_gpu_laser.so",
    "libgazebo_ros_ray_sensor.so",
    "libgazebo_ros_head_rplidar_controller.so",
)
LASER_PLUGIN_NAMES = (
    "gazebo_ros_laser",
    "gazebo_ros_ray_sensor",
    "gazebo_ros_head_rplidar_controller",
    "gazebo_ros_head_hokuyo_controller",
)
IMU_SENSOR_PLUGINS = ("libgazebo_ros_imu_sensor.so",)
#: plugins whose job navlab's simulator does anyway (joint states, ground truth): no warning
BUILTIN_PLUGINS = ("libgazebo_ros_joint_state_publisher.so",)
P3D_PLUGINS = ("libgazebo_ros_p3d.so",)
#: <gazebo reference="link"> tags understood or harmless to ignore (rendering, ODE contact tuning)
LINK_TAGS = (
    "mu1",
    "mu2",
    "material",
    "kp",
    "kd",
    "minDepth",
    "maxVel",
    "fdir1",
    "selfCollide",
    "self_collide",
    "turnGravityOff",
    "gravity",
    "maxContacts",
    "dampingFactor",
    "sensor",
    "implicitSpringDamper",
    "provideFeedback",
    "stopCfm",
    "stopErp",
    "visual",
    "collision",
    "laserRetro",
    "static",
    "velocity_decay",
    "enable_wind",
    "kinematic",
)

DD_KEYS_ROS1 = {
    "leftJoint": "left_joint",
    "rightJoint": "right_joint",
    "wheelSeparation": "wheel_separation",
    "wheelDiameter": "wheel_diameter",
    "wheelTorque": "max_torque",
    "wheelAcceleration": "max_accel",
    "updateRate": "update_rate",
    "commandTopic": "command_topic",
    "odometryTopic": "odometry_topic",
    "odometryFrame": "odometry_frame",
    "robotBaseFrame": "robot_base_frame",
    "odometrySource": "odometry_source",
    "publishTf": "publish_odom",
    "publishOdomTF": "publish_tf",
    "publishWheelTF": "publish_wheel_tf",
    "robotNamespace": "namespace",
}
#: tags older ROS 1 releases read that Noetic's gazebo_ros_diff_drive does not: the warning names what it reads
DD_NOT_IN_NOETIC = {
    "torque": "<torque> is not read by ROS Noetic's gazebo_ros_diff_drive (ignored since Hydro); it reads "
    "<wheelTorque> (default 5 N m), which applies",
    "legacyMode": "<legacyMode> was removed from gazebo_ros_diff_drive in Melodic (gazebo_ros_pkgs PR #707); "
    "Noetic drives the <leftJoint> joint as the left wheel and <rightJoint> as the right one",
}
DD_KEYS_ROS2 = {
    "left_joint": "left_joint",
    "right_joint": "right_joint",
    "wheel_separation": "wheel_separation",
    "wheel_diameter": "wheel_diameter",
    "max_wheel_torque": "max_torque",
    "max_wheel_acceleration": "max_accel",
    "update_rate": "update_rate",
    "odometry_frame": "odometry_frame",
    "robot_base_frame": "robot_base_frame",
    "odometry_source": "odometry_source",
    "publish_odom_tf": "publish_tf",
    "publish_wheel_tf": "publish_wheel_tf",
    "command_topic": "command_topic",
    "odometry_topic": "odometry_topic",
}
DD_IGNORED = (
    "alwaysOn",
    "rosDebugLevel",
    "publishWheelJointState",
    "publishOdom",
    "publish_odom",
    "ros",
    "num_wheel_pairs",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
    "odometryRate",
)
FLOAT_FIELDS = ("wheel_separation", "wheel_diameter", "max_torque", "max_accel", "update_rate")
BOOL_FIELDS = ("publish_tf", "publish_odom", "publish_wheel_tf")


@dataclass
class GazeboTags:
    """What the ``<gazebo>`` tags of one robot declare."""

    diff_drive: DiffDriveConfig | None = None
    ros_control: RosControlConfig | None = None
    lidars: list[LidarConfig] = field(default_factory=list)
    imus: list[ImuConfig] = field(default_factory=list)
    ground_truths: list[P3dConfig] = field(default_factory=list)
    sensors: SensorSuite = field(default_factory=SensorSuite)  # cameras, 3D lidars, ranges, bumpers
    warnings: list[str] = field(default_factory=list)


def _did_you_mean(key: str, choices: list[str]) -> str:
    return did_you_mean(key, choices, template=" (did you mean <{}>?)")


def parse_diff_drive(plugin: ET.Element, where: str, warnings: list[str]) -> DiffDriveConfig:
    """The ROS 1 or ROS 2 ``libgazebo_ros_diff_drive.so`` plugin parameters."""
    cfg = DiffDriveConfig()
    values: dict[str, str] = {}
    ns, remaps = ros_remaps(plugin)
    known = [*DD_KEYS_ROS1, *DD_KEYS_ROS2, *DD_IGNORED]
    for child in plugin:
        if not isinstance(child.tag, str):
            continue
        key = DD_KEYS_ROS1.get(child.tag) or DD_KEYS_ROS2.get(child.tag)
        if child.tag == "legacyMode" and (child.text or "").strip().lower() in ("false", "0"):
            pass  # what Noetic does anyway: nothing to say
        elif child.tag in DD_NOT_IN_NOETIC:
            warnings.append(f"{where}: {DD_NOT_IN_NOETIC[child.tag]}")
        elif key is not None:
            values[key] = (child.text or "").strip()
        elif child.tag not in DD_IGNORED:
            warnings.append(
                f"{where}: unknown diff-drive parameter <{child.tag}> ignored{_did_you_mean(child.tag, known)}"
            )
    if "odometry_source" not in values:
        cfg.odometry_source = "world"  # both plugins default to the true pose
    for key, raw in values.items():
        w = f"{where}/<{key}>"
        if key in FLOAT_FIELDS:
            v = floats(raw, 1, where, f"{key} value")[0]
            if key in ("wheel_separation", "wheel_diameter") and v <= 0:
                raise DescriptionError(f"{w}: must be positive, got {v}")
            if key in ("max_torque", "max_accel") and v < 0:
                raise DescriptionError(f"{w}: must be >= 0, got {v}")
            setattr(cfg, key, plugin_rate(v) if key == "update_rate" else v)
        elif key in BOOL_FIELDS:
            setattr(cfg, key, parse_bool(raw, where + f" ({key})"))
        elif key == "odometry_source":
            sources: dict[str, Literal["encoder", "world"]] = {
                "0": "encoder",
                "1": "world",
                "encoder": "encoder",
                "world": "world",
            }
            src = sources.get(raw.lower())
            if src is None:
                raise DescriptionError(f"{where}: odometry source {raw!r}: expected encoder/world (0/1)")
            cfg.odometry_source = src
        else:
            setattr(cfg, key, raw)
    if ns:
        cfg.namespace = ns
    if "cmd_vel" in remaps:
        cfg.command_topic = remaps["cmd_vel"]
    if "odom" in remaps:
        cfg.odometry_topic = remaps["odom"]
    cfg.command_topic = scoped(cfg.namespace, cfg.command_topic)
    cfg.odometry_topic = scoped(cfg.namespace, cfg.odometry_topic)
    return cfg


def _is_laser_plugin(plugin: ET.Element) -> bool:
    return plugin_file(plugin) in LASER_PLUGINS or plugin.get("name", "") in LASER_PLUGIN_NAMES


def read_gazebo_tags(root: ET.Element, links: dict[str, Link], joint_names: set[str], source: str) -> GazeboTags:
    """Read every ``<gazebo>`` element of a URDF ``<robot>``; set friction on ``links`` in place."""
    out = GazeboTags()
    imu_sensors: dict[str, ET.Element] = {}
    for gz in root.findall("gazebo"):
        ref = gz.get("reference")
        where = f'{source}: <gazebo reference="{ref}">' if ref else f"{source}: <gazebo>"
        if ref is not None and ref not in links:
            if ref not in joint_names:
                out.warnings.append(f"{where}: no link or joint named {ref!r}; tags ignored")
            continue
        for child in gz:
            if not isinstance(child.tag, str):
                continue
            if ref is not None and child.tag in ("mu1", "mu2"):
                mu = number(child, f"{where}/<{child.tag}>", 0.0)
                if mu < 0:
                    raise DescriptionError(f"{where}/<{child.tag}>: friction {mu}: expected >= 0")
                setattr(links[ref], child.tag, mu)
            elif ref is not None and child.tag in CONTACT_TAGS:
                links[ref].contact = read_contact_tag(links[ref].contact, child, f"{where}/<{child.tag}>")
            elif ref is not None and child.tag == "material":
                _apply_material(links[ref], child, f"{where}/<material>", out.warnings)
            elif ref is not None and child.tag == "sensor":
                _read_sensor(child, ref, where, out, imu_sensors)
            elif child.tag == "plugin":
                _read_model_plugin(child, where, out)
            elif ref is not None and child.tag not in LINK_TAGS:
                out.warnings.append(
                    f"{where}: unknown tag <{child.tag}> ignored{_did_you_mean(child.tag, list(LINK_TAGS))}"
                )
    covered = {imu.link for imu in out.imus}
    for link, sensor in imu_sensors.items():
        if link not in covered:
            out.warnings.append(
                f'{source}: <gazebo reference="{link}">: imu sensor '
                f"{sensor.get('name')!r} has no ROS plugin; nothing is published"
            )
    return out


def _apply_material(link: Link, el: ET.Element, where: str, warnings: list[str]) -> None:
    """``<gazebo reference="link"><material>Gazebo/Orange</material>``: Gazebo draws every visual of the
    link in that named material (over the URDF's ``<material>`` colour)."""
    name = (el.text or "").strip() or (el.findtext("script/name") or "").strip()
    rgba = gazebo_material(name)
    if rgba is None:
        if name:
            warnings.append(
                f"{where}: material {name!r} is not one of Gazebo's named materials navlab knows "
                "(Gazebo/Orange, Gazebo/Grey, ...); the URDF colour is kept"
            )
        return
    link.visuals = [replace(v, rgba=rgba) for v in link.visuals]


def _read_sensor(
    sensor: ET.Element, link: str, where: str, out: GazeboTags, imu_sensors: dict[str, ET.Element]
) -> None:
    stype = sensor.get("type", "")
    w = f'{where}/<sensor name="{sensor.get("name", "")}" type="{stype}">'
    plugin = sensor_plugin(sensor)
    if plugin is not None and read_sensor3d(sensor, plugin, link, w, out.sensors, out.warnings):
        return
    if stype in ("ray", "gpu_ray", "lidar", "gpu_lidar"):
        if plugin is None:
            out.warnings.append(f"{w}: no ROS plugin, so nothing is published; sensor ignored")
        elif not _is_laser_plugin(plugin):
            out.warnings.append(
                f"{w}: unknown plugin {plugin.get('filename')!r} (name {plugin.get('name')!r}); sensor ignored"
            )
        else:
            out.lidars.append(parse_lidar(sensor, link, w, plugin, out.warnings))
    elif stype == "imu":
        if plugin is not None and plugin_file(plugin) in IMU_SENSOR_PLUGINS:
            out.imus.append(parse_imu(plugin, link, w, sensor))
        elif plugin is not None:
            out.warnings.append(f"{w}: unknown plugin {plugin.get('filename')!r}; sensor ignored")
        else:
            imu_sensors[link] = sensor
    else:
        out.warnings.append(
            f"{w}: sensor type {stype!r} is not simulated (navlab has ray/gpu_ray, imu, "
            "camera, depth and contact sensors with their gazebo_ros plugins); ignored"
        )


def _read_model_plugin(plugin: ET.Element, where: str, out: GazeboTags) -> None:
    fname = plugin_file(plugin)
    w = f'{where}/<plugin name="{plugin.get("name", "")}" filename="{plugin.get("filename", "")}">'
    if fname in DIFF_DRIVE_PLUGINS:
        if out.diff_drive is not None:
            out.warnings.append(f"{w}: a second diff-drive plugin; the first one is used")
        else:
            out.diff_drive = parse_diff_drive(plugin, w, out.warnings)
    elif fname in SKID_STEER_PLUGINS:
        if out.diff_drive is not None:
            out.warnings.append(f"{w}: a second drive plugin; the first one is used")
        else:
            out.diff_drive = parse_skid_steer(plugin, w, out.warnings)
    elif fname in ROS_CONTROL_PLUGINS:
        out.ros_control = parse_ros_control(plugin, w, out.warnings)
    elif fname in IMU_MODEL_PLUGINS:
        body = (plugin.findtext("bodyName") or "").strip()
        if not body:
            raise DescriptionError(f"{w}: missing <bodyName> (the IMU's link)")
        out.imus.append(parse_imu(plugin, body, w, None))
    elif fname in P3D_PLUGINS:
        p3d = parse_p3d(plugin, w, out.warnings)
        if p3d is not None:
            out.ground_truths.append(p3d)
    elif fname not in BUILTIN_PLUGINS:
        out.warnings.append(
            f"{w}: unknown plugin, ignored (navlab simulates libgazebo_ros_diff_drive, "
            "skid_steer_drive, gazebo_ros_control, laser/ray-sensor and imu plugins)"
        )


def _side(joint: str, chain: dict[str, tuple[str, Origin]]) -> float:
    """y (m) of a joint's frame in the root link's frame, following parent joints up the tree."""
    pose = Origin()
    name: str | None = joint
    seen: set[str] = set()
    while name is not None and name in chain and name not in seen:
        seen.add(name)
        parent_joint, origin = chain[name]
        pose = origin.then(pose)
        name = parent_joint or None
    return pose.xyz[1]


def swapped_joints_note(dd: DiffDriveConfig, chain: dict[str, tuple[str, Origin]]) -> str | None:
    """How the robot turns when ``<leftJoint>`` names the wheel on the right, else None.

    ``chain``: joint name -> (its parent link's parent joint name or "", its origin), to find on which
    side (+y: left) each wheel sits. ROS Noetic's plugin drives the ``<leftJoint>`` joint as the left
    wheel whatever side it is on, so such a robot turns the opposite way to cmd_vel, in Gazebo and here."""
    if dd.legacy_mode or _side(dd.left_joint, chain) >= _side(dd.right_joint, chain):
        return None
    return (
        f"<leftJoint> {dd.left_joint!r} is the wheel on the right: ROS Noetic's plugin drives it as the left "
        "wheel, so the robot turns the opposite way to cmd_vel's angular.z, as it does in Gazebo"
    )


def check_plugin_joints(
    tags: GazeboTags,
    joints: dict[str, str],
    links: dict[str, Link],
    source: str,
    chain: dict[str, tuple[str, Origin]] | None = None,
) -> None:
    """The diff-drive joints must be continuous/revolute joints; sensors must sit on existing links.

    With ``chain`` (see :func:`swapped_joints_note`) a note on a robot whose left and right joints are
    named the other way round is added to the warnings."""
    dd = tags.diff_drive
    if dd is not None:
        lefts, rights = dd.wheel_joints()
        for role, name in [*(("left", n) for n in lefts), *(("right", n) for n in rights)]:
            if name not in joints:
                raise DescriptionError(
                    f"{source}: diff-drive plugin: {role} joint {name!r} is not a joint of "
                    f"the robot (joints: {', '.join(joints)})"
                )
            if joints[name] not in ("continuous", "revolute"):
                raise DescriptionError(
                    f"{source}: diff-drive plugin: {role} joint {name!r} is {joints[name]}, "
                    "expected continuous or revolute"
                )
        if chain is not None:
            note = swapped_joints_note(dd, chain)
            if note:
                tags.warnings.append(f"{source}: diff-drive plugin: {note}")
    for imu in tags.imus:
        if imu.link not in links:
            raise DescriptionError(f"{source}: imu plugin {imu.name!r}: body {imu.link!r} is not a link")
    for p3d in list(tags.ground_truths):
        if p3d.link not in links:  # Noetic: "bodyName: X does not exist", the plugin does not load
            tags.warnings.append(
                f"{source}: p3d plugin {p3d.name!r}: bodyName {p3d.link!r} is not a link of the "
                "robot; as in ROS Noetic the plugin does not load"
            )
            tags.ground_truths.remove(p3d)
    for lidar in tags.lidars:
        if not math.isfinite(lidar.max_angle - lidar.min_angle) or lidar.max_angle < lidar.min_angle:
            raise DescriptionError(f"{source}: lidar {lidar.name!r}: max_angle < min_angle")
