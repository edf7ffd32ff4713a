"""``gazebo_ros_imu_sensor``: an IMU's ``sensor_msgs/Imu`` with Gazebo's noise model.

Gazebo's gaussian sensor noise, per axis of the angular velocity (rad/s) and the linear acceleration
(m/s²): a bias drawn once when the sensor starts, ``N(bias_mean, bias_stddev)`` with a random sign,
then every sample ``true + mean + bias + N(0, stddev)``. The noise comes from the SDF ``<imu>`` block
(``<angular_velocity><x><noise>`` ... with ``mean``, ``stddev``, ``bias_mean``, ``bias_stddev``) and the
plugin's ``<gaussianNoise>`` (stddev on every axis, as in ``RobotModel.imus``). Orientation is the IMU
frame's orientation in the world; rates and accelerations are in the IMU frame (gravity included, as a
real accelerometer reads). Covariances: the noise variances on the diagonals (orientation: the
angular velocity's, as the ROS 1 plugin sets ``gaussianNoise²``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from navlab import msgs
from navlab.description import ImuConfig, RobotModel
from navlab.geometry import xyzw_from_wxyz
from navlab.sim.errors import SimError
from navlab.sim.plugins import SensorPlugin

AXES = ("x", "y", "z")


@dataclass(frozen=True)
class AxisNoise:
    """Gazebo gaussian noise of one channel's three axes: each field is (x, y, z)."""

    mean: tuple[float, float, float] = (0.0, 0.0, 0.0)
    stddev: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bias_mean: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bias_stddev: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for key in ("mean", "stddev", "bias_mean", "bias_stddev"):
            v = np.asarray(getattr(self, key), dtype=np.float64)
            if v.shape != (3,) or not np.isfinite(v).all():
                raise SimError(f"imu noise {key}: expected three finite numbers (x, y, z), got {getattr(self, key)!r}")
            if key.endswith("stddev") and (v < 0).any():
                raise SimError(f"imu noise {key}: expected numbers >= 0, got {getattr(self, key)!r}")


