"""``<gazebo>`` extension tags → plugin configs (diff drive, lidar, imu) and link friction.

Both the ROS 1 (``gazebo_ros_pkgs`` for Gazebo classic, camelCase: ``wheelSeparation``) and the
ROS 2 (``gazebo_ros_pkgs`` for ROS 2, snake_case: ``wheel_separation`` plus ``<ros><remapping>``)
spellings are read. An unknown plugin, sensor type or tag is reported in the returned warnings and
the rest of the robot loads.
"""

from __future__ import annotations

import difflib
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from typing import Literal

from navlab.core.limits import check_ceiling
from navlab.description.errors import DescriptionError
from navlab.description.materials import gazebo_material
from navlab.description.model import DiffDriveConfig, ImuConfig, LidarConfig, Link, Origin, P3dConfig, RosControlConfig
from navlab.description.skid_steer import (
    CONTACT_TAGS,
    ROS_CONTROL_PLUGINS,
    SKID_STEER_PLUGINS,
    parse_ros_control,
    parse_skid_steer,
    read_contact_tag,
)
from navlab.description.urdf import floats

DIFF_DRIVE_PLUGINS = ("libgazebo_ros_diff_drive.so",)
LASER_PLUGINS = ("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so", "libgazebo_ros_ray_sensor.so",
                 "libgazebo_ros_head_rplidar_controller.so")
LASER_PLUGIN_NAMES = ("gazebo_ros_laser", "gazebo_ros_ray_sensor", "gazebo_ros_head_rplidar_controller",
                      "gazebo_ros_head_hokuyo_controller")
IMU_SENSOR_PLUGINS = ("libgazebo_ros_imu_sensor.so",)
IMU_MODEL_PLUGINS = ("libgazebo_ros_imu.so",)
#: plugins whose job navlab's simulator does anyway (joint states, ground truth): no warning
BUILTIN_PLUGINS = ("libgazebo_ros_joint_state_publisher.so",)
P3D_PLUGINS = ("libgazebo_ros_p3d.so",)
#: <gazebo reference="link"> tags understood or harmless to ignore (rendering, ODE contact tuning)
LINK_TAGS = ("mu1", "mu2", "material", "kp", "kd", "minDepth", "maxVel", "fdir1", "selfCollide",
             "self_collide", "turnGravityOff", "gravity", "maxContacts", "dampingFactor", "sensor",
             "implicitSpringDamper", "provideFeedback", "stopCfm", "stopErp", "visual", "collision",
             "laserRetro", "static", "velocity_decay", "enable_wind", "kinematic")

DD_KEYS_ROS1 = {
    "leftJoint": "left_joint", "rightJoint": "right_joint", "wheelSeparation": "wheel_separation",
    "wheelDiameter": "wheel_diameter", "wheelTorque": "max_torque",
    "wheelAcceleration": "max_accel", "updateRate": "update_rate", "commandTopic": "command_topic",
    "odometryTopic": "odometry_topic", "odometryFrame": "odometry_frame",
    "robotBaseFrame": "robot_base_frame", "odometrySource": "odometry_source", "publishTf": "publish_odom",
    "publishOdomTF": "publish_tf", "publishWheelTF": "publish_wheel_tf", "robotNamespace": "namespace",
}
#: tags older ROS 1 releases read that Noetic's gazebo_ros_diff_drive does not: the warning names what it reads
DD_NOT_IN_NOETIC = {
    "torque": "<torque> is not read by ROS Noetic's gazebo_ros_diff_drive (ignored since Hydro); it reads "
              "<wheelTorque> (default 5 N m), which applies",
    "legacyMode": "<legacyMode> was removed from gazebo_ros_diff_drive in Melodic (gazebo_ros_pkgs PR #707); "
                  "Noetic drives the <leftJoint> joint as the left wheel and <rightJoint> as the right one",
}
DD_KEYS_ROS2 = {
    "left_joint": "left_joint", "right_joint": "right_joint", "wheel_separation": "wheel_separation",
    "wheel_diameter": "wheel_diameter", "max_wheel_torque": "max_torque",
    "max_wheel_acceleration": "max_accel", "update_rate": "update_rate",
    "odometry_frame": "odometry_frame", "robot_base_frame": "robot_base_frame",
    "odometry_source": "odometry_source", "publish_odom_tf": "publish_tf",
    "publish_wheel_tf": "publish_wheel_tf", "command_topic": "command_topic",
    "odometry_topic": "odometry_topic",
}
#: tags older laser plugins (or other ones) read that Noetic's gazebo_ros_laser does not: what applies instead
LASER_NOT_IN_NOETIC = {
    "gaussianNoise": "the sensor's <ray><noise> (gaussian, stddev)",
    "hokuyoMinIntensity": "the sensor's intensities as Gazebo computes them",
    "updateRate": "the sensor's <update_rate>",
}
DD_IGNORED = ("alwaysOn", "rosDebugLevel", "publishWheelJointState", "publishOdom", "publish_odom",
              "ros", "num_wheel_pairs", "covariance_x", "covariance_y", "covariance_yaw", "odometryRate")
