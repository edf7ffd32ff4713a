"""The shipped mybot description carries the paper's Table I numbers and plugin settings."""

from __future__ import annotations

import math
import shutil

import pytest

from navlab import resources
from navlab.description import load_robot


@pytest.fixture(scope="module")
def mybot():
    return load_robot(resources.robot("mybot"))


def _joint(robot, name):
    return next(j for j in robot.joints if j.name == name)


def test_table_one_links(mybot):
    chassis = mybot.links["chassis"]
    assert mybot.name == "mybot" and mybot.root_link == "chassis"
    assert chassis.collisions[0].geometry.kind == "cylinder"
    assert chassis.collisions[0].geometry.size == pytest.approx((0.2, 0.05))
    assert chassis.inertial.mass == pytest.approx(10.0)
    for side in ("left", "right"):
        wheel = mybot.links[f"{side}_wheel"]
        assert wheel.collisions[0].geometry.kind == "cylinder"
        assert wheel.collisions[0].geometry.size == pytest.approx((0.08, 0.03))
        assert wheel.inertial.mass == pytest.approx(2.0)
    for end in ("front", "back"):
        caster = mybot.links[f"caster_{end}"]
        assert caster.collisions[0].geometry.kind == "sphere"
        assert caster.collisions[0].geometry.size == pytest.approx((0.04,))
        assert caster.inertial.mass == pytest.approx(0.5)
        assert caster.mu1 == 0.0 and caster.mu2 == 0.0  # frictionless casters in mybot.gazebo
    assert "laser" in mybot.links
    total = sum(link.inertial.mass for link in mybot.links.values())
    assert total == pytest.approx(15.0, abs=1e-3)


def test_inertia_is_that_of_solid_shapes(mybot):
    c = mybot.links["chassis"].inertial
    assert c.izz == pytest.approx(10 * 0.2**2 / 2)
    assert c.ixx == pytest.approx(10 * (3 * 0.2**2 + 0.05**2) / 12)
    w = mybot.links["left_wheel"].inertial
    assert w.iyy == pytest.approx(2 * 0.08**2 / 2)  # spin axis along y


def test_wheel_joints_are_continuous_along_y_and_0_4_m_apart(mybot):
    left, right = _joint(mybot, "left_wheel_hinge"), _joint(mybot, "right_wheel_hinge")
    for j in (left, right):
        assert j.type == "continuous" and j.parent == "chassis"
        assert j.axis == pytest.approx((0.0, 1.0, 0.0))
    assert left.origin.xyz[1] > 0 > right.origin.xyz[1]  # REP-103: left is +y
    assert left.origin.xyz[1] - right.origin.xyz[1] == pytest.approx(0.4)
    # the wheel's rolling cylinder is turned onto the y axis
    assert abs(mybot.links["left_wheel"].collisions[0].origin.rpy[0]) == pytest.approx(math.pi / 2)


def test_robot_stands_level_on_wheels_and_casters(mybot):
    """Lowest points of both wheels and both casters lie at the same height, under the chassis."""
    wheel_bottoms = [_joint(mybot, f"{s}_wheel_hinge").origin.xyz[2] - 0.08 for s in ("left", "right")]
    caster_joints = [_joint(mybot, f"caster_{e}_joint") for e in ("front", "back")]
    caster_bottoms = [j.origin.xyz[2] - 0.04 for j in caster_joints]
    assert wheel_bottoms == pytest.approx(caster_bottoms * 1, abs=1e-9)
    assert caster_joints[0].origin.xyz[0] > 0 > caster_joints[1].origin.xyz[0]
    assert all(j.type == "fixed" for j in caster_joints)
    chassis_bottom = -0.025
    assert min(wheel_bottoms) < chassis_bottom
    # casters sit inside the chassis outline
    assert all(abs(j.origin.xyz[0]) + 0.04 <= 0.2 for j in caster_joints)


def test_laser_sits_0_06_m_above_the_chassis_top(mybot):
    joint = _joint(mybot, "laser_joint")
    assert joint.type == "fixed" and joint.child == "laser"
    lidar = mybot.lidars[0]
    assert lidar.link == "laser"
    assert joint.origin.xyz[2] + lidar.origin.xyz[2] - 0.025 == pytest.approx(0.06)


