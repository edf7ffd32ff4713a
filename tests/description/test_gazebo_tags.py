"""<gazebo> tags: ROS 1 and ROS 2 plugin spellings, sensors, friction, and warnings for unknowns."""

from __future__ import annotations

import pytest

from navlab.description import DescriptionError, load_robot

BODY = """
  <link name="base_link">
    <inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>
  </link>
  <link name="wl"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="wr"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="scan_link"/>
  <link name="imu_link"/>
  <joint name="jl" type="continuous"><parent link="base_link"/><child link="wl"/>
    <origin xyz="0 0.15 0"/><axis xyz="0 1 0"/></joint>
  <joint name="jr" type="continuous"><parent link="base_link"/><child link="wr"/>
    <origin xyz="0 -0.15 0"/><axis xyz="0 1 0"/></joint>
  <joint name="js" type="fixed"><parent link="base_link"/><child link="scan_link"/></joint>
  <joint name="ji" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
"""

ROS1 = """
  <gazebo>
    <plugin name="dd" filename="libgazebo_ros_diff_drive.so">
      <legacyMode>false</legacyMode>
      <leftJoint>jl</leftJoint><rightJoint>jr</rightJoint>
      <wheelSeparation>0.3</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
      <wheelTorque>4</wheelTorque><wheelAcceleration>2.5</wheelAcceleration><updateRate>50</updateRate>
      <commandTopic>cmd_demo</commandTopic><odometryTopic>odom_demo</odometryTopic>
      <odometryFrame>odom</odometryFrame><robotBaseFrame>base_link</robotBaseFrame>
      <odometrySource>1</odometrySource><publishOdomTF>0</publishOdomTF><publishWheelTF>true</publishWheelTF>
    </plugin>
  </gazebo>
"""

ROS2 = """
  <gazebo>
    <plugin name="dd" filename="libgazebo_ros_diff_drive.so">
      <ros><remapping>cmd_vel:=cmd_demo</remapping><remapping>odom:=odom_demo</remapping></ros>
      <update_rate>50</update_rate>
      <left_joint>jl</left_joint><right_joint>jr</right_joint>
      <wheel_separation>0.3</wheel_separation><wheel_diameter>0.1</wheel_diameter>
      <max_wheel_torque>4</max_wheel_torque><max_wheel_acceleration>2.5</max_wheel_acceleration>
      <publish_odom>true</publish_odom><publish_odom_tf>false</publish_odom_tf>
      <publish_wheel_tf>true</publish_wheel_tf>
      <odometry_frame>odom</odometry_frame><robot_base_frame>base_link</robot_base_frame>
      <odometry_source>1</odometry_source>
    </plugin>
  </gazebo>
"""


def _robot(tmp_path, *tags: str, name: str = "r.urdf"):
    f = tmp_path / name
    f.write_text(f'<robot name="r">{BODY}{"".join(tags)}</robot>')
    return load_robot(f)


def test_ros1_and_ros2_diff_drive_spellings_agree(tmp_path):
    r1 = _robot(tmp_path, ROS1, name="ros1.urdf").diff_drive
    r2 = _robot(tmp_path, ROS2, name="ros2.urdf").diff_drive
    assert r1 == r2
    assert (r1.left_joint, r1.right_joint, r1.wheel_separation, r1.wheel_diameter) == ("jl", "jr", 0.3, 0.1)
    assert (r1.max_torque, r1.max_accel, r1.update_rate) == (4, 2.5, 50)
    assert (r1.command_topic, r1.odometry_topic) == ("cmd_demo", "odom_demo")
    assert r1.odometry_source == "world" and r1.publish_tf is False and r1.publish_wheel_tf is True


def test_ros2_namespace_prefixes_relative_topics(tmp_path):
    tag = ROS2.replace("<ros>", "<ros><namespace>/demo</namespace>")
    dd = _robot(tmp_path, tag).diff_drive
    assert dd.namespace == "/demo" and dd.command_topic == "/demo/cmd_demo"


def test_noetic_ignores_torque_and_legacy_mode_and_says_which_tag_it_reads(tmp_path):
    tag = ROS1.replace("<wheelTorque>4</wheelTorque>", "<torque>15</torque>").replace(
        "<legacyMode>false</legacyMode>", "<legacyMode>true</legacyMode>"
    )
    robot = _robot(tmp_path, tag)
    assert robot.diff_drive.max_torque == 5.0  # Noetic's wheelTorque default, not the ignored <torque>
    assert robot.diff_drive.legacy_mode is False  # Noetic has no legacy mode
    (torque,) = [w for w in robot.warnings if "<torque>" in w]
    assert "<wheelTorque>" in torque and "5 N m" in torque
    assert any("<legacyMode> was removed" in w for w in robot.warnings)


