"""Camera, depth camera, Velodyne, range and bumper <sensor> tags: ROS Noetic's parameter names and defaults,
topics under <robotNamespace>/<cameraName>, and one clear error line for a bad tag."""

from __future__ import annotations

import math

import pytest

from navlab.description import DescriptionError, load_robot

BODY = """
  <link name="base_link">
    <inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision name="base_collision"><geometry><box size="0.3 0.3 0.1"/></geometry></collision>
  </link>
  <link name="sensor_link"/>
  <joint name="js" type="fixed"><parent link="base_link"/><child link="sensor_link"/></joint>
"""


def _load(tmp_path, sensor: str):
    f = tmp_path / "r.urdf"
    f.write_text(f'<robot name="r">{BODY}<gazebo reference="sensor_link">{sensor}</gazebo></robot>')
    return load_robot(f)


CAMERA = """<sensor type="camera" name="cam"><update_rate>15</update_rate>
  <camera><horizontal_fov>1.2</horizontal_fov><image><width>64</width><height>48</height><format>B8G8R8</format></image>
  <clip><near>0.02</near><far>30</far></clip><noise><type>gaussian</type><mean>0</mean><stddev>0.007</stddev></noise>
  </camera>{plugin}</sensor>"""


def test_camera_defaults_are_noetics(tmp_path) -> None:
    robot = _load(tmp_path, CAMERA.format(plugin='<plugin name="c" filename="libgazebo_ros_camera.so"/>'))
    (cam,) = robot.sensors.cameras
    assert cam.kind == "camera" and cam.update_rate == 15
    assert (cam.image_topic, cam.camera_info_topic) == ("image_raw", "camera_info")  # no cameraName: no prefix
    assert cam.camera.width == 64 and cam.camera.height == 48 and cam.camera.format == "B8G8R8"
    assert (cam.camera.near, cam.camera.far, cam.camera.noise_stddev) == (0.02, 30.0, 0.007)
    assert cam.camera.focal_length == pytest.approx(64 / (2 * math.tan(0.6)))
    assert (cam.camera.cx, cam.camera.cy) == (32.5, 24.5)  # gazebo_ros_camera_utils: (width + 1) / 2
    assert cam.frame_id == "sensor_link"
    assert any("<frameName>" in w for w in robot.warnings)
    assert cam.camera.anti_aliasing == 4  # SDF 1.9's <image><anti_aliasing> default
    aa = CAMERA.replace("</format>", "</format><anti_aliasing>0</anti_aliasing>")
    plugin = '<plugin name="c" filename="libgazebo_ros_camera.so"/>'
    (sharp,) = _load(tmp_path, aa.format(plugin=plugin)).sensors.cameras
    assert sharp.camera.anti_aliasing == 0


def test_camera_topics_under_namespace_and_camera_name(tmp_path) -> None:
    plugin = """<plugin name="c" filename="libgazebo_ros_camera.so"><robotNamespace>bot</robotNamespace>
      <cameraName>front</cameraName><imageTopicName>rgb/image</imageTopicName><frameName>cam_optical</frameName>
      <updateRate>5</updateRate></plugin>"""
    (cam,) = _load(tmp_path, CAMERA.format(plugin=plugin)).sensors.cameras
    assert cam.image_topic == "/bot/front/rgb/image" and cam.camera_info_topic == "/bot/front/camera_info"
    assert cam.frame_id == "cam_optical" and cam.update_rate == 5  # <updateRate> throttles the sensor's 15 Hz


def test_openni_kinect_defaults(tmp_path) -> None:
    sensor = CAMERA.replace('type="camera"', 'type="depth"').format(
        plugin='<plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>kinect</cameraName>'
        "<frameName>k_optical</frameName></plugin>"
    )
    (cam,) = _load(tmp_path, sensor).sensors.cameras
    assert cam.kind == "depth"
    assert cam.image_topic == "/kinect/ir/image_raw" and cam.camera_info_topic == "/kinect/ir/camera_info"
    assert cam.depth_image_topic == "/kinect/depth/image_raw" and cam.depth_info_topic == "/kinect/depth/camera_info"
    assert cam.point_cloud_topic == "/kinect/points"
    assert (cam.point_cloud_cutoff, cam.point_cloud_cutoff_max) == (0.4, 5.0)


RAY = """<sensor type="ray" name="{name}"><update_rate>10</update_rate><ray><scan>
  <horizontal><samples>{h}</samples><min_angle>{hmin}</min_angle><max_angle>{hmax}</max_angle></horizontal>
  <vertical><samples>{v}</samples><min_angle>{vmin}</min_angle><max_angle>{vmax}</max_angle></vertical>
  </scan><range><min>0.3</min><max>{rmax}</max></range></ray>{plugin}</sensor>"""


