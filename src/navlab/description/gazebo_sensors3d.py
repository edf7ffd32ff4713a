"""The ``<sensor>`` tags of cameras, depth cameras, 3D lidars, range sensors and bumpers, read as ROS Noetic's
gazebo_ros plugins read them (parameter names and defaults of ``gazebo_ros_camera_utils``,
``gazebo_ros_openni_kinect``, ``velodyne_gazebo_plugins``' ``GazeboRosVelodyneLaser``, ``gazebo_ros_range`` and
``gazebo_ros_bumper``). A bad value is a :class:`DescriptionError` naming the element and what was expected.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import Any

from navlab.core import check_ceiling
from navlab.description.errors import DescriptionError
from navlab.description.gazebo_sensors import noetic_default, sensor_noise
from navlab.description.gazebo_values import number, parse_bool, plugin_file, plugin_rate, scoped
from navlab.description.model import Origin
from navlab.description.sensor_model import (
    BumperConfig,
    CameraConfig,
    CameraModel,
    Lidar3dConfig,
    RangeConfig,
    SensorSuite,
)
from navlab.description.urdf import floats

CAMERA_PLUGINS = ("libgazebo_ros_camera.so",)
DEPTH_PLUGINS = ("libgazebo_ros_openni_kinect.so", "libgazebo_ros_depth_camera.so")
VELODYNE_PLUGINS = ("libgazebo_ros_velodyne_laser.so", "libgazebo_ros_velodyne_gpu_laser.so")
RANGE_PLUGINS = ("libgazebo_ros_range.so",)
BUMPER_PLUGINS = ("libgazebo_ros_bumper.so",)
SENSOR_PLUGINS = (*CAMERA_PLUGINS, *DEPTH_PLUGINS, *VELODYNE_PLUGINS, *RANGE_PLUGINS, *BUMPER_PLUGINS)
IMAGE_FORMATS = ("R8G8B8", "B8G8R8", "L8")
#: the most samples per pixel ``<image><anti_aliasing>`` may ask for (OpenGL's usual multisampling ceiling)
MAX_ANTI_ALIASING = 16
#: the most image pixels / rays of one sensor navlab accepts
MAX_PIXELS = 4096 * 4096


def read_sensor3d(
    sensor: ET.Element, plugin: ET.Element, link: str, where: str, out: SensorSuite, warnings: list[str]
) -> bool:
    """Add the sensor to ``out`` if its plugin is one of :data:`SENSOR_PLUGINS`; False otherwise."""
    fname = plugin_file(plugin)
    stype = sensor.get("type", "")
    if fname in CAMERA_PLUGINS or fname in DEPTH_PLUGINS:
        wanted = ("camera",) if fname in CAMERA_PLUGINS else ("depth", "depth_camera", "camera", "rgbd_camera")
        _expect_type(stype, wanted, fname, where)
        out.cameras.append(
            parse_camera(sensor, plugin, link, where, warnings, kind="camera" if fname in CAMERA_PLUGINS else "depth")
        )
    elif fname in VELODYNE_PLUGINS:
        _expect_type(stype, ("ray", "gpu_ray"), fname, where)
        out.lidars3d.append(parse_velodyne(sensor, plugin, link, where, warnings))
    elif fname in RANGE_PLUGINS:
        _expect_type(stype, ("ray", "gpu_ray"), fname, where)
        out.ranges.append(parse_range(sensor, plugin, link, where, warnings))
    elif fname in BUMPER_PLUGINS:
        _expect_type(stype, ("contact",), fname, where)
        out.bumpers.append(parse_bumper(sensor, plugin, link, where, warnings))
    else:
        return False
    return True


def _expect_type(stype: str, wanted: tuple[str, ...], fname: str, where: str) -> None:
    if stype not in wanted:
        raise DescriptionError(f"{where}: {fname} needs a sensor of type {' or '.join(wanted)}, got {stype!r}")


def _rate(sensor: ET.Element, plugin: ET.Element, where: str) -> float:
    """The sensor's ``<update_rate>`` throttled by the plugin's ``<updateRate>`` (0: the sensor's), in Hz."""
    rate = number(sensor.find("update_rate"), where + "/<update_rate>", 0.0)
    throttle = number(plugin.find("updateRate"), where + "/<updateRate>", 0.0)
    if rate < 0 or throttle < 0:
        raise DescriptionError(f"{where}: <update_rate>/<updateRate> must be >= 0, got {rate}/{throttle}")
    if throttle > 0 and (rate <= 0 or throttle < rate):
        rate = throttle
    return plugin_rate(rate)


def _pose(sensor: ET.Element, where: str) -> Origin:
    return Origin.from_pose6(floats(sensor.findtext("pose") or "0 0 0 0 0 0", 6, where, "<pose>"))


def parse_camera_model(cam: ET.Element | None, where: str) -> CameraModel:
    """The SDF ``<camera>`` element (``<horizontal_fov>``, ``<image>`` with SDF 1.9's ``<anti_aliasing>``,
    ``<clip>``, ``<noise>``)."""
    if cam is None:
        raise DescriptionError(f"{where}: a camera sensor needs a <camera> element")
    w = where + "/<camera>"
    hfov = number(cam.find("horizontal_fov"), w + "/<horizontal_fov>", 1.047)
    if not 0 < hfov < math.pi:
        raise DescriptionError(f"{w}/<horizontal_fov>: expected 0 < fov < pi rad, got {hfov}")
    width = number(cam.find("image/width"), w + "/<image>/<width>", 320)
    height = number(cam.find("image/height"), w + "/<image>/<height>", 240)
    if width < 1 or height < 1 or width != int(width) or height != int(height):
        raise DescriptionError(f"{w}/<image>: width and height must be whole numbers >= 1, got {width} x {height}")
    if width * height > MAX_PIXELS:
        raise DescriptionError(
            f"{w}/<image>: {width:.0f} x {height:.0f} pixels, more than navlab's ceiling of "
            f"{MAX_PIXELS:,} (4096 x 4096)"
        )
    fmt = (cam.findtext("image/format") or "R8G8B8").strip()
    if fmt not in IMAGE_FORMATS:
        raise DescriptionError(f"{w}/<image>/<format>: {fmt!r} not supported; expected one of {IMAGE_FORMATS}")
    aa = number(cam.find("image/anti_aliasing"), w + "/<image>/<anti_aliasing>", 4)
    if aa != int(aa) or not 0 <= aa <= MAX_ANTI_ALIASING:
        raise DescriptionError(
            f"{w}/<image>/<anti_aliasing>: expected a whole number of samples per pixel from 0 (off) to "
            f"{MAX_ANTI_ALIASING}, got {aa}"
        )
    near = number(cam.find("clip/near"), w + "/<clip>/<near>", 0.1)
    far = number(cam.find("clip/far"), w + "/<clip>/<far>", 100.0)
    if not 0 < near < far:
        raise DescriptionError(f"{w}/<clip>: expected 0 < near < far, got near {near}, far {far}")
    mean, std = sensor_noise(cam.find("noise"), w + "/<noise>")
    if std < 0:
        raise DescriptionError(f"{w}/<noise>/<stddev>: must be >= 0, got {std}")
    return CameraModel(
        width=int(width),
        height=int(height),
        horizontal_fov=hfov,
        near=near,
        far=far,
        format=fmt,
        noise_mean=mean,
        noise_stddev=std,
        anti_aliasing=int(aa),
    )


def parse_camera(
    sensor: ET.Element, plugin: ET.Element, link: str, where: str, warnings: list[str], *, kind: str
) -> CameraConfig:
    """``gazebo_ros_camera`` / ``gazebo_ros_openni_kinect``: GazeboRosCameraUtils' tags with Noetic's defaults."""
    cam = parse_camera_model(sensor.find("camera"), where)
    ns = (plugin.findtext("robotNamespace") or "").strip()
    name = (plugin.findtext("cameraName") or "").strip()
    frame = (plugin.findtext("frameName") or "").strip()
    if not frame:
        warnings.append(
            f"{where}: no <frameName>: ROS Noetic's camera plugin then stamps images with an empty "
            f"frame; navlab uses the link {link!r}"
        )
    depth = kind == "depth"
    cfg = CameraConfig(
        link=link,
        kind=kind,
        origin=_pose(sensor, where),
        update_rate=_rate(sensor, plugin, where),
        camera=cam,
        camera_name=name,
        frame_id=frame.lstrip("/") or link,
        name=sensor.get("name", "camera"),
    )
    prefix = scoped(ns, name) if name else ns.strip("/")

    def topic(tag: str, default: str) -> str:
        value = (plugin.findtext(tag) or "").strip() or default
        return value if value.startswith("/") else scoped(prefix, value) if prefix else value

    cfg.image_topic = topic("imageTopicName", "ir/image_raw" if depth else "image_raw")
    cfg.camera_info_topic = topic("cameraInfoTopicName", "ir/camera_info" if depth else "camera_info")
    cfg.depth_image_topic = topic("depthImageTopicName", "depth/image_raw")
    cfg.depth_info_topic = topic("depthImageCameraInfoTopicName", "depth/camera_info")
    cfg.point_cloud_topic = topic("pointCloudTopicName", "points")
    cfg.point_cloud_cutoff = number(plugin.find("pointCloudCutoff"), where + "/<pointCloudCutoff>", 0.4)
    cfg.point_cloud_cutoff_max = number(plugin.find("pointCloudCutoffMax"), where + "/<pointCloudCutoffMax>", 5.0)
    if depth and not 0 <= cfg.point_cloud_cutoff < cfg.point_cloud_cutoff_max:
        raise DescriptionError(
            f"{where}: expected 0 <= <pointCloudCutoff> < <pointCloudCutoffMax>, got "
            f"{cfg.point_cloud_cutoff} and {cfg.point_cloud_cutoff_max}"
        )
    cfg.hack_baseline = number(plugin.find("hackBaseline"), where + "/<hackBaseline>", 0.0)
    k1, k2, k3, t1, t2 = (
        number(plugin.find(f"distortion{k}"), f"{where}/<distortion{k}>", 0.0) for k in ("K1", "K2", "K3", "T1", "T2")
    )
    cfg.distortion = (k1, k2, t1, t2, k3)
    if any(cfg.distortion):
        warnings.append(
            f"{where}: lens distortion (<distortionK1>..) is reported in CameraInfo.D but not applied "
            "to the simulated image"
        )
    return cfg


def _ray_grid(sensor: ET.Element, where: str) -> tuple[ET.Element, dict[str, float]]:
    """The ``<ray>`` element and its scan grid and range (samples, angles, vertical ones, min, max, noise)."""
    ray = sensor.find("ray")
    if ray is None:
        ray = sensor.find("lidar")
    if ray is None:
        raise DescriptionError(f"{where}: a {sensor.get('type')} sensor needs a <ray> element")
    out: dict[str, float] = {}
    for axis in ("horizontal", "vertical"):
        el = ray.find(f"scan/{axis}")
        w = f"{where}/<ray>/<scan>/<{axis}>"
        samples = number(el.find("samples") if el is not None else None, w + "/<samples>", 1)
        if samples < 1 or samples != int(samples):
            raise DescriptionError(f"{w}/<samples>: expected a whole number >= 1, got {samples}")
        lo = number(el.find("min_angle") if el is not None else None, w + "/<min_angle>", 0.0)
        hi = number(el.find("max_angle") if el is not None else None, w + "/<max_angle>", 0.0)
        if hi < lo:
            raise DescriptionError(f"{w}: max_angle {hi} < min_angle {lo}")
        if axis == "vertical" and not -math.pi / 2 <= lo <= hi <= math.pi / 2:
            raise DescriptionError(f"{w}: vertical angles must lie in [-pi/2, pi/2], got {lo} .. {hi}")
        out[f"{axis}_samples"], out[f"{axis}_min"], out[f"{axis}_max"] = int(samples), lo, hi
    check_ceiling(
        DescriptionError, f"{where}/<ray>/<scan>/<horizontal>", "<samples>", out["horizontal_samples"], "lidar_samples"
    )
    if out["horizontal_samples"] * out["vertical_samples"] > MAX_PIXELS:
        raise DescriptionError(
            f"{where}/<ray>/<scan>: {out['horizontal_samples'] * out['vertical_samples']:,.0f} "
            f"rays, more than navlab's ceiling of {MAX_PIXELS:,}"
        )
    rng = ray.find("range")
    rw = f"{where}/<ray>/<range>"
    out["min"] = number(rng.find("min") if rng is not None else None, rw + "/<min>", 0.0)
    out["max"] = number(rng.find("max") if rng is not None else None, rw + "/<max>", 10.0)
    if not 0 <= out["min"] < out["max"]:
        raise DescriptionError(f"{rw}: expected 0 <= min < max, got min {out['min']}, max {out['max']}")
    out["noise"] = sensor_noise(ray.find("noise"), rw)[1]
    return ray, out


def _ray_fields(sensor: ET.Element, plugin: ET.Element, link: str, where: str, g: dict[str, Any]) -> dict[str, Any]:
    """The description fields a 3D lidar and a range sensor share: pose, rate and the ``<ray>`` grid ``g``'s
    angles and range (its vertical sample count is ``rings`` of one, ``vertical_samples`` of the other)."""
    return {
        "link": link,
        "origin": _pose(sensor, where),
        "update_rate": _rate(sensor, plugin, where),
        "samples": int(g["horizontal_samples"]),
        "min_angle": g["horizontal_min"],
        "max_angle": g["horizontal_max"],
        "vertical_min_angle": g["vertical_min"],
        "vertical_max_angle": g["vertical_max"],
        "range_min": g["min"],
        "range_max": g["max"],
    }


def parse_velodyne(sensor: ET.Element, plugin: ET.Element, link: str, where: str, warnings: list[str]) -> Lidar3dConfig:
    """``GazeboRosVelodyneLaser`` (velodyne_gazebo_plugins): ``<topicName>`` (default ``/world``), ``<frameName>``
    (``/world``), ``<min_range>`` (0), ``<max_range>`` (inf), ``<gaussianNoise>`` (0), ``<robotNamespace>``,
    ``<organize_cloud>`` (false)."""
    _, g = _ray_grid(sensor, where)
    ns = (plugin.findtext("robotNamespace") or "").strip()
    topic = noetic_default(plugin, "topicName", "/world", "velodyne laser plugin", where, warnings)
    frame = noetic_default(plugin, "frameName", "/world", "velodyne laser plugin", where, warnings)
    noise = number(plugin.find("gaussianNoise"), where + "/<gaussianNoise>", 0.0)
    if noise < 0:
        raise DescriptionError(f"{where}/<gaussianNoise>: must be >= 0, got {noise}")
    organize = plugin.findtext("organize_cloud")
    return Lidar3dConfig(
        **_ray_fields(sensor, plugin, link, where, g),
        rings=int(g["vertical_samples"]),
        min_range=number(plugin.find("min_range"), where + "/<min_range>", 0.0),
        max_range=number(plugin.find("max_range"), where + "/<max_range>", math.inf),
        noise_stddev=math.hypot(noise, g["noise"]),
        topic=scoped(ns, topic),
        frame_id=frame.lstrip("/") or link,
        organize_cloud=parse_bool(organize, where + "/<organize_cloud>") if organize else False,
        name=sensor.get("name", "velodyne"),
    )


def parse_range(sensor: ET.Element, plugin: ET.Element, link: str, where: str, warnings: list[str]) -> RangeConfig:
    """``gazebo_ros_range``: ``<topicName>`` (``/range``), ``<frameName>`` (``/world``), ``<radiation>``
    (``ultrasound``; anything else is infrared), ``<fov>`` (0.05 rad), ``<gaussianNoise>`` (0), ``<updateRate>``."""
    _, g = _ray_grid(sensor, where)
    ns = (plugin.findtext("robotNamespace") or "").strip()
    topic = noetic_default(plugin, "topicName", "/range", "gazebo_ros_range", where, warnings)
    frame = noetic_default(plugin, "frameName", "/world", "gazebo_ros_range", where, warnings)
    radiation = noetic_default(plugin, "radiation", "ultrasound", "gazebo_ros_range", where, warnings).lower()
    if radiation not in ("ultrasound", "infrared"):
        raise DescriptionError(f"{where}/<radiation>: expected ultrasound or infrared, got {radiation!r}")
    fov = float(noetic_default(plugin, "fov", "0.05", "gazebo_ros_range", where, warnings) or 0.05)
    noise = number(plugin.find("gaussianNoise"), where + "/<gaussianNoise>", 0.0)
    if not 0 < fov < math.pi or noise < 0:
        raise DescriptionError(f"{where}: expected 0 < <fov> < pi and <gaussianNoise> >= 0, got {fov} and {noise}")
    return RangeConfig(
        **_ray_fields(sensor, plugin, link, where, g),
        vertical_samples=int(g["vertical_samples"]),
        radiation=radiation,
        fov=fov,
        noise_stddev=math.hypot(noise, g["noise"]),
        topic=scoped(ns.strip("/"), topic),
        frame_id=frame.lstrip("/") or link,
        name=sensor.get("name", "range"),
    )


def parse_bumper(sensor: ET.Element, plugin: ET.Element, link: str, where: str, warnings: list[str]) -> BumperConfig:
    """``gazebo_ros_bumper`` on a contact sensor: ``<bumperTopicName>`` (``bumper_states``), ``<frameName>``
    (``world``), ``<robotNamespace>``; the sensor's ``<contact><collision>`` names the collision it watches."""
    collision = (sensor.findtext("contact/collision") or "").strip()
    if not collision:
        raise DescriptionError(f"{where}: a contact sensor needs <contact><collision>NAME</collision></contact>")
    ns = (plugin.findtext("robotNamespace") or "").strip()
    topic = (plugin.findtext("bumperTopicName") or "bumper_states").strip()
    frame = (plugin.findtext("frameName") or "world").strip()
    return BumperConfig(
        link=link,
        collision=collision,
        update_rate=_rate(sensor, plugin, where),
        topic=scoped(ns, topic),
        frame_id=frame.lstrip("/") or "world",
        name=sensor.get("name", "bumper"),
    )
