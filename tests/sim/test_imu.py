"""The IMU plugin (gazebo_ros_imu_sensor): Gazebo's noise model, its statistics, the message it publishes."""

from __future__ import annotations

import numpy as np
import pytest
from sim_helpers import make_mybot, make_room

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.description import ImuConfig, load_robot_named
from navlab.sim import SimError, launch_sim
from navlab.sim.imu import AxisNoise, ImuNoise, noise_from_description

SENSOR = """<robot name="mybot"><gazebo reference="chassis"><sensor type="imu" name="imu"><imu>
<angular_velocity>{gyro}</angular_velocity><linear_acceleration>{accel}</linear_acceleration></imu></sensor></gazebo></robot>"""
AXIS = "<{a}><noise type='gaussian'><mean>{m}</mean><stddev>{s}</stddev><bias_mean>{b}</bias_mean></noise></{a}>"


def _xml(gyro: tuple[float, float, float], accel: tuple[float, float, float]) -> str:
    return SENSOR.format(
        gyro="".join(AXIS.format(a=a, m=gyro[0], s=gyro[1], b=gyro[2]) for a in "xyz"),
        accel="".join(AXIS.format(a=a, m=accel[0], s=accel[1], b=accel[2]) for a in "xyz"),
    )


def test_noise_statistics_match_the_parameters_over_10000_samples() -> None:
    gyro = AxisNoise(mean=(0.02, 0.0, -0.01), stddev=(0.01, 0.02, 0.005), bias_mean=(0.03, 0.0, 0.0))
    accel = AxisNoise(stddev=(0.05, 0.05, 0.1), bias_mean=(0.1, 0.2, 0.0), bias_stddev=(0.0, 0.0, 0.0))
    noise = ImuNoise(gyro, accel, np.random.default_rng(7))
    assert np.abs(noise.gyro_bias) == pytest.approx([0.03, 0.0, 0.0])  # drawn once, with a random sign
    g, a = noise.apply(np.zeros((10_000, 3)), np.tile([0.0, 0.0, 9.81], (10_000, 1)))
    want_g = np.array(gyro.mean) + noise.gyro_bias
    want_a = np.array([0.0, 0.0, 9.81]) + noise.accel_bias
    for got, want, std in ((g, want_g, gyro.stddev), (a, want_a, accel.stddev)):
        for k in range(3):
            if want[k] != 0.0:
                assert got[:, k].mean() == pytest.approx(want[k], rel=0.05)
            else:
                assert abs(got[:, k].mean()) < 0.05 * std[k]
            assert got[:, k].std() == pytest.approx(std[k], rel=0.05)


def test_plugin_publishes_noisy_imu_in_its_frame_with_covariances() -> None:
    robot = make_mybot()
    robot.imus.append(ImuConfig(link="chassis", update_rate=500.0, topic="imu", frame_id="chassis", name="imu"))
    robot.urdf_xml = _xml((0.05, 0.02, 0.0), (0.0, 0.05, 0.0))
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=robot, seed=3)
    got: list = []
    Node("probe", context=Context(ex)).create_subscription(msgs.Imu, "imu", got.append)
    ex.run(21.0)  # the last 10,000 samples at 500 Hz, at rest (the first second: the robot settles on the floor)
    assert len(got) == pytest.approx(10_500, abs=1)
    got = got[-10_000:]
    m = got[-1]
    assert m.header.frame_id == "chassis"
    assert m.angular_velocity_covariance[0] == pytest.approx(0.02**2)
    assert m.linear_acceleration_covariance[8] == pytest.approx(0.05**2)
    gyro = np.array([[x.angular_velocity.x, x.angular_velocity.y, x.angular_velocity.z] for x in got])
    acc = np.array([[x.linear_acceleration.x, x.linear_acceleration.y, x.linear_acceleration.z] for x in got])
    assert gyro.mean(axis=0) == pytest.approx([0.05] * 3, rel=0.05)
    assert gyro.std(axis=0) == pytest.approx([0.02] * 3, rel=0.05)
    assert acc.std(axis=0) == pytest.approx([0.05] * 3, rel=0.05)
    assert acc[:, 2].mean() == pytest.approx(9.81, abs=0.01)  # gravity, as a real accelerometer reads
    assert abs(msgs.yaw_from_quaternion(m.orientation)) < 1e-3
    del gazebo


def test_mybot_has_an_imu_with_gazebo_noise() -> None:
    robot = load_robot_named("mybot")
    (imu,) = robot.imus
    assert (imu.link, imu.frame_id, imu.topic, imu.update_rate) == ("chassis", "chassis", "imu", 100.0)
    gyro, accel = noise_from_description(robot, imu)
    assert gyro.stddev == (2e-4, 2e-4, 2e-4) and accel.bias_mean == (0.1, 0.1, 0.1)


def test_bad_noise_is_refused() -> None:
    with pytest.raises(SimError, match="stddev: expected numbers >= 0"):
        AxisNoise(stddev=(0.1, -0.1, 0.0))
    with pytest.raises(SimError, match="three finite numbers"):
        AxisNoise(mean=(0.1, 0.2))  # type: ignore[arg-type]