def test_velodyne_defaults(tmp_path) -> None:
    sensor = RAY.format(
        name="vlp",
        h=440,
        hmin=-math.pi,
        hmax=math.pi,
        v=16,
        vmin=-0.2618,
        vmax=0.2618,
        rmax=100,
        plugin='<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"/>',
    )
    robot = _load(tmp_path, sensor)
    (lid,) = robot.sensors.lidars3d
    assert (lid.samples, lid.rings, lid.vertical_min_angle, lid.vertical_max_angle) == (440, 16, -0.2618, 0.2618)
    assert (lid.topic, lid.frame_id, lid.min_range, lid.max_range, lid.noise_stddev) == (
        "/world",
        "world",
        0.0,
        math.inf,
        0.0,
    )
    assert lid.organize_cloud is False
    assert any("<topicName>" in w for w in robot.warnings)


def test_range_defaults(tmp_path) -> None:
    sensor = RAY.format(
        name="sonar",
        h=5,
        hmin=-0.1,
        hmax=0.1,
        v=5,
        vmin=-0.1,
        vmax=0.1,
        rmax=4,
        plugin='<plugin name="r" filename="libgazebo_ros_range.so"/>',
    )
    (rng,) = _load(tmp_path, sensor).sensors.ranges
    assert (rng.topic, rng.frame_id, rng.radiation, rng.fov, rng.noise_stddev) == (
        "/range",
        "world",
        "ultrasound",
        0.05,
        0.0,
    )
    assert (rng.samples, rng.vertical_samples, rng.range_min, rng.range_max) == (5, 5, 0.3, 4.0)


def test_bumper_defaults(tmp_path) -> None:
    sensor = """<sensor type="contact" name="bump"><contact><collision>base_collision</collision></contact>
      <plugin name="b" filename="libgazebo_ros_bumper.so"/></sensor>"""
    (b,) = _load(tmp_path, sensor).sensors.bumpers
    assert (b.topic, b.frame_id, b.collision) == ("bumper_states", "world", "base_collision")


@pytest.mark.parametrize(
    ("sensor", "message"),
    [
        (
            CAMERA.replace("<width>64</width>", "<width>-3</width>").format(
                plugin='<plugin name="c" filename="libgazebo_ros_camera.so"/>'
            ),
            "<image>: width and height",
        ),
        (
            CAMERA.replace("<near>0.02</near>", "<near>40</near>").format(
                plugin='<plugin name="c" filename="libgazebo_ros_camera.so"/>'
            ),
            "<clip>: expected 0 < near < far",
        ),
        (
            CAMERA.replace("<horizontal_fov>1.2</horizontal_fov>", "<horizontal_fov>4</horizontal_fov>").format(
                plugin='<plugin name="c" filename="libgazebo_ros_camera.so"/>'
            ),
            "<horizontal_fov>: expected 0 < fov < pi",
        ),
        (
            CAMERA.replace("</format>", "</format><anti_aliasing>2.5</anti_aliasing>").format(
                plugin='<plugin name="c" filename="libgazebo_ros_camera.so"/>'
            ),
            "<anti_aliasing>: expected a whole number of samples per pixel from 0 (off) to 16, got 2.5",
        ),
        (
            CAMERA.format(plugin='<plugin name="c" filename="libgazebo_ros_velodyne_laser.so"/>'),
            "needs a sensor of type ray or gpu_ray, got 'camera'",
        ),
        (
            RAY.format(
                name="s",
                h=1,
                hmin=0,
                hmax=0,
                v=1,
                vmin=0,
                vmax=0,
                rmax=4,
                plugin='<plugin name="r" filename="libgazebo_ros_range.so"><radiation>laser</radiation></plugin>',
            ),
            "<radiation>: expected ultrasound or infrared",
        ),
        (
            RAY.format(
                name="s",
                h=8,
                hmin=0,
                hmax=1,
                v=4,
                vmin=0.5,
                vmax=-0.5,
                rmax=4,
                plugin='<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"/>',
            ),
            "max_angle -0.5 < min_angle",
        ),
        (
            '<sensor type="contact" name="b"><plugin name="b" filename="libgazebo_ros_bumper.so"/></sensor>',
            "needs <contact><collision>",
        ),
    ],
)
def test_bad_sensor_tags_one_line(tmp_path, sensor: str, message: str) -> None:
    with pytest.raises(DescriptionError) as err:
        _load(tmp_path, sensor)
    text = str(err.value)
    assert message in text and "\n" not in text and "r.urdf" in text
