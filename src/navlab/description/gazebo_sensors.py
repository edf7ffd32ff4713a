"""gazebo_ros sensor plugins as Noetic reads them: the laser (``<ray>`` sensors), the IMU (sensor and model
plugins) and p3d ground truth."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from navlab.core import check_ceiling
from navlab.description.errors import DescriptionError
from navlab.description.gazebo_values import number, plugin_file, plugin_rate, ros_remaps, scoped
from navlab.description.model import ImuConfig, LidarConfig, Origin, P3dConfig
from navlab.description.urdf import floats

IMU_MODEL_PLUGINS = ("libgazebo_ros_imu.so",)
#: tags older laser plugins (or other ones) read that Noetic's gazebo_ros_laser does not: what applies instead
LASER_NOT_IN_NOETIC = {
    "gaussianNoise": "the sensor's <ray><noise> (gaussian, stddev)",
    "hokuyoMinIntensity": "the sensor's intensities as Gazebo computes them",
    "updateRate": "the sensor's <update_rate>",
}


def noetic_default(plugin: ET.Element, tag: str, default: str, what: str, where: str, warnings: list[str]) -> str:
    """``<tag>`` of a ROS 1 plugin, or Noetic's default for it (with a warning naming the tag and the default)."""
    text = plugin.findtext(tag)
    if text is None:
        warnings.append(f"{where}: no <{tag}>: ROS Noetic's {what} then uses {default!r}, and so does navlab")
        return default
    return text.strip()


def sensor_noise(el: ET.Element | None, where: str) -> tuple[float, float]:
    """(mean, stddev) of a ``<noise>`` element (gaussian only; others warn-free zero)."""
    if el is None:
        return 0.0, 0.0
    kind = (el.findtext("type") or el.get("type") or "gaussian").strip()
    if kind == "none":
        return 0.0, 0.0
    return number(el.find("mean"), where, 0.0), number(el.find("stddev"), where, 0.0)


def sensor_plugin(sensor: ET.Element) -> ET.Element | None:
    return sensor.find("plugin")


def parse_lidar(sensor: ET.Element, link: str, where: str, plugin: ET.Element, warnings: list[str]) -> LidarConfig:
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
    samples = int(number(hor.find("samples"), where + "/<horizontal>", 640))
    if samples < 1:
        raise DescriptionError(f"{where}/<horizontal>/<samples>: must be >= 1, got {samples}")
    check_ceiling(DescriptionError, f"{where}/<horizontal>", "<samples>", samples, "lidar_samples")
    vert = ray.find("scan/vertical/samples")
    if vert is not None and int(float(vert.text or "1")) > 1:
        warnings.append(f"{where}: {vert.text} vertical samples; only the horizontal plane is simulated")
    rng = ray.find("range")
    rw = where + "/<range>"
    range_min = number(rng.find("min") if rng is not None else None, rw, 0.0)
    range_max = number(rng.find("max") if rng is not None else None, rw, 10.0)
    if not 0 <= range_min < range_max:
        raise DescriptionError(f"{rw}: expected 0 <= min < max, got min {range_min}, max {range_max}")
    mean, std = sensor_noise(ray.find("noise") if ray.find("noise") is not None else sensor.find("noise"), where)
    ns, remaps = ros_remaps(plugin)
    name = plugin.get("name", "")
    ros2 = plugin.find("ros") is not None or plugin_file(plugin) == "libgazebo_ros_ray_sensor.so"
    if not ros2:  # ROS 1: <topicName>, <frameName>, <robotNamespace>, with Noetic's defaults
        ns = (plugin.findtext("robotNamespace") or "").strip()
        topic = noetic_default(plugin, "topicName", "/world", "gazebo_ros_laser", where, warnings)
        frame = noetic_default(plugin, "frameName", "/world", "gazebo_ros_laser", where, warnings)
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
        update_rate=plugin_rate(number(sensor.find("update_rate"), where, 0.0)),
        samples=samples,
        min_angle=number(hor.find("min_angle"), where, 0.0),
        max_angle=number(hor.find("max_angle"), where, 0.0),
        range_min=range_min,
        range_max=range_max,
        range_resolution=number(rng.find("resolution") if rng is not None else None, rw, 0.0),
        noise_mean=mean,
        noise_stddev=std,
        topic=scoped(ns, topic or "scan"),
        frame_id=frame.lstrip("/") or link,
        name=sensor.get("name", "laser"),
    )