FLOAT_FIELDS = ("wheel_separation", "wheel_diameter", "max_torque", "max_accel", "update_rate")
BOOL_FIELDS = ("publish_tf", "publish_odom", "publish_wheel_tf")
GAZEBO_DEFAULT_RATE = 1000.0  # Hz: Gazebo's default physics rate; a plugin rate of 0 means every step


@dataclass
class GazeboTags:
    """What the ``<gazebo>`` tags of one robot declare."""

    diff_drive: DiffDriveConfig | None = None
    ros_control: RosControlConfig | None = None
    lidars: list[LidarConfig] = field(default_factory=list)
    imus: list[ImuConfig] = field(default_factory=list)
    ground_truths: list[P3dConfig] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def _bool(text: str, where: str) -> bool:
    t = text.strip().lower()
    if t in ("1", "true", "yes"):
        return True
    if t in ("0", "false", "no"):
        return False
    raise DescriptionError(f"{where}: expected true/false, got {text!r}")


def _num(el: ET.Element | None, where: str, default: float) -> float:
    if el is None or not (el.text or "").strip():
        return default
    return floats(el.text, 1, where, f"<{el.tag}>")[0]


def _remaps(plugin: ET.Element) -> tuple[str, dict[str, str]]:
    """ROS 2 ``<ros><namespace>`` and ``<remapping>from:=to</remapping>`` of a plugin."""
    ros = plugin.find("ros")
    if ros is None:
        return "", {}
    ns = (ros.findtext("namespace") or "").strip()
    remaps = {}
    for r in ros.findall("remapping"):
        src, sep, dst = (r.text or "").partition(":=")
        if sep:
            remaps[src.strip()] = dst.strip()
    return ns, remaps


def _scoped(ns: str, topic: str) -> str:
    """``topic`` in namespace ``ns`` (absolute topics stay as they are)."""
    if not ns or topic.startswith("/"):
        return topic
    return "/" + ns.strip("/") + "/" + topic.lstrip("~/")


def _did_you_mean(key: str, choices: list[str]) -> str:
    close = difflib.get_close_matches(key, choices, n=1)
    return f" (did you mean <{close[0]}>?)" if close else ""


def _rate(value: float) -> float:
    return GAZEBO_DEFAULT_RATE if value <= 0 else value