def test_diff_drive_plugin_matches_the_paper(mybot):
    dd = mybot.diff_drive
    assert dd is not None
    assert (dd.left_joint, dd.right_joint) == ("left_wheel_hinge", "right_wheel_hinge")
    assert dd.update_rate == 30 and dd.wheel_separation == 0.4 and dd.wheel_diameter == 0.16
    assert dd.max_torque == 5.0  # the paper wrote <torque>15</torque>, which Noetic does not read (wheelTorque default)
    assert (dd.command_topic, dd.odometry_topic, dd.odometry_frame) == ("cmd_vel", "odom", "odom")
    assert dd.robot_base_frame == "chassis" and dd.odometry_source == "encoder"
    assert dd.legacy_mode is False
    assert mybot.warnings == []


def test_lidar_matches_the_paper(mybot):
    (lidar,) = mybot.lidars
    assert lidar.samples == 720 and lidar.update_rate == 40
    assert lidar.min_angle == pytest.approx(-math.pi, abs=1e-6)
    assert lidar.max_angle == pytest.approx(math.pi, abs=1e-6)
    assert (lidar.range_min, lidar.range_max, lidar.range_resolution) == (0.2, 25.0, 0.01)
    assert (lidar.noise_mean, lidar.noise_stddev) == (0.0, 0.01)
    assert lidar.topic == "/mybot/laser/scan" and lidar.frame_id == "laser"


def test_urdf_xml_is_fully_expanded(mybot):
    assert "xacro:" not in mybot.urdf_xml and "$(find" not in mybot.urdf_xml
    assert '<robot name="mybot"' in mybot.urdf_xml


def test_user_search_path_overrides_shipped_package(tmp_path):
    """$(find mybot_description) resolves through the user's search path first."""
    pkg = tmp_path / "src" / "mybot_description"
    shutil.copytree(resources.path("robots/mybot"), pkg)
    gz = pkg / "mybot.gazebo"
    gz.write_text(gz.read_text().replace("<wheelSeparation>0.4<", "<wheelSeparation>0.5<"))
    robot = load_robot(pkg / "mybot.xacro", search_paths=[tmp_path / "src"])
    assert robot.diff_drive.wheel_separation == 0.5


def test_ros_package_path_is_searched(tmp_path, monkeypatch):
    pkg = tmp_path / "ws" / "mybot_description"
    shutil.copytree(resources.path("robots/mybot"), pkg)
    gz = pkg / "mybot.gazebo"
    gz.write_text(gz.read_text().replace("<wheelSeparation>0.4<", "<wheelSeparation>0.7<"))
    top = tmp_path / "elsewhere" / "robot.xacro"
    top.parent.mkdir()
    top.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find mybot_description)/mybot.xacro"/></robot>'
    )
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    assert load_robot(top).diff_drive.wheel_separation == 0.7
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    assert load_robot(top).diff_drive.wheel_separation == 0.4  # falls back to the shipped package


def test_xacro_args(tmp_path):
    f = tmp_path / "arg.xacro"
    f.write_text("""<robot name="a" xmlns:xacro="http://www.ros.org/wiki/xacro">
      <xacro:arg name="mass" default="1.0"/>
      <link name="base"><inertial><mass value="$(arg mass)"/>
        <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>""")
    assert load_robot(f).links["base"].inertial.mass == 1.0
    assert load_robot(f, args={"mass": "2.5"}).links["base"].inertial.mass == 2.5


def test_rplidar_visual_is_a_collada_mesh_in_millimetres(mybot):
    """The paper inserts the RPLidar A2 as a .dae mesh; it is converted for MuJoCo with its units."""
    (visual,) = mybot.links["laser"].visuals
    geom = visual.geometry
    assert geom.kind == "mesh" and geom.mesh_source.name == "rplidar_a2.dae"
    assert geom.mesh_path.suffix == ".obj" and geom.mesh_path.exists()
    assert geom.mesh_scale == pytest.approx((0.001, 0.001, 0.001))
    from navlab.description.meshes import read_mesh

    verts, _ = read_mesh(geom.mesh_path)
    height = verts[:, 2].max() * geom.mesh_scale[2]
    assert 0.04 < height <= mybot.lidars[0].origin.xyz[2]  # the scanner's top is just under the rays