class ImuNoise:
    """Noise of one IMU (pure): ``bias`` drawn at construction from ``rng``; ``apply`` adds the rest.

    ``apply(gyro, accel)`` takes the true values, arrays (..., 3), and returns noisy copies.
    """

    def __init__(self, gyro: AxisNoise, accel: AxisNoise, rng: np.random.Generator) -> None:
        self.gyro, self.accel, self.rng = gyro, accel, rng
        self.gyro_bias = self._bias(gyro)
        self.accel_bias = self._bias(accel)

    def _bias(self, n: AxisNoise) -> np.ndarray:
        """Gazebo's: N(bias_mean, bias_stddev) per axis, then a random sign."""
        mean, std = np.asarray(n.bias_mean, dtype=np.float64), np.asarray(n.bias_stddev, dtype=np.float64)
        if not (mean.any() or std.any()):
            return np.zeros(3)
        sign = np.where(self.rng.random(3) < 0.5, -1.0, 1.0)
        return (mean + std * self.rng.standard_normal(3)) * sign

    def _noisy(self, value: np.ndarray, n: AxisNoise, bias: np.ndarray) -> np.ndarray:
        out = np.asarray(value, dtype=np.float64) + np.asarray(n.mean) + bias
        if any(n.stddev):
            out = out + self.rng.standard_normal(out.shape) * np.asarray(n.stddev)
        return out

    def apply(self, gyro: np.ndarray, accel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Noisy (angular velocity rad/s, linear acceleration m/s²)."""
        return self._noisy(gyro, self.gyro, self.gyro_bias), self._noisy(accel, self.accel, self.accel_bias)


def _float(el: ET.Element | None, tag: str) -> float | None:
    text = el.findtext(tag) if el is not None else None
    if text is None or not text.strip():
        return None
    try:
        return float(text)
    except ValueError:
        raise SimError(f"imu <noise><{tag}>: expected a number, got {text!r}") from None


def noise_from_description(robot: RobotModel, cfg: ImuConfig) -> tuple[AxisNoise, AxisNoise]:
    """(angular velocity, linear acceleration) noise of IMU ``cfg``: the per-axis SDF ``<noise>`` blocks of
    its ``<sensor>`` in the robot's URDF, else the plugin's stddevs on every axis."""
    gyro_std, accel_std = cfg.gyro_noise_stddev, cfg.accel_noise_stddev
    base = {"angular_velocity": gyro_std, "linear_acceleration": accel_std}
    sensor = _find_sensor(robot.urdf_xml, cfg)
    out = []
    for group, std in base.items():
        fields: dict[str, list[float]] = {"mean": [], "stddev": [], "bias_mean": [], "bias_stddev": []}
        for axis in AXES:
            noise = sensor.find(f"imu/{group}/{axis}/noise") if sensor is not None else None
            for key, values in fields.items():
                v = _float(noise, key)
                values.append(v if v is not None else (std if key == "stddev" else 0.0))
        out.append(AxisNoise(**{k: (v[0], v[1], v[2]) for k, v in fields.items()}))
    return out[0], out[1]


def _find_sensor(urdf_xml: str, cfg: ImuConfig) -> ET.Element | None:
    if not urdf_xml:
        return None
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError:
        return None
    for gz in root.findall("gazebo"):
        if gz.get("reference") != cfg.link:
            continue
        for sensor in gz.findall("sensor"):
            if sensor.get("type") == "imu" and sensor.get("name", "imu") == cfg.name:
                return sensor
    return None


class ImuSensorPlugin(SensorPlugin[ImuConfig]):
    """``gazebo_ros_imu_sensor`` for the robot's IMU number ``index``: ``sensor_msgs/Imu`` on the
    configured topic every ``1/update_rate`` s, stamped with simulated time, in the IMU's frame
    (``frameName``/``bodyName``, else its link)."""

    static_frame = False
    idle_unread = True
    robot_sensors = "imus"

    def setup(self) -> None:
        cfg, sim = self.cfg, self.sim
        assert sim.robot is not None
        gyro, accel = noise_from_description(sim.robot, cfg)
        self.noise_model = (gyro, accel)
        self.noise: ImuNoise | None = None  # drawn at the first reading, from the node's (seeded) generator
        self.site = sim.info.imu_sites[self.index]
        g2, a2 = np.square(gyro.stddev), np.square(accel.stddev)
        self.cov = (np.diag(g2).ravel(), np.diag(g2).ravel(), np.diag(a2).ravel())
        self.pub = self.create_publisher(msgs.Imu, cfg.topic, 10)

    def reading(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(quaternion x y z w in the world, noisy angular velocity rad/s, noisy acceleration m/s²)."""
        d = self.sim.data
        site = self.site
        if self.noise is None:
            self.noise = ImuNoise(*self.noise_model, self.rng)
        quat = d.sensor(f"{site}_quat").data
        gyro, accel = self.noise.apply(d.sensor(f"{site}_gyro").data, d.sensor(f"{site}_accel").data)
        return np.array(xyzw_from_wxyz(quat)), gyro, accel

    def unread(self) -> bool:
        """Whether nobody subscribes or listens (a recorder, ``topic echo``): the timer then idles."""
        return not self.read(self.pub)

    def update(self) -> None:
        """Read the IMU and publish, when anyone subscribes or listens: a 100 Hz message nobody reads cost ~6 %
        of a navigation run's CPU (navlab bench nav), and its timer events ~1 % of a mapping run's."""
        if self.unread():
            return
        quat, gyro, accel = self.reading()
        self.pub.publish(
            msgs.Imu(
                header=msgs.header(self.get_clock().now_ns(), self.frame_id),
                orientation=msgs.quaternion_msg(quat),
                orientation_covariance=self.cov[0].copy(),
                angular_velocity=msgs.vector3(gyro),
                angular_velocity_covariance=self.cov[1].copy(),
                linear_acceleration=msgs.vector3(accel),
                linear_acceleration_covariance=self.cov[2].copy(),
            )
        )