def parse_diff_drive(plugin: ET.Element, where: str, warnings: list[str]) -> DiffDriveConfig:
    """The ROS 1 or ROS 2 ``libgazebo_ros_diff_drive.so`` plugin parameters."""
    cfg = DiffDriveConfig()
    values: dict[str, str] = {}
    ns, remaps = _remaps(plugin)
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
            warnings.append(f"{where}: unknown diff-drive parameter <{child.tag}> ignored"
                            f"{_did_you_mean(child.tag, known)}")
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
            setattr(cfg, key, _rate(v) if key == "update_rate" else v)
        elif key in BOOL_FIELDS:
            setattr(cfg, key, _bool(raw, where + f" ({key})"))
        elif key == "odometry_source":
            sources: dict[str, Literal["encoder", "world"]] = {
                "0": "encoder", "1": "world", "encoder": "encoder", "world": "world"}  # fmt: skip
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
    cfg.command_topic = _scoped(cfg.namespace, cfg.command_topic)
    cfg.odometry_topic = _scoped(cfg.namespace, cfg.odometry_topic)
    return cfg


def _noetic_default(plugin: ET.Element, tag: str, default: str, what: str, where: str, warnings: list[str]) -> str:
    """``<tag>`` of a ROS 1 plugin, or Noetic's default for it (with a warning naming the tag and the default)."""
    text = plugin.findtext(tag)
    if text is None:
        warnings.append(f"{where}: no <{tag}>: ROS Noetic's {what} then uses {default!r}, and so does navlab")
        return default
    return text.strip()


def _noise(el: ET.Element | None, where: str) -> tuple[float, float]:
    """(mean, stddev) of a ``<noise>`` element (gaussian only; others warn-free zero)."""
    if el is None:
        return 0.0, 0.0
    kind = (el.findtext("type") or el.get("type") or "gaussian").strip()
    if kind == "none":
        return 0.0, 0.0
    return _num(el.find("mean"), where, 0.0), _num(el.find("stddev"), where, 0.0)


def _sensor_plugin(sensor: ET.Element) -> ET.Element | None:
    return sensor.find("plugin")


def parse_lidar(sensor: ET.Element, link: str, where: str, plugin: ET.Element,
                warnings: list[str]) -> LidarConfig:
    """A ray/gpu_ray ``<sensor>`` with a ROS laser plugin."""
    pose = floats(sensor.findtext("pose") or "0 0 0 0 0 0", 6, where, "<pose>")
    ray = sensor.find("ray")
    if ray is None:
        ray = sensor.find("lidar")  # SDF >= 1.7 spelling
    if ray is None:
        raise DescriptionError(f"{where}: a {sensor.get('type')} sensor needs a <ray> element")
    hor = ray.find("scan/horizontal")
    if hor is None:
        raise DescriptionError(f"{where}/<ray>: missing <scan><horizontal>")
    samples = int(_num(hor.find("samples"), where + "/<horizontal>", 640))
    if samples < 1:
        raise DescriptionError(f"{where}/<horizontal>/<samples>: must be >= 1, got {samples}")
    check_ceiling(DescriptionError, f"{where}/<horizontal>", "<samples>", samples, "lidar_samples")
    vert = ray.find("scan/vertical/samples")
    if vert is not None and int(float(vert.text or "1")) > 1:
        warnings.append(f"{where}: {vert.text} vertical samples; only the horizontal plane is simulated")
    rng = ray.find("range")
    rw = where + "/<range>"
    range_min = _num(rng.find("min") if rng is not None else None, rw, 0.0)
    range_max = _num(rng.find("max") if rng is not None else None, rw, 10.0)
    if not 0 <= range_min < range_max:
        raise DescriptionError(f"{rw}: expected 0 <= min < max, got min {range_min}, max {range_max}")
    mean, std = _noise(ray.find("noise") if ray.find("noise") is not None else sensor.find("noise"), where)
    ns, remaps = _remaps(plugin)
    name = plugin.get("name", "")
    ros2 = plugin.find("ros") is not None or _plugin_file(plugin) == "libgazebo_ros_ray_sensor.so"
    if not ros2:  # ROS 1: <topicName>, <frameName>, <robotNamespace>, with Noetic's defaults
        ns = (plugin.findtext("robotNamespace") or "").strip()
        topic = _noetic_default(plugin, "topicName", "/world", "gazebo_ros_laser", where, warnings)
        frame = _noetic_default(plugin, "frameName", "/world", "gazebo_ros_laser", where, warnings)
        for tag, read in LASER_NOT_IN_NOETIC.items():
            if plugin.find(tag) is not None:
                warnings.append(f"{where}: <{tag}> is not read by ROS Noetic's gazebo_ros_laser; {read} applies")
    else:  # ROS 2: node named after the plugin publishes ~/out unless remapped
        topic = remaps.get("~/out") or remaps.get("out") or f"{name or 'ray_sensor'}/out"
        frame = (plugin.findtext("frame_name") or plugin.findtext("frameName") or "").strip()
        out_type = (plugin.findtext("output_type") or "sensor_msgs/LaserScan").strip()
        if out_type.replace("/msg/", "/") != "sensor_msgs/LaserScan":
            warnings.append(f"{where}: output_type {out_type} not supported; publishing sensor_msgs/LaserScan")
    return LidarConfig(
        link=link,
        origin=Origin.from_pose6(pose),
        update_rate=_rate(_num(sensor.find("update_rate"), where, 0.0)),
        samples=samples,
        min_angle=_num(hor.find("min_angle"), where, 0.0),
        max_angle=_num(hor.find("max_angle"), where, 0.0),
        range_min=range_min,
        range_max=range_max,
        range_resolution=_num(rng.find("resolution") if rng is not None else None, rw, 0.0),
        noise_mean=mean,
        noise_stddev=std,
        topic=_scoped(ns, topic or "scan"),
        frame_id=frame.lstrip("/") or link,
        name=sensor.get("name", "laser"),
    )


