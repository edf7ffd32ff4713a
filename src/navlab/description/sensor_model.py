"""Configs of the gazebo_ros sensors beyond the planar laser and IMU: cameras, depth cameras, 3D lidars,
range (sonar/IR) sensors and bumpers, as their Noetic plugins read them from a robot's ``<gazebo>`` tags.

Plain dataclasses in SI units; ``origin`` is the sensor's ``<pose>`` in ``link``'s frame (Gazebo's camera
looks along the sensor frame's +x, y left, z up; the published images use the ``frameName`` frame, usually
an ``*_optical_frame`` with z forward, x right, y down, as in ROS).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from navlab.description.model import Origin


@dataclass(frozen=True)
class CameraModel:
    """The ``<camera>`` element: image size (px), horizontal field of view (rad), clip planes (m), pixel format,
    gaussian noise on each pixel value (std dev on the 0..1 scale, as Gazebo's image noise) and the colour
    image's multisample anti-aliasing (``<image><anti_aliasing>``, SDF 1.9: samples per pixel; 0 or 1: off)."""

    width: int = 320
    height: int = 240
    horizontal_fov: float = 1.047  # SDF's default (60 degrees)
    near: float = 0.1
    far: float = 100.0
    format: str = "R8G8B8"
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    anti_aliasing: int = 4  # SDF's default

    @property
    def focal_length(self) -> float:
        """Pixels: ``width / (2 tan(hfov / 2))`` (gazebo_ros_camera_utils' computed focal length)."""
        return self.width / (2.0 * math.tan(self.horizontal_fov / 2.0))

    @property
    def cx(self) -> float:
        """Principal point x (px), Noetic's default ``(width + 1) / 2``."""
        return (self.width + 1.0) / 2.0

    @property
    def cy(self) -> float:
        """Principal point y (px), Noetic's default ``(height + 1) / 2``."""
        return (self.height + 1.0) / 2.0


@dataclass
class CameraConfig:
    """``libgazebo_ros_camera.so`` (``kind="camera"``) or ``libgazebo_ros_openni_kinect.so`` (``kind="depth"``).

    Topics are ``<robotNamespace>/<cameraName>/<topic>``. A depth camera publishes the depth image (32FC1,
    metres along the optical axis, NaN outside ``[point_cloud_cutoff, point_cloud_cutoff_max]``), the organised
    ``PointCloud2`` (x, y, z, rgb in the optical frame) and both camera infos; its colour image is published
    only when ``image_topic`` has a subscriber."""

    link: str
    kind: str = "camera"  # "camera" | "depth"
    origin: Origin = field(default_factory=Origin)
    update_rate: float = 30.0  # Hz
    camera: CameraModel = CameraModel()
    camera_name: str = ""
    image_topic: str = "image_raw"
    camera_info_topic: str = "camera_info"
    depth_image_topic: str = "depth/image_raw"
    depth_info_topic: str = "depth/camera_info"
    point_cloud_topic: str = "points"
    point_cloud_cutoff: float = 0.4  # m
    point_cloud_cutoff_max: float = 5.0  # m
    frame_id: str = ""
    hack_baseline: float = 0.0
    distortion: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)  # k1 k2 t1 t2 k3
    name: str = "camera"


@dataclass
class Lidar3dConfig:
    """A ``libgazebo_ros_velodyne_laser.so`` ray sensor: ``samples`` x ``rings`` rays, azimuths from ``min_angle``
    to ``max_angle`` and ring elevations from ``vertical_min_angle`` to ``vertical_max_angle`` (rad, both
    inclusive); points kept when ``max(min_range, range_min) < r < min(max_range, range_max - range_min - 0.01)``
    (the plugin's rule); ``noise_stddev`` the plugin's ``<gaussianNoise>`` (m) plus the ray's own noise."""

    link: str
    origin: Origin = field(default_factory=Origin)
    update_rate: float = 10.0
    samples: int = 1875
    min_angle: float = -math.pi
    max_angle: float = math.pi
    rings: int = 16
    vertical_min_angle: float = -0.2618
    vertical_max_angle: float = 0.2618
    range_min: float = 0.3
    range_max: float = 100.0
    min_range: float = 0.0  # the plugin's <min_range>
    max_range: float = math.inf  # the plugin's <max_range>
    noise_stddev: float = 0.0
    topic: str = "/world"
    frame_id: str = ""
    organize_cloud: bool = False
    name: str = "velodyne"


@dataclass
class RangeConfig:
    """``libgazebo_ros_range.so`` on a ray sensor: ``sensor_msgs/Range`` = the nearest of the sensor's rays (its
    ``<scan>`` grid, ``samples`` x ``vertical_samples``), ``radiation`` ``ultrasound`` (sonar) or ``infrared``,
    ``fov`` (rad) reported, ``noise_stddev`` the plugin's ``<gaussianNoise>`` (m)."""

    link: str
    origin: Origin = field(default_factory=Origin)
    update_rate: float = 10.0
    samples: int = 1
    min_angle: float = 0.0
    max_angle: float = 0.0
    vertical_samples: int = 1
    vertical_min_angle: float = 0.0
    vertical_max_angle: float = 0.0
    range_min: float = 0.02
    range_max: float = 4.0
    radiation: str = "ultrasound"
    fov: float = 0.05
    noise_stddev: float = 0.0
    topic: str = "/range"
    frame_id: str = ""
    name: str = "range"


@dataclass
class BumperConfig:
    """``libgazebo_ros_bumper.so`` on a ``contact`` sensor: ``gazebo_msgs/ContactsState`` of ``link``'s collisions
    (``collision``: the ``<contact><collision>`` name) on ``topic`` in ``frame_id`` at ``update_rate`` Hz."""

    link: str
    collision: str = ""
    update_rate: float = 20.0
    topic: str = "bumper_states"
    frame_id: str = "world"
    name: str = "bumper"


SensorConfig = CameraConfig | Lidar3dConfig | RangeConfig | BumperConfig


@dataclass
class SensorSuite:
    """The extra sensors of one robot, by kind."""

    cameras: list[CameraConfig] = field(default_factory=list)
    lidars3d: list[Lidar3dConfig] = field(default_factory=list)
    ranges: list[RangeConfig] = field(default_factory=list)
    bumpers: list[BumperConfig] = field(default_factory=list)

    def all(self) -> list[SensorConfig]:
        """Every sensor, cameras first."""
        return [*self.cameras, *self.lidars3d, *self.ranges, *self.bumpers]
