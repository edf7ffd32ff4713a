"""Depth camera, 3D lidar, range cone, RGB camera and bumper against the exact geometry of a known world."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from sim_helpers import make_mybot

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.description.model import Origin
from navlab.description.sensor_model import BumperConfig, CameraConfig, CameraModel, Lidar3dConfig, RangeConfig
from navlab.io.pointcloud import read_field, read_xyz
from navlab.sim.sensors3d import depth_image, lidar3d_ranges, range_reading, sensor_pose
from navlab.sim.simulation import Simulation
from navlab.sim.spawn import primitive_model
from navlab.world.model import WorldModel

CAM_ORIGIN = Origin((0.1, 0.0, 0.2))  # on the chassis, level, looking along +x


def _sim(*models, visuals: bool = False) -> Simulation:
    return Simulation(make_mybot(), WorldModel("empty", models=list(models)), seed=0, visuals=visuals)


def test_depth_pixel_is_the_range_to_a_known_box_within_noise() -> None:
    box = primitive_model("box", "box", (0.4, 2.0, 1.0), x=2.0)  # front face at x = 1.8
    sim = _sim(box)
    cfg = CameraConfig(
        link="chassis",
        kind="depth",
        origin=CAM_ORIGIN,
        point_cloud_cutoff=0.1,
        camera=CameraModel(width=32, height=24, horizontal_fov=0.8, near=0.05, far=10.0, noise_stddev=0.01),
    )
    depth = depth_image(sim, cfg, np.random.default_rng(1))
    pos, _ = sensor_pose(sim, "chassis", CAM_ORIGIN)
    expected = 1.8 - pos[0]  # a level camera: depth along the optical axis = the distance to the face's plane
    centre = depth[10:14, 14:18]
    assert np.all(np.abs(centre - expected) < 4 * 0.01)
    assert abs(float(centre.mean()) - expected) < 0.01
    # the floor below the horizon: depth = camera height / tan(depression angle) along the optical axis
    row = 23
    f = cfg.camera.focal_length
    assert depth[row, 16] == pytest.approx(pos[2] * f / (row - 11.5), abs=0.05)


def test_a_held_depth_cloud_never_changes_and_dropped_ones_are_reused() -> None:
    from navlab.sim.sensor_plugins import DepthCameraPlugin

    box = primitive_model("box", "box", (0.4, 2.0, 1.0), x=2.0)
    sim = _sim(box)
    cfg = CameraConfig(
        link="chassis", kind="depth", origin=CAM_ORIGIN, camera=CameraModel(width=32, height=24, far=10.0)
    )
    camera = DepthCameraPlugin(Executor(), sim=sim, config=cfg)
    depth = depth_image(sim, cfg)

    def address(msg: Any) -> int:
        return int(msg.data.__array_interface__["data"][0])

    held = camera.cloud(depth, 0)
    seen = read_xyz(held, copy=False)  # a view into the message, as a costmap keeps it
    first, kept = address(held), read_xyz(held)
    del held
    others = [camera.cloud(depth * (k + 2), k + 1) for k in range(3)]
    assert first not in {address(m) for m in others}  # the view still holds the first frame's points
    np.testing.assert_array_equal(seen, kept)
    spent = {address(m) for m in others}
    del seen, others
    assert address(camera.cloud(depth, 9)) in spent | {first}  # nobody holds them: a buffer is reused


def test_3d_lidar_rings_at_the_configured_angles() -> None:
    from navlab.core import Executor
    from navlab.sim.sensor_plugins import VelodynePlugin

    wall = primitive_model("box", "wall", (0.2, 20.0, 4.0), x=3.0)
    sim = _sim(wall)
    cfg = Lidar3dConfig(
        link="chassis",
        origin=Origin((0.0, 0.0, 0.3)),
        samples=90,
        min_angle=-0.6,
        max_angle=0.6,
        rings=8,
        vertical_min_angle=-0.2,
        vertical_max_angle=0.25,
        range_min=0.3,
        range_max=20.0,
        topic="points",
        frame_id="velodyne",
    )
    sim.robot.sensors.lidars3d.append(cfg)
    plugin = VelodynePlugin(Executor(), sim=sim, config=cfg)
    msg = plugin.cloud(lidar3d_ranges(sim, cfg), 0)
    xyz, ring = read_xyz(msg), read_field(msg, "ring")
    assert msg.point_step == 32 and [f.name for f in msg.fields] == ["x", "y", "z", "intensity", "ring"]
    assert len(xyz) == 8 * 90 and set(ring.tolist()) == set(range(8))
    elevation = np.arctan2(xyz[:, 2], np.hypot(xyz[:, 0], xyz[:, 1]))
    wanted = np.linspace(-0.2, 0.25, 8)[ring]
    assert np.abs(elevation - wanted).max() < 1e-4
    # every point lies on the wall's face (x = 2.9 in the world) or on the floor (the low rings; the sensor frame
    # is the chassis', level)
    pos, _ = sensor_pose(sim, "chassis", cfg.origin)
    on_wall = np.abs(xyz[:, 0] - (2.9 - pos[0])) < 1e-4
    on_floor = np.abs(xyz[:, 2] + pos[2]) < 1e-4
    assert np.all(on_wall | on_floor) and on_wall.sum() > 400 and on_floor[ring == 0].all()


def test_sonar_cone_returns_the_nearest_surface_in_its_cone() -> None:
    wall = primitive_model("box", "wall", (0.2, 20.0, 2.0), x=3.0)
    inside = primitive_model("box", "post", (0.1, 0.1, 1.0), x=1.5, y=1.5 * math.tan(0.12))  # 0.12 rad off axis
    outside = primitive_model("box", "far_post", (0.1, 0.1, 1.0), x=1.0, y=1.0 * math.tan(0.4))  # outside
    # vertical spread small enough that the floor stays beyond max range (a wider cone near the floor sees it)
    cfg = RangeConfig(
        link="chassis",
        origin=Origin((0.0, 0.0, 0.2)),
        samples=9,
        min_angle=-0.15,
        max_angle=0.15,
        vertical_samples=3,
        vertical_min_angle=-0.05,
        vertical_max_angle=0.05,
        range_min=0.02,
        range_max=4.0,
        fov=0.3,
    )
    pos, _ = sensor_pose(_sim(), "chassis", cfg.origin)
    assert range_reading(_sim(wall, outside), cfg) == pytest.approx((2.9 - pos[0]), abs=1e-6)  # the wall, on axis
    near = range_reading(_sim(wall, inside, outside), cfg)
    face = 1.45 - pos[0]
    assert face <= near <= face / math.cos(0.15) + 1e-6  # the post's face, seen by a ray of the cone
    assert range_reading(_sim(), cfg) == 4.0  # nothing: max range, as Gazebo reports


def test_a_coloured_box_appears_where_the_camera_model_puts_it() -> None:
    pytest.importorskip("mujoco.egl")
    from navlab.sim.camera_render import CameraRenderer

    red = primitive_model("box", "red", (0.3, 0.3, 0.3), x=2.0, y=0.5, z=0.3, rgba=(1.0, 0.0, 0.0, 1.0))
    sim = _sim(red, visuals=True)
    cfg = CameraConfig(
        link="chassis", origin=CAM_ORIGIN, camera=CameraModel(width=64, height=48, horizontal_fov=1.2, far=20.0)
    )
    try:
        renderer = CameraRenderer(sim, cfg)
    except Exception as exc:  # no EGL/OSMesa on this machine
        pytest.skip(f"no offscreen renderer: {exc}")
    try:
        rgb = renderer.render().astype(int)
    finally:
        renderer.close()
    pos, _ = sensor_pose(sim, "chassis", CAM_ORIGIN)
    f = cfg.camera.focal_length
    x, y, z = 2.0 - 0.15 - pos[0], 0.5 - pos[1], 0.3 - pos[2]  # the box's front face centre in the camera frame
    u, v = round(31.5 - f * y / x), round(23.5 - f * z / x)
    r, g, b = rgb[v, u]
    assert r > 100 and r > 2 * g and r > 2 * b  # red where the pinhole model projects the box
    redness = (rgb[..., 0] > 2 * rgb[..., 1] + 30) & (rgb[..., 0] > 100)
    vs, us = np.nonzero(redness)
    assert abs(us.mean() - u) < 3 and abs(vs.mean() - v) < 3
    assert not redness[:, 40:].any()  # nothing red on the right half (the box is to the left)


def test_anti_aliasing_only_blends_the_edges_of_the_box() -> None:
    pytest.importorskip("mujoco.egl")
    from navlab.sim.camera_render import CameraRenderer

    red = primitive_model("box", "red", (0.3, 0.3, 0.3), x=2.0, y=0.5, z=0.3, rgba=(1.0, 0.0, 0.0, 1.0))
    sim = _sim(red, visuals=True)
    images = {}
    for samples in (0, 4):
        model = CameraModel(width=64, height=48, horizontal_fov=1.2, far=20.0, anti_aliasing=samples)
        try:
            renderer = CameraRenderer(sim, CameraConfig(link="chassis", origin=CAM_ORIGIN, camera=model))
        except Exception as exc:  # no EGL/OSMesa on this machine
            pytest.skip(f"no offscreen renderer: {exc}")
        try:
            images[samples] = renderer.render().astype(int)
        finally:
            renderer.close()
    sharp, smooth = images[0], images[4]
    padded = np.pad(sharp, ((1, 1), (1, 1), (0, 0)), mode="edge")
    window = np.lib.stride_tricks.sliding_window_view(padded, (3, 3), axis=(0, 1))  # each pixel's 3 x 3
    edge = (window.max(axis=(-2, -1)) - window.min(axis=(-2, -1))).max(axis=-1) > 8  # outlines, face borders
    changed = np.abs(smooth - sharp).max(axis=-1) > 8
    red_px = (sharp[..., 0] > 2 * sharp[..., 1] + 30) & (sharp[..., 0] > 100)
    assert (changed & edge & red_px).sum() >= 5  # 4x multisampling (SDF's default) blends the box's edges
    assert not (changed & ~edge).any()  # and nothing else
    assert sim.model.vis.quality.offsamples == 4  # the model's own setting is kept


def test_bumper_reports_the_contact_with_the_box() -> None:
    from navlab.core import Executor
    from navlab.sim.sensor_plugins import BumperPlugin

    box = primitive_model("box", "crate", (0.4, 0.4, 0.3), x=0.39)  # overlaps the chassis (radius 0.2) by 1 cm
    sim = _sim(box)
    sim.step(5)
    cfg = BumperConfig(link="chassis", collision="chassis_collision", topic="bumper")
    states = BumperPlugin(Executor(), sim=sim, config=cfg).states()
    assert states and all(s.collision1_name == "chassis_collision" for s in states)
    assert any("crate" in s.collision2_name for s in states)
    assert all(s.contact_normals[0].x > 0.9 for s in states)  # pushing on the +x face
    assert _sim().robot_collisions() == [] and BumperPlugin(Executor(), sim=_sim(), config=cfg).states() == []


def test_sensor_topics_record_to_rosbag2_and_read_back(tmp_path) -> None:
    from navlab.core import Executor
    from navlab.core.record import Recorder
    from navlab.io.rosbag import bag_topics, read_bag
    from navlab.sim.gazebo import launch_sim

    ex = Executor(seed=0)
    launch_sim(ex, world="room_obstacles", robot="mybot_depth")
    rec = Recorder(ex, tmp_path / "bag", topics=["/camera/depth/*"])
    ex.run(0.2)
    bag = rec.close()
    types = {topic: kind for topic, (kind, _) in bag_topics(bag).items()}
    assert types == {
        "/camera/depth/points": "sensor_msgs/msg/PointCloud2",
        "/camera/depth/image_raw": "sensor_msgs/msg/Image",
        "/camera/depth/camera_info": "sensor_msgs/msg/CameraInfo",
    }
    clouds = [m for topic, _, m in read_bag(bag, topics=["/camera/depth/points"])]
    assert len(clouds) >= 2 and read_xyz(clouds[0]).shape == (320 * 240, 3)  # 15 Hz over 0.2 s
    assert clouds[0].header.frame_id == "camera_depth_optical_frame"


SONAR_BUMPER = """<?xml version="1.0"?>
<robot name="mybot_sonar" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find mybot_description)/mybot.xacro"/>
  <gazebo reference="chassis">
    <sensor type="ray" name="sonar_front"><pose>0.2 0 0.05 0 0 0</pose><update_rate>10</update_rate>
      <ray><scan><horizontal><samples>5</samples><min_angle>-0.13</min_angle><max_angle>0.13</max_angle></horizontal>
      <vertical><samples>3</samples><min_angle>-0.05</min_angle><max_angle>0.05</max_angle></vertical></scan>
      <range><min>0.02</min><max>3.0</max></range></ray>
      <plugin name="sonar" filename="libgazebo_ros_range.so"><topicName>sonar_front</topicName>
        <frameName>sonar_front_link</frameName><radiation>ultrasound</radiation><fov>0.26</fov></plugin>
    </sensor>
    <sensor type="contact" name="bumper"><contact><collision>chassis_collision</collision></contact>
      <plugin name="bumper" filename="libgazebo_ros_bumper.so"><bumperTopicName>bumper</bumperTopicName></plugin>
    </sensor>
  </gazebo>