def _imu_noise(sensor: ET.Element | None, where: str) -> tuple[float, float]:
    """(gyro stddev, accel stddev) from an SDF ``<imu>`` block (first axis that has noise)."""
    if sensor is None or sensor.find("imu") is None:
        return 0.0, 0.0
    imu = sensor.find("imu")
    out = []
    for group in ("angular_velocity", "linear_acceleration"):
        std = 0.0
        for axis in ("x", "y", "z"):
            noise = imu.find(f"{group}/{axis}/noise") if imu is not None else None
            if noise is not None:
                std = _noise(noise, where)[1]
                break
        out.append(std)
    legacy = imu.find("noise") if imu is not None else None  # SDF 1.4 <imu><noise><rate>/<accel>
    if legacy is not None:
        out[0] = out[0] or _num(legacy.find("rate/stddev"), where, 0.0)
        out[1] = out[1] or _num(legacy.find("accel/stddev"), where, 0.0)
    return out[0], out[1]


def parse_imu(plugin: ET.Element, link: str, where: str, sensor: ET.Element | None) -> ImuConfig:
    """An IMU from a sensor plugin (``gazebo_ros_imu_sensor``) or the ROS 1 model plugin ``gazebo_ros_imu``."""
    gyro, accel = _imu_noise(sensor, where)
    if not (gyro or accel):  # the ROS 1 model plugin carries an SDF-1.4-style <imu><noise> block itself
        gyro, accel = _imu_noise(plugin, where)
    gaussian = _num(plugin.find("gaussianNoise"), where, 0.0)
    ns, remaps = _remaps(plugin)
    if plugin.find("ros") is None:  # ROS 1: <topicName>, <frameName>/<bodyName>, <robotNamespace>
        ns = (plugin.findtext("robotNamespace") or "").strip()
        topic = (_noetic_default(plugin, "topicName", "/default_imu", "gazebo_ros_imu", where, [])
                 if _plugin_file(plugin) in IMU_MODEL_PLUGINS else (plugin.findtext("topicName") or "imu").strip())
        frame = (plugin.findtext("frameName") or plugin.findtext("bodyName") or link).strip()
    else:
        topic = remaps.get("~/out") or remaps.get("out") or f"{plugin.get('name') or 'imu'}/out"
        frame = (plugin.findtext("frame_name") or link).strip()
    rate = _num(plugin.find("updateRateHZ"), where, 0.0) or _num(plugin.find("updateRate"), where, 0.0)
    if sensor is not None and not rate:
        rate = _num(sensor.find("update_rate"), where, 0.0)
    pose = floats((sensor.findtext("pose") if sensor is not None else None) or "0 0 0 0 0 0", 6, where, "<pose>")
    return ImuConfig(
        link=link, origin=Origin.from_pose6(pose),
        update_rate=_rate(rate), topic=_scoped(ns, topic), frame_id=frame.lstrip("/"),
        gyro_noise_stddev=gyro or gaussian, accel_noise_stddev=accel or gaussian,
        name=(sensor.get("name", "imu") if sensor is not None else plugin.get("name", "imu")),
    )