RAY = """<ray><scan><horizontal><samples>{n}</samples><resolution>1</resolution>
  <min_angle>-1.5</min_angle><max_angle>1.5</max_angle></horizontal></scan>
  <range><min>0.1</min><max>12</max><resolution>0.02</resolution></range>
  <noise><type>gaussian</type><mean>0.0</mean><stddev>0.03</stddev></noise></ray>"""


@pytest.mark.parametrize(
    "stype,plugin,topic",
    [
        (
            "ray",
            '<plugin name="gazebo_ros_laser_controller" filename="libgazebo_ros_laser.so">'
            "<topicName>/front/scan</topicName><frameName>scan_link</frameName></plugin>",
            "/front/scan",
        ),
        (
            "gpu_ray",
            '<plugin name="gpu" filename="libgazebo_ros_gpu_laser.so">'
            "<robotNamespace>bot</robotNamespace><topicName>scan</topicName><frameName>scan_link</frameName></plugin>",
            "/bot/scan",
        ),
        (
            "ray",
            '<plugin name="scanner" filename="libgazebo_ros_ray_sensor.so"><ros><namespace>/demo</namespace>'
            "<remapping>~/out:=scan</remapping></ros><output_type>sensor_msgs/LaserScan</output_type>"
            "<frame_name>scan_link</frame_name></plugin>",
            "/demo/scan",
        ),
        (
            "ray",
            '<plugin name="scanner" filename="libgazebo_ros_ray_sensor.so">'
            "<output_type>sensor_msgs/LaserScan</output_type></plugin>",
            "scanner/out",
        ),
    ],
)
def test_laser_plugins(tmp_path, stype, plugin, topic):
    tag = (
        f'<gazebo reference="scan_link"><sensor type="{stype}" name="front_laser">'
        f"<pose>0.1 0 0.2 0 0 0</pose><update_rate>15</update_rate>{RAY.format(n=541)}{plugin}</sensor></gazebo>"
    )
    robot = _robot(tmp_path, ROS1, tag)
    (lidar,) = robot.lidars
    assert lidar.link == "scan_link" and lidar.name == "front_laser" and lidar.topic == topic
    assert lidar.origin.xyz == (0.1, 0.0, 0.2) and lidar.update_rate == 15 and lidar.samples == 541
    assert (lidar.min_angle, lidar.max_angle, lidar.range_min, lidar.range_max) == (-1.5, 1.5, 0.1, 12)
    assert lidar.noise_stddev == 0.03 and lidar.frame_id == "scan_link"
    assert robot.warnings == []


def test_imu_sensor_plugins_ros1_and_ros2(tmp_path):
    noise = (
        "<imu><angular_velocity><x><noise type='gaussian'><mean>0</mean><stddev>0.002</stddev></noise></x>"
        "</angular_velocity><linear_acceleration><x><noise type='gaussian'><mean>0</mean>"
        "<stddev>0.017</stddev></noise></x></linear_acceleration></imu>"
    )
    ros2 = (
        f'<gazebo reference="imu_link"><sensor type="imu" name="imu_sensor"><update_rate>200</update_rate>'
        f'{noise}<plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so"><ros>'
        f"<remapping>~/out:=imu</remapping></ros></plugin></sensor></gazebo>"
    )
    ros1 = (
        '<gazebo reference="imu_link"><sensor type="imu" name="imu_sensor"><update_rate>200</update_rate>'
        '<plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName>'
        "<bodyName>imu_link</bodyName><updateRateHZ>100.0</updateRateHZ><gaussianNoise>0.01</gaussianNoise>"
        "<frameName>imu_link</frameName></plugin></sensor></gazebo>"
    )
    (a,) = _robot(tmp_path, ROS1, ros2, name="a.urdf").imus
    assert (a.link, a.topic, a.update_rate) == ("imu_link", "imu", 200)
    assert (a.gyro_noise_stddev, a.accel_noise_stddev) == (0.002, 0.017)
    (b,) = _robot(tmp_path, ROS1, ros1, name="b.urdf").imus
    assert (b.link, b.topic, b.update_rate, b.frame_id) == ("imu_link", "imu", 100, "imu_link")
    assert b.gyro_noise_stddev == b.accel_noise_stddev == 0.01