def imu_noise(sensor: ET.Element | None, where: str) -> tuple[float, float]:
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
                std = sensor_noise(noise, where)[1]
                break
        out.append(std)
    legacy = imu.find("noise") if imu is not None else None  # SDF 1.4 <imu><noise><rate>/<accel>
    if legacy is not None:
        out[0] = out[0] or number(legacy.find("rate/stddev"), where, 0.0)
        out[1] = out[1] or number(legacy.find("accel/stddev"), where, 0.0)
    return out[0], out[1]


def parse_imu(plugin: ET.Element, link: str, where: str, sensor: ET.Element | None) -> ImuConfig:
    """An IMU from a sensor plugin (``gazebo_ros_imu_sensor``) or the ROS 1 model plugin ``gazebo_ros_imu``."""
    gyro, accel = imu_noise(sensor, where)
    if not (gyro or accel):  # the ROS 1 model plugin carries an SDF-1.4-style <imu><noise> block itself
        gyro, accel = imu_noise(plugin, where)
    gaussian = number(plugin.find("gaussianNoise"), where, 0.0)
    ns, remaps = ros_remaps(plugin)
    if plugin.find("ros") is None:  # ROS 1: <topicName>, <frameName>/<bodyName>, <robotNamespace>
        ns = (plugin.findtext("robotNamespace") or "").strip()
        topic = (
            noetic_default(plugin, "topicName", "/default_imu", "gazebo_ros_imu", where, [])
            if plugin_file(plugin) in IMU_MODEL_PLUGINS
            else (plugin.findtext("topicName") or "imu").strip()
        )
        frame = (plugin.findtext("frameName") or plugin.findtext("bodyName") or link).strip()
    else:
        topic = remaps.get("~/out") or remaps.get("out") or f"{plugin.get('name') or 'imu'}/out"
        frame = (plugin.findtext("frame_name") or link).strip()
    rate = number(plugin.find("updateRateHZ"), where, 0.0) or number(plugin.find("updateRate"), where, 0.0)
    if sensor is not None and not rate:
        rate = number(sensor.find("update_rate"), where, 0.0)
    pose = floats((sensor.findtext("pose") if sensor is not None else None) or "0 0 0 0 0 0", 6, where, "<pose>")
    return ImuConfig(
        link=link,
        origin=Origin.from_pose6(pose),
        update_rate=plugin_rate(rate),
        topic=scoped(ns, topic),
        frame_id=frame.lstrip("/"),
        gyro_noise_stddev=gyro or gaussian,
        accel_noise_stddev=accel or gaussian,
        name=(sensor.get("name", "imu") if sensor is not None else plugin.get("name", "imu")),
    )


def parse_p3d(plugin: ET.Element, where: str, warnings: list[str]) -> P3dConfig | None:
    """A ROS 1 ``libgazebo_ros_p3d`` plugin as Noetic reads it: ``bodyName`` and ``topicName`` required (without
    them the plugin does not load: a warning, and nothing published), ``frameName`` default ``world``,
    ``updateRate`` default 0 (every physics step), ``robotNamespace`` in front of a relative topic."""
    missing = [t for t in ("bodyName", "topicName") if not (plugin.findtext(t) or "").strip()]
    if missing:
        warnings.append(
            f"{where}: no <{missing[0]}>: ROS Noetic's gazebo_ros_p3d does not load without it; nothing is published"
        )
        return None
    ns = (plugin.findtext("robotNamespace") or "").strip()
    return P3dConfig(
        link=str(plugin.findtext("bodyName")).strip(),
        topic=scoped(ns, str(plugin.findtext("topicName")).strip()),
        frame_id=(plugin.findtext("frameName") or "world").strip().lstrip("/") or "world",
        update_rate=plugin_rate(number(plugin.find("updateRate"), where, 0.0)),
        name=plugin.get("name") or "p3d",
    )