def parse_p3d(plugin: ET.Element, where: str, warnings: list[str]) -> P3dConfig | None:
    """A ROS 1 ``libgazebo_ros_p3d`` plugin as Noetic reads it: ``bodyName`` and ``topicName`` required (without
    them the plugin does not load: a warning, and nothing published), ``frameName`` default ``world``,
    ``updateRate`` default 0 (every physics step), ``robotNamespace`` in front of a relative topic."""
    missing = [t for t in ("bodyName", "topicName") if not (plugin.findtext(t) or "").strip()]
    if missing:
        warnings.append(f"{where}: no <{missing[0]}>: ROS Noetic's gazebo_ros_p3d does not load without it; "
                        "nothing is published")
        return None
    ns = (plugin.findtext("robotNamespace") or "").strip()
    return P3dConfig(link=str(plugin.findtext("bodyName")).strip(),
                     topic=_scoped(ns, str(plugin.findtext("topicName")).strip()),
                     frame_id=(plugin.findtext("frameName") or "world").strip().lstrip("/") or "world",
                     update_rate=_rate(_num(plugin.find("updateRate"), where, 0.0)),
                     name=plugin.get("name") or "p3d")


def _plugin_file(plugin: ET.Element) -> str:
    return (plugin.get("filename") or "").rsplit("/", 1)[-1]


def _is_laser_plugin(plugin: ET.Element) -> bool:
    return _plugin_file(plugin) in LASER_PLUGINS or plugin.get("name", "") in LASER_PLUGIN_NAMES


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
                mu = _num(child, f"{where}/<{child.tag}>", 0.0)
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
                out.warnings.append(f"{where}: unknown tag <{child.tag}> ignored"
                                    f"{_did_you_mean(child.tag, list(LINK_TAGS))}")
    covered = {imu.link for imu in out.imus}
    for link, sensor in imu_sensors.items():
        if link not in covered:
            out.warnings.append(f'{source}: <gazebo reference="{link}">: imu sensor '
                                f"{sensor.get('name')!r} has no ROS plugin; nothing is published")
    return out


def _apply_material(link: Link, el: ET.Element, where: str, warnings: list[str]) -> None:
    """``<gazebo reference="link"><material>Gazebo/Orange</material>``: Gazebo draws every visual of the
    link in that named material (over the URDF's ``<material>`` colour)."""
    name = (el.text or "").strip() or (el.findtext("script/name") or "").strip()
    rgba = gazebo_material(name)
    if rgba is None:
        if name:
            warnings.append(f"{where}: material {name!r} is not one of Gazebo's named materials navlab knows "
                            "(Gazebo/Orange, Gazebo/Grey, ...); the URDF colour is kept")
        return
    link.visuals = [replace(v, rgba=rgba) for v in link.visuals]


