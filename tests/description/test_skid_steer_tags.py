"""Skid-steer <gazebo> tags: libgazebo_ros_skid_steer_drive.so's names and defaults, libgazebo_ros_control.so, ODE
contact tags, bad values as one clear error, and a robot package's own control/EKF files."""

from __future__ import annotations

from pathlib import Path

import pytest

from navlab.description import DescriptionError, load_robot
from navlab.description.robot_files import robot_files

FIXTURE = Path(__file__).parents[1] / "fixtures" / "skidbot_description"
WHEEL = (
    '<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" '
    'izz="0.01"/></inertial><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision>'
    '</link><joint name="{n}_joint" type="continuous"><parent link="base_link"/><child link="{n}"/>'
    '<origin xyz="{x} {y} 0"/><axis xyz="0 1 0"/></joint>'
)
BODY = (
    '<link name="base_link"><inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" '
    'izz="0.1"/></inertial></link>'
    + "".join(
        WHEEL.format(n=n, x=x, y=y)
        for n, x, y in (
            ("left_front", 0.1, 0.15),
            ("left_rear", -0.1, 0.15),
            ("right_front", 0.1, -0.15),
            ("right_rear", -0.1, -0.15),
        )
    )
)


def _robot(tmp_path: Path, tags: str):
    f = tmp_path / "r.urdf"
    f.write_text(f'<robot name="r">{BODY}{tags}</robot>')
    return load_robot(f)


def test_skid_steer_plugin_defaults_are_noetic_ones(tmp_path: Path) -> None:
    plugin = (
        '<gazebo><plugin name="s" filename="libgazebo_ros_skid_steer_drive.so">'
        "<leftFrontJoint>left_front_joint</leftFrontJoint><rightFrontJoint>right_front_joint</rightFrontJoint>"
        "<leftRearJoint>left_rear_joint</leftRearJoint><rightRearJoint>right_rear_joint</rightRearJoint>"
        "<robotNamespace>/r1</robotNamespace></plugin></gazebo>"
    )
    dd = _robot(tmp_path, plugin).diff_drive
    assert dd is not None and dd.drive == "gazebo_ros_skid_steer_drive"
    assert (dd.wheel_separation, dd.wheel_diameter, dd.max_torque, dd.update_rate) == (0.4, 0.15, 5.0, 100.0)
    assert (dd.robot_base_frame, dd.publish_tf, dd.odometry_source) == ("base_footprint", False, "world")
    assert (dd.command_topic, dd.odometry_topic, dd.odom_covariance) == ("/r1/cmd_vel", "/r1/odom", (1e-4, 1e-4, 0.01))


@pytest.mark.parametrize(
    ("tags", "expected"),
    [
        (
            '<gazebo><plugin name="s" filename="libgazebo_ros_skid_steer_drive.so"><leftFrontJoint>lf</leftFrontJoint>'
            "</plugin></gazebo>",
            "left joint 'lf' is not a joint",
        ),
        (
            '<gazebo><plugin name="s" filename="libgazebo_ros_skid_steer_drive.so"><broadcastTF>maybe</broadcastTF>'
            "</plugin></gazebo>",
            "<broadcastTF>: expected true/false",
        ),
        ('<gazebo reference="left_front"><kp>-5</kp></gazebo>', "<kp>: expected a number >= 0"),
        ('<gazebo reference="left_front"><fdir1>0 0 0</fdir1></gazebo>', "<fdir1>: expected a non-zero direction"),
    ],
)
def test_bad_values_are_one_clear_error(tmp_path: Path, tags: str, expected: str) -> None:
    with pytest.raises(DescriptionError, match=expected.replace("(", r"\(")) as err:
        _robot(tmp_path, tags)
    assert "\n" not in str(err.value)


def test_contact_tags_and_ros_control_are_read(tmp_path: Path) -> None:
    tags = (
        '<gazebo reference="left_front"><mu1>0.9</mu1><mu2>0.7</mu2><kp value="1e6"/><kd>5</kd>'
        "<minDepth>0.002</minDepth><maxVel>0.1</maxVel><fdir1>1 0 0</fdir1></gazebo>"
        '<gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">'
        "<robotNamespace>/</robotNamespace><controlPeriod>0.001</controlPeriod></plugin></gazebo>"
    )
    robot = _robot(tmp_path, tags)
    c = robot.links["left_front"].contact
    assert c is not None and (c.kp, c.kd, c.min_depth, c.max_vel, c.fdir1) == (1e6, 5.0, 0.002, 0.1, (1.0, 0.0, 0.0))
    assert robot.ros_control is not None and robot.ros_control.control_period == 0.001
    assert robot.diff_drive is None and not any("cmd_vel will not move" in w for w in robot.warnings)


def test_a_packages_own_control_and_ekf_files_are_found() -> None:
    files = robot_files(FIXTURE / "urdf" / "skidbot.urdf.xacro")
    assert files.control == FIXTURE / "config" / "control.yaml"
    assert files.ekf == FIXTURE / "config" / "ekf.yaml"