def test_unknown_plugin_and_sensor_warn_and_the_rest_loads(tmp_path):
    tags = (
        '<gazebo><plugin name="arm_ctrl" filename="libgazebo_ros_vacuum_gripper.so"/></gazebo>'
        '<gazebo reference="scan_link"><sensor type="camera" name="front_cam"/></gazebo>'
        '<gazebo reference="scan_link"><sensor type="ray" name="sonar">'
        + RAY.format(n=5)
        + '<plugin name="x" filename="libmy_sonar.so"/></sensor></gazebo>'
    )
    robot = _robot(tmp_path, ROS1, tags)
    text = "\n".join(robot.warnings)
    assert "libgazebo_ros_vacuum_gripper.so" in text and "arm_ctrl" in text
    assert "front_cam" in text and "camera" in text
    assert "libmy_sonar.so" in text
    assert robot.diff_drive is not None and robot.diff_drive.wheel_separation == 0.3
    assert robot.lidars == []


def test_link_friction_and_bad_reference(tmp_path):
    tags = (
        '<gazebo reference="wl"><mu1>0.8</mu1><mu2>0.6</mu2><kp>1e6</kp></gazebo>'
        '<gazebo reference="no_such_link"><mu1>1</mu1></gazebo>'
        '<gazebo reference="wr"><mu3>1</mu3></gazebo>'
    )
    robot = _robot(tmp_path, ROS1, tags)
    assert (robot.links["wl"].mu1, robot.links["wl"].mu2) == (0.8, 0.6)
    assert robot.links["wr"].mu1 is None
    assert any("no_such_link" in w for w in robot.warnings)
    assert any("<mu3>" in w and "did you mean" in w for w in robot.warnings)


def test_no_diff_drive_is_a_warning(tmp_path):
    robot = _robot(tmp_path)
    assert robot.diff_drive is None and any("diff_drive" in w for w in robot.warnings)


def test_diff_drive_joint_must_exist(tmp_path):
    with pytest.raises(DescriptionError, match=r"r\.urdf.*left joint 'wheel_l'.*not a joint"):
        _robot(tmp_path, ROS1.replace("<leftJoint>jl<", "<leftJoint>wheel_l<"))


def test_diff_drive_bad_value_names_element(tmp_path):
    with pytest.raises(DescriptionError, match=r"r\.urdf.*<plugin name=\"dd\".*wheel_separation"):
        _robot(tmp_path, ROS1.replace("<wheelSeparation>0.3<", "<wheelSeparation>wide<"))


def test_noetic_laser_defaults_and_ignored_tags(tmp_path):
    """ROS Noetic's gazebo_ros_laser: no <topicName> publishes on /world, no <frameName> stamps frame /world;
    <gaussianNoise>/<hokuyoMinIntensity>/<updateRate> are not read (the sensor's <noise>/<update_rate> are)."""
    plugin = (
        '<plugin name="laser" filename="libgazebo_ros_laser.so"><gaussianNoise>0.5</gaussianNoise>'
        "<hokuyoMinIntensity>101</hokuyoMinIntensity><updateRate>40</updateRate></plugin>"
    )
    tag = (
        f'<gazebo reference="scan_link"><sensor type="ray" name="front_laser"><update_rate>15</update_rate>'
        f"{RAY.format(n=181)}{plugin}</sensor></gazebo>"
    )
    robot = _robot(tmp_path, ROS1, tag)
    (lidar,) = robot.lidars
    assert (lidar.topic, lidar.frame_id, lidar.update_rate, lidar.noise_stddev) == ("/world", "world", 15, 0.03)
    said = " | ".join(robot.warnings)
    for words in (
        "no <topicName>",
        "'/world'",
        "no <frameName>",
        "<gaussianNoise> is not read",
        "<ray><noise>",
        "<hokuyoMinIntensity> is not read",
        "<updateRate> is not read",
        "<update_rate>",
    ):
        assert words in said


def test_noetic_imu_model_plugin_default_topic(tmp_path):
    tag = (
        '<gazebo><plugin name="imu" filename="libgazebo_ros_imu.so"><bodyName>imu_link</bodyName>'
        "<updateRate>50</updateRate></plugin></gazebo>"
    )
    (imu,) = _robot(tmp_path, ROS1, tag).imus
    assert imu.topic == "/default_imu" and imu.frame_id == "imu_link"  # Noetic's gazebo_ros_imu defaults
