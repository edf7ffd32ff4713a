"""Robots other than mybot: a massless base_footprint root, an IMU, a wheel acceleration limit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import make_mybot, make_room

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.description import ImuConfig, Joint, Link, Origin
from navlab.sim import Simulation, launch_sim
from navlab.sim.diffdrive import EncoderOdometry, ramp, wheel_speeds


def _with_footprint_and_imu() -> object:
    """mybot under a massless ``base_footprint`` root (TurtleBot-style) with an IMU on the chassis."""
    robot = make_mybot(odometry_source="world")
    robot.links["base_footprint"] = Link("base_footprint")
    robot.joints.insert(0, Joint("base_joint", "fixed", "base_footprint", "chassis", Origin((0.0, 0.0, 0.08))))
    robot.root_link = "base_footprint"
    robot.diff_drive.robot_base_frame = "base_footprint"  # type: ignore[union-attr]
    robot.imus.append(ImuConfig(link="chassis", update_rate=100.0, topic="imu", gyro_noise_stddev=0.001))
    return robot


def test_massless_root_imu_and_world_odometry() -> None:
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=_with_footprint_and_imu())  # type: ignore[arg-type]
    sim = gazebo.sim
    assert sim.link_pose("base_footprint").position[2] == pytest.approx(0.0, abs=0.005)  # on the floor
    imu, odom = [], []
    probe = Node("probe", context=Context(ex))
    probe.create_subscription(msgs.Imu, "imu", imu.append)
    probe.create_subscription(msgs.Odometry, "odom", odom.append)
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.0, 0.8)))
    ex.run(2.0)
    assert len(imu) == pytest.approx(200, abs=1)
    assert imu[-1].angular_velocity.z == pytest.approx(0.8, abs=0.05)  # yaw rate in the IMU frame
    assert imu[-1].linear_acceleration.z == pytest.approx(9.81, abs=0.3)  # gravity, as a real IMU reads
    assert imu[-1].header.frame_id == "chassis"
    # odometrySource world: odom is the true pose of base_footprint
    x, y, _ = msgs.pose2d(odom[-1].pose.pose)
    tx, ty, tyaw = sim.base_pose2d("base_footprint")
    assert (x, y) == pytest.approx((tx, ty), abs=1e-3)
    assert ex.tf.lookup_pose2d("odom", "base_footprint")[2] == pytest.approx(tyaw, abs=0.05)


def test_wheel_acceleration_limit_ramps_speed() -> None:
    robot = make_mybot()
    robot.diff_drive.max_accel = 0.5  # type: ignore[union-attr]  # m/s² at the wheel rim, as Gazebo applies it
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=robot)
    probe = Node("probe", context=Context(ex))
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.05, lambda: cmd.publish(msgs.twist(0.5, 0.0)))
    ex.run(0.55)
    v = gazebo.sim.link_velocity()[0][0]
    assert v == pytest.approx(0.25, abs=0.04)  # half-way up the 1 s ramp, not at 0.5 m/s


def test_pure_kinematics() -> None:
    assert wheel_speeds(0.5, 0.0, 0.4, 0.16) == pytest.approx((6.25, 6.25))
    assert wheel_speeds(0.0, 1.0, 0.4, 0.16) == pytest.approx((-2.5, 2.5))
    assert ramp(0.0, 10.0, 5.0, 0.1) == pytest.approx(0.5)
    assert ramp(0.0, 10.0, 0.0, 0.1) == 10.0
    odo = EncoderOdometry(0.4, 0.16)
    odo.reset(0.0, 0.0)
    # a quarter circle of radius 1 m: outer wheel 1.2 m, inner 0.8 m of arc
    steps = 100
    for k in range(1, steps + 1):
        x, y, yaw, v, w = odo.update(0.8 * math.pi / 2 / 0.08 * k / steps, 1.2 * math.pi / 2 / 0.08 * k / steps, 0.01)
    assert (x, y, yaw) == pytest.approx((1.0, 1.0, math.pi / 2), abs=1e-3)
    assert w == pytest.approx(math.pi / 2, rel=1e-6)  # rad/s: (pi/2 / 100) rad per 0.01 s
    assert np.isfinite(v)


def test_scan_ignores_robot_itself_and_world_without_robot_works() -> None:
    sim = Simulation(make_mybot(noise=0.0), make_room())
    ranges = sim.scan()
    assert np.all(ranges[np.isfinite(ranges)] > 3.9)  # only the room's walls, never the chassis or wheels
    empty = Simulation(None, make_room())
    empty.step(10)
    assert empty.model_names() == ["wall_north", "wall_south", "wall_east", "wall_west"]


def test_turtlebot3_fixture_drives_and_scans() -> None:
    """A third-party ROS 1 package (TurtleBot3 burger style: 28 g wheels, mu 0.1, LDS at 5 Hz) unedited."""
    from pathlib import Path

    from navlab.description import load_robot

    top = Path(__file__).parents[1] / "fixtures" / "turtlebot3_description" / "urdf" / "turtlebot3_burger.urdf.xacro"
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=load_robot(top), pose=(3.0, 0.0, 0.0))
    scans = []
    probe = Node("probe", context=Context(ex))
    probe.create_subscription(msgs.LaserScan, "scan", scans.append)
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.2, 0.0)))
    ex.run(3.0)
    x, y, yaw = gazebo.sim.base_pose2d()
    assert x - 3.0 == pytest.approx(0.2 * 2.9, abs=0.05) and abs(y) < 0.02 and abs(yaw) < 0.02
    assert len(scans) == 15 and len(scans[-1].ranges) == 360  # 5 Hz, 360 beams
    # beam 0 looks straight ahead from base_scan (3.2 cm behind base_link) to the wall at x = 5
    laser_x = gazebo.sim.link_pose("base_scan").position[0]
    assert scans[-1].ranges[0] == pytest.approx(5.0 - laser_x, abs=0.05)
