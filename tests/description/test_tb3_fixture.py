"""A third-party ROS 1 robot (TurtleBot3-burger-style package) loads with no edits to its files."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from navlab.description import load_robot

PKG = Path(__file__).parents[1] / "fixtures" / "turtlebot3_description"
TOP = PKG / "urdf" / "turtlebot3_burger.urdf.xacro"


def _digest() -> str:
    return hashlib.sha1(b"".join(p.read_bytes() for p in sorted(PKG.rglob("*")) if p.is_file())).hexdigest()


@pytest.fixture(scope="module")
def burger():
    before = _digest()
    robot = load_robot(TOP)  # $(find turtlebot3_description) found by walking up to package.xml
    assert _digest() == before  # nothing in the package was touched
    return robot


def test_structure(burger):
    assert burger.name == "turtlebot3_burger" and burger.root_link == "base_footprint"
    assert set(burger.links) == {
        "base_footprint",
        "base_link",
        "wheel_left_link",
        "wheel_right_link",
        "caster_back_link",
        "imu_link",
        "base_scan",
    }
    types = {j.name: j.type for j in burger.joints}
    assert types["wheel_left_joint"] == types["wheel_right_joint"] == "continuous"
    assert types["base_joint"] == types["scan_joint"] == types["imu_joint"] == "fixed"
    left = next(j for j in burger.joints if j.name == "wheel_left_joint")
    assert left.origin.rpy == pytest.approx((-1.57, 0.0, 0.0)) and left.axis == (0.0, 0.0, 1.0)
    assert burger.links["base_link"].inertial.ixy == pytest.approx(-1.2294101e-05)
    assert burger.links["base_footprint"].inertial is None  # massless root, fixed to base_link


def test_meshes_resolved_from_package_uris(burger):
    geom = burger.links["base_link"].visuals[0].geometry
    assert geom.kind == "mesh"
    assert geom.mesh_path == PKG / "meshes" / "bases" / "burger_base.stl"
    assert geom.mesh_path.is_absolute() and geom.mesh_path.exists()
    assert geom.mesh_scale == pytest.approx((0.001, 0.001, 0.001))
    # <gazebo reference="base_link"><material>Gazebo/DarkGrey: Gazebo draws it so, over the URDF colour
    assert burger.links["base_link"].visuals[0].rgba == pytest.approx((0.175, 0.175, 0.175, 1.0))
    assert "package://" not in str(burger.links["base_scan"].visuals[0].geometry.mesh_path)


def test_plugins(burger):
    dd = burger.diff_drive
    assert (dd.left_joint, dd.right_joint) == ("wheel_left_joint", "wheel_right_joint")
    assert dd.wheel_separation == pytest.approx(0.16) and dd.wheel_diameter == pytest.approx(0.066)
    assert dd.max_torque == 10 and dd.max_accel == 1  # <wheelTorque>, <wheelAcceleration>
    assert dd.robot_base_frame == "base_footprint" and dd.odometry_source == "world"
    (lidar,) = burger.lidars
    assert lidar.link == "base_scan" and lidar.samples == 360 and lidar.update_rate == 5
    assert (lidar.range_min, lidar.range_max) == (0.12, 3.5)
    assert lidar.max_angle == pytest.approx(6.28319) and lidar.topic == "scan" and lidar.frame_id == "base_scan"
    (imu,) = burger.imus
    assert imu.link == "imu_link" and imu.topic == "imu" and imu.frame_id == "imu_link"
    assert imu.gyro_noise_stddev == pytest.approx(2e-4) and imu.accel_noise_stddev == pytest.approx(1.7e-2)
    assert burger.links["wheel_left_link"].mu1 == pytest.approx(0.1)
    assert burger.warnings == []


def test_copied_package_loads_through_search_path(tmp_path):
    """The same package, found by search path instead of by walking up (a catkin workspace layout)."""
    import shutil

    ws = tmp_path / "catkin_ws" / "src"
    shutil.copytree(PKG, ws / "turtlebot3" / "turtlebot3_description")
    top = tmp_path / "burger.urdf.xacro"
    top.write_text(
        '<robot name="b" xmlns:xacro="http://ros.org/wiki/xacro"><xacro:include '
        'filename="$(find turtlebot3_description)/urdf/turtlebot3_burger.urdf.xacro"/></robot>'
    )
    robot = load_robot(top, search_paths=[ws])
    assert robot.links["base_link"].visuals[0].geometry.mesh_path.is_relative_to(ws)


def test_load_by_package_uri():
    robot = load_robot("package://turtlebot3_description/urdf/turtlebot3_burger.urdf.xacro", search_paths=[PKG.parent])
    assert robot.name == "turtlebot3_burger" and robot.source == TOP