</robot>
"""


def test_range_and_bumper_plugins_publish_their_messages(tmp_path) -> None:
    from navlab.sim.gazebo import launch_sim

    robot = tmp_path / "mybot_sonar.xacro"
    robot.write_text(SONAR_BUMPER)
    ex = Executor(seed=0)
    gz = launch_sim(ex, world="empty", robot=str(robot))
    gz.spawn(primitive_model("box", "wall", (0.2, 3.0, 1.0), x=1.6))  # its face 1.5 m ahead of the chassis centre
    got = Probe(ex).got
    ex.run(0.3)
    r = got["range"]
    assert (r.header.frame_id, r.radiation_type, r.field_of_view, r.max_range) == (
        "sonar_front_link",
        0,
        pytest.approx(0.26),
        3.0,
    )
    pos, _ = sensor_pose(gz.sim, "chassis", Origin((0.2, 0.0, 0.05)))
    assert r.range == pytest.approx(1.5 - pos[0], abs=0.01)  # the nearest ray: on the axis
    assert got["bumper"].header.frame_id == "world" and got["bumper"].states == []  # touching nothing


class Probe(Node):
    """Keeps the newest sonar reading and bumper state."""

    def __init__(self, ex: Executor) -> None:
        super().__init__("probe", context=Context(ex))
        self.got: dict[str, Any] = {}
        self.create_subscription(msgs.Range, "/sonar_front", lambda m: self.got.__setitem__("range", m), 1)
        self.create_subscription(msgs.ContactsState, "/bumper", lambda m: self.got.__setitem__("bumper", m), 1)


@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.0), (-1.0, 0.9, -0.5), (2.0, -2.0, 2.5)])
def test_culled_camera_cast_equals_every_ray_against_every_geom(pose: tuple[float, float, float]) -> None:
    from navlab.description import load_robot
    from navlab.sim.raycast3d import ALL, PINHOLE, cast_grid, pinhole_dirs
    from navlab.world import load_world

    robot = load_robot("mybot_depth")  # pitched 0.35 rad down: the floor's rows and the boxes' blocks are culled
    cam = robot.sensors.cameras[0]
    sim = Simulation(robot, load_world("tables"), robot_pose=pose)
    m, d = sim.model, sim.data
    fast, _ = sim.ray_geoms()
    w, h = 64, 48
    f = w / (2 * math.tan(cam.camera.horizontal_fov / 2))
    dirs = pinhole_dirs(w, h, f)
    pos, rot = sensor_pose(sim, cam.link, cam.origin)
    culled, every = np.empty(w * h), np.empty(w * h)
    cast_grid(
        pos,
        rot,
        dirs,
        h,
        w,
        PINHOLE,
        np.array([f, (w - 1) / 2, (h - 1) / 2]),
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        0.05,
        20.0,
        culled,
    )
    cast_grid(
        pos,
        rot,
        dirs,
        1,
        w * h,
        ALL,
        np.zeros(3),
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        0.05,
        20.0,
        every,
    )
    np.testing.assert_array_equal(culled, every)
    assert np.isfinite(every).mean() > 0.5


def test_culled_lidar_cast_equals_every_ray_against_every_geom() -> None:
    from navlab.description import load_robot
    from navlab.sim.raycast3d import ALL, SPHERICAL, cast_grid, spherical_dirs
    from navlab.world import load_world

    sim = Simulation(load_robot("mybot"), load_world("tables"), robot_pose=(0.5, 1.5, 0.7))
    m, d = sim.model, sim.data
    fast, _ = sim.ray_geoms()
    az, el = np.linspace(-math.pi, math.pi, 361), np.linspace(-0.3, 0.3, 16)
    dirs = spherical_dirs(az, el)
    pos, rot = sensor_pose(sim, "laser", Origin((0.0, 0.0, 0.3)))
    culled, every = np.empty(len(dirs)), np.empty(len(dirs))
    cast_grid(
        pos,
        rot,
        dirs,
        16,
        361,
        SPHERICAL,
        np.array([az[0], az[1] - az[0], el[0], el[1] - el[0]]),
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        0.3,
        30.0,
        culled,
    )
    cast_grid(
        pos,
        rot,
        dirs,
        1,
        len(dirs),
        ALL,
        np.zeros(4),
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        0.3,
        30.0,
        every,
    )
    np.testing.assert_array_equal(culled, every)