def _read_sensor(sensor: ET.Element, link: str, where: str, out: GazeboTags,
                 imu_sensors: dict[str, ET.Element]) -> None:
    stype = sensor.get("type", "")
    w = f"{where}/<sensor name=\"{sensor.get('name', '')}\" type=\"{stype}\">"
    plugin = _sensor_plugin(sensor)
    if stype in ("ray", "gpu_ray", "lidar", "gpu_lidar"):
        if plugin is None:
            out.warnings.append(f"{w}: no ROS plugin, so nothing is published; sensor ignored")
        elif not _is_laser_plugin(plugin):
            out.warnings.append(f"{w}: unknown plugin {plugin.get('filename')!r} "
                                f"(name {plugin.get('name')!r}); sensor ignored")
        else:
            out.lidars.append(parse_lidar(sensor, link, w, plugin, out.warnings))
    elif stype == "imu":
        if plugin is not None and _plugin_file(plugin) in IMU_SENSOR_PLUGINS:
            out.imus.append(parse_imu(plugin, link, w, sensor))
        elif plugin is not None:
            out.warnings.append(f"{w}: unknown plugin {plugin.get('filename')!r}; sensor ignored")
        else:
            imu_sensors[link] = sensor
    else:
        out.warnings.append(f"{w}: sensor type {stype!r} is not simulated (navlab has ray/gpu_ray and imu); "
                            "ignored")


def _read_model_plugin(plugin: ET.Element, where: str, out: GazeboTags) -> None:
    fname = _plugin_file(plugin)
    w = f"{where}/<plugin name=\"{plugin.get('name', '')}\" filename=\"{plugin.get('filename', '')}\">"
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
        out.warnings.append(f"{w}: unknown plugin, ignored (navlab simulates libgazebo_ros_diff_drive, "
                            "skid_steer_drive, gazebo_ros_control, laser/ray-sensor and imu plugins)")


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
    return (f"<leftJoint> {dd.left_joint!r} is the wheel on the right: ROS Noetic's plugin drives it as the left "
            "wheel, so the robot turns the opposite way to cmd_vel's angular.z, as it does in Gazebo")


def check_plugin_joints(tags: GazeboTags, joints: dict[str, str], links: dict[str, Link], source: str,
                        chain: dict[str, tuple[str, Origin]] | None = None) -> None:
    """The diff-drive joints must be continuous/revolute joints; sensors must sit on existing links.

    With ``chain`` (see :func:`swapped_joints_note`) a note on a robot whose left and right joints are
    named the other way round is added to the warnings."""
    dd = tags.diff_drive
    if dd is not None:
        lefts, rights = dd.wheel_joints()
        for role, name in [*(("left", n) for n in lefts), *(("right", n) for n in rights)]:
            if name not in joints:
                raise DescriptionError(f"{source}: diff-drive plugin: {role} joint {name!r} is not a joint of "
                                       f"the robot (joints: {', '.join(joints)})")
            if joints[name] not in ("continuous", "revolute"):
                raise DescriptionError(f"{source}: diff-drive plugin: {role} joint {name!r} is {joints[name]}, "
                                       "expected continuous or revolute")
        if chain is not None:
            note = swapped_joints_note(dd, chain)
            if note:
                tags.warnings.append(f"{source}: diff-drive plugin: {note}")
    for imu in tags.imus:
        if imu.link not in links:
            raise DescriptionError(f"{source}: imu plugin {imu.name!r}: body {imu.link!r} is not a link")
    for p3d in list(tags.ground_truths):
        if p3d.link not in links:  # Noetic: "bodyName: X does not exist", the plugin does not load
            tags.warnings.append(f"{source}: p3d plugin {p3d.name!r}: bodyName {p3d.link!r} is not a link of the "
                                 "robot; as in ROS Noetic the plugin does not load")
            tags.ground_truths.remove(p3d)
    for lidar in tags.lidars:
        if not math.isfinite(lidar.max_angle - lidar.min_angle) or lidar.max_angle < lidar.min_angle:
            raise DescriptionError(f"{source}: lidar {lidar.name!r}: max_angle < min_angle")
