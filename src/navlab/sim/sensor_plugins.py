"""gazebo_ros sensor plugins as navlab nodes: camera, depth camera (openni_kinect), Velodyne 3D lidar, range, bumper.

Each node publishes what its ROS Noetic plugin publishes, with the plugin's topics and frame, every
``1/update_rate`` simulated seconds — and, as Gazebo's sensors do, only while anyone subscribes (or a recorder
or viewer listens): an unread camera costs nothing. Sensor frames that are not links of the robot get a static
tf from their link (a camera's optical frame turned z forward, x right, y down).
"""

from __future__ import annotations

import sys
from typing import Any

import mujoco
import numpy as np

from navlab import msgs
from navlab.core import Executor, Node
from navlab.description import BumperConfig, CameraConfig, Lidar3dConfig, Origin, RangeConfig
from navlab.io import FLOAT32, UINT16, cloud_message, point_field
from navlab.sim.plugins import SensorPlugin
from navlab.sim.raster import depth_cloud
from navlab.sim.sensors3d import depth_image, lidar3d_angles, lidar3d_ranges, range_reading, sensor_pose
from navlab.sim.simulation import Simulation
from navlab.sim.sweep import scan_cloud

ENCODINGS = {"R8G8B8": ("rgb8", 3), "B8G8R8": ("bgr8", 3), "L8": ("mono8", 1)}
# the openni_kinect cloud's fields: setPointCloud2FieldsByString(2, "xyz", "rgb"), 32-byte points
DEPTH_FIELDS = [point_field(name, offset, FLOAT32) for name, offset in (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))]
# GazeboRosVelodyneLaser's: x y z intensity (float32) and ring (uint16) in 32-byte points
VELODYNE_FIELDS = [*DEPTH_FIELDS[:3], point_field("intensity", 16, FLOAT32), point_field("ring", 20, UINT16)]


def camera_info(cfg: CameraConfig, stamp_ns: int, frame_id: str) -> Any:
    """``sensor_msgs/CameraInfo`` as gazebo_ros_camera_utils fills it (plumb_bob, K from the field of view)."""
    cam = cfg.camera
    f, cx, cy = cam.focal_length, cam.cx, cam.cy
    return msgs.CameraInfo(
        header=msgs.header(stamp_ns, frame_id),
        height=cam.height,
        width=cam.width,
        distortion_model="plumb_bob",
        d=np.array(cfg.distortion, dtype=np.float64),
        k=np.array([f, 0, cx, 0, f, cy, 0, 0, 1], dtype=np.float64),
        r=np.eye(3).ravel(),
        p=np.array([f, 0, cx, -f * cfg.hack_baseline, 0, f, cy, 0, 0, 0, 1, 0], dtype=np.float64),
        binning_x=0,
        binning_y=0,
        roi=msgs.RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False),
    )


class CameraPlugin(SensorPlugin[CameraConfig]):
    """``libgazebo_ros_camera.so`` (and the colour image of a depth camera): ``sensor_msgs/Image`` on
    ``image_topic`` and ``CameraInfo`` on ``camera_info_topic``, rendered offscreen (see
    :mod:`navlab.sim.camera_render`), with the ``<camera><noise>`` (std dev on the 0..1 scale) per pixel."""

    optical = True

    def setup(self) -> None:
        super().setup()
        config = self.cam = self.cfg
        self.renderer: Any = None
        self.image_pub = self.create_publisher(msgs.Image, config.image_topic, 2)
        self.info_pub = self.create_publisher(msgs.CameraInfo, config.camera_info_topic, 2)
        self.last_image: np.ndarray | None = None

    def image(self) -> np.ndarray:
        """Render the camera's RGB image now (height x width x 3 uint8), noise added."""
        if self.renderer is None:
            from navlab.sim.camera_render import CameraRenderer

            self.renderer = CameraRenderer(self.sim, self.cam)
        rgb = self.renderer.render()
        cam = self.cam.camera
        if cam.noise_stddev > 0 or cam.noise_mean:
            noisy = rgb + 255.0 * (cam.noise_mean + cam.noise_stddev * self.rng.standard_normal(rgb.shape))
            rgb = np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
        self.last_image = rgb
        return rgb

    def update(self) -> None:
        if not self.read(self.image_pub, self.info_pub):
            return
        now = self.executor.now_ns
        self.image_pub.publish(self.image_msg(self.image(), now))
        self.info_pub.publish(camera_info(self.cam, now, self.frame_id))

    def image_msg(self, rgb: np.ndarray, stamp_ns: int) -> Any:
        """``sensor_msgs/Image`` in the camera's ``<format>`` (rgb8, bgr8 or mono8)."""
        encoding, channels = ENCODINGS[self.cam.camera.format]
        if channels == 1:
            data = np.rint(rgb @ np.array([0.299, 0.587, 0.114])).astype(np.uint8)
        else:
            data = rgb[..., ::-1] if encoding == "bgr8" else rgb
        h, w = rgb.shape[:2]
        return msgs.Image(
            header=msgs.header(stamp_ns, self.frame_id),
            height=h,
            width=w,
            encoding=encoding,
            is_bigendian=0,
            step=w * channels,
            data=np.ascontiguousarray(data).reshape(-1),
        )

    def destroy_node(self) -> None:
        """Free the GL context with the node."""
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None
        super().destroy_node()


class DepthCameraPlugin(CameraPlugin):
    """``libgazebo_ros_openni_kinect.so``: the depth image (32FC1, m along the optical axis, NaN outside the point
    cloud cutoffs) on ``depth_image_topic``, the organised cloud (x y z rgb, optical frame) on
    ``point_cloud_topic``, ``CameraInfo`` on both info topics, the colour image (rendered) only when read.
    Depth comes from ray casting (:func:`navlab.sim.sensors3d.depth_image`), not from the renderer."""

    def setup(self) -> None:
        super().setup()
        config = self.cfg
        self.depth_pub = self.create_publisher(msgs.Image, config.depth_image_topic, 1)
        self.cloud_pub = self.create_publisher(msgs.PointCloud2, config.point_cloud_topic, 1)
        self.depth_info_pub = self.create_publisher(msgs.CameraInfo, config.depth_info_topic, 1)
        self._scratch = np.empty((config.camera.height, config.camera.width))  # depth_image's float64 buffer
        self._image = np.empty((config.camera.height, config.camera.width), np.float32)  # an unpublished image
        self._spares: list[np.ndarray] = []  # clouds' point buffers, reused once no message holds them

    def update(self) -> None:
        now = self.executor.now_ns
        colour = self.read(self.image_pub)
        if colour:
            self.image_pub.publish(self.image_msg(self.image(), now))
        if self.read(self.depth_pub, self.cloud_pub):
            published = self.read(self.depth_pub)  # else the image is only the cloud's: drawn into a kept buffer
            image = None if published else self._image
            depth = depth_image(self.sim, self.cam, self.rng, scratch=self._scratch, out=image)
            if published:
                h, w = depth.shape
                self.depth_pub.publish(
                    msgs.Image(
                        header=msgs.header(now, self.frame_id),
                        height=h,
                        width=w,
                        encoding="32FC1",
                        is_bigendian=0,
                        step=4 * w,
                        data=depth.reshape(-1).view(np.uint8),
                    )
                )
            if self.read(self.cloud_pub):
                self.cloud_pub.publish(self.cloud(depth, now))
        if self.read(self.info_pub):
            self.info_pub.publish(camera_info(self.cam, now, self.frame_id))
        if self.read(self.depth_info_pub):
            self.depth_info_pub.publish(camera_info(self.cam, now, self.frame_id))

    def cloud(self, depth: np.ndarray, stamp_ns: int) -> Any:
        """The organised PointCloud2 of a depth image (rgb from the last colour image when sizes match, else 0)."""
        h, w = depth.shape
        rgb = self.last_image if self.last_image is not None else np.zeros((0, 0, 3), np.uint8)
        words = self._points_buffer(h * w)
        dense = depth_cloud(depth, self.cam.camera.focal_length, rgb, words, words.view(np.uint32))
        return cloud_message(stamp_ns, self.frame_id, words, DEPTH_FIELDS, height=h, width=w, dense=dense)

    def _points_buffer(self, n: int) -> np.ndarray:
        """An (n x 8) float32 buffer for the next cloud: a spare one that no message (nor any view of one) holds
        any more — nobody can see it change — else a new one (a fresh 2.4 MB buffer costs its page faults)."""
        for buf in self._spares:
            if len(buf) == n and sys.getrefcount(buf) <= 3:  # the list, the loop variable, getrefcount's argument
                return buf
        buf = np.empty((n, 8), dtype=np.float32)
        self._spares = [buf, *self._spares[:2]]
        return buf


class VelodynePlugin(SensorPlugin[Lidar3dConfig]):
    """``GazeboRosVelodyneLaser``: ``sensor_msgs/PointCloud2`` (x y z intensity ring, 32-byte points) of the points
    with ``max(min_range, range_min) < r < min(max_range, range_max - range_min - 0.01)``, ring 0 the lowest."""

    def setup(self) -> None:
        super().setup()
        config = self.lidar = self.cfg
        self.pub = self.create_publisher(msgs.PointCloud2, config.topic, 1)
        az, el = lidar3d_angles(config)
        self.unit = np.stack(
            [
                np.cos(el)[:, None] * np.cos(az)[None, :],
                np.cos(el)[:, None] * np.sin(az)[None, :],
                np.broadcast_to(np.sin(el)[:, None], (len(el), len(az))),
            ],
            axis=-1,
        )

    def update(self) -> None:
        if self.read(self.pub):
            self.pub.publish(self.cloud(lidar3d_ranges(self.sim, self.lidar, self.rng), self.executor.now_ns))

    def cloud(self, ranges: np.ndarray, stamp_ns: int) -> Any:
        """The plugin's cloud from ranges (rings x samples); organised (NaN: dropped) if ``organize_cloud``."""
        c = self.lidar
        words = np.empty((ranges.size, 8), dtype=np.float32)
        lo = max(c.min_range, c.range_min)
        hi = min(c.max_range, c.range_max - c.range_min - 0.01)
        cap = c.range_max - c.range_min
        n = scan_cloud(ranges, self.unit, lo, hi, cap, c.organize_cloud, words, words.view(np.uint32))
        height, width = (c.rings, c.samples) if c.organize_cloud else (1, n)
        dense = n == 0 or not np.isnan(words[:n, 0]).any()
        fields = VELODYNE_FIELDS
        return cloud_message(stamp_ns, self.frame_id, words[:n], fields, height=height, width=width, dense=dense)


class RangePlugin(SensorPlugin[RangeConfig]):
    """``gazebo_ros_range``: ``sensor_msgs/Range`` (ULTRASOUND 0 / INFRARED 1, ``field_of_view`` the plugin's
    ``<fov>``, min/max the ray sensor's range) with the nearest return of the sensor's rays."""

    def setup(self) -> None:
        super().setup()
        config = self.range = self.cfg
        self.pub = self.create_publisher(msgs.Range, config.topic, 1)

    def update(self) -> None:
        if not self.read(self.pub):
            return
        c = self.range
        self.pub.publish(
            msgs.Range(
                header=msgs.header(self.executor.now_ns, self.frame_id),
                radiation_type=0 if c.radiation == "ultrasound" else 1,
                field_of_view=float(c.fov),
                min_range=float(c.range_min),
                max_range=float(c.range_max),
                range=float(range_reading(self.sim, c, self.rng)),
            )
        )


class BumperPlugin(SensorPlugin[BumperConfig]):
    """``gazebo_ros_bumper``: ``gazebo_msgs/ContactsState`` of the bumper link's contacts with anything but the
    floor (MuJoCo contacts of the link's body: position and normal in ``frameName``'s frame — ``world`` or a
    link — depth in m, contact force as the wrench), published every update even when empty (Noetic does)."""

    def setup(self) -> None:
        super().setup()
        config = self.bumper = self.cfg
        self.pub = self.create_publisher(msgs.ContactsState, config.topic, 1)

    def update(self) -> None:
        if self.read(self.pub):
            self.pub.publish(
                msgs.ContactsState(header=msgs.header(self.executor.now_ns, self.frame_id), states=self.states())
            )

    def states(self) -> list[Any]:
        """One ContactState per contact of the bumper's body with a world geom."""
        sim = self.sim
        m, d = sim.model, sim.data
        body = sim.link_body(self.bumper.link)
        if self.frame_id == "world" or self.frame_id not in (sim.robot.links if sim.robot else {}):
            pos0, rot = np.zeros(3), np.eye(3)
        else:
            pos0, rot = sensor_pose(sim, self.frame_id, Origin())
        force = np.zeros(6)
        out = []
        for i in range(d.ncon):
            con = d.contact[i]
            g1, g2 = int(con.geom1), int(con.geom2)
            mine = m.geom_bodyid[g1] == body, m.geom_bodyid[g2] == body
            if not any(mine) or all(mine):
                continue
            other = g2 if mine[0] else g1
            if m.geom_type[other] == mujoco.mjtGeom.mjGEOM_PLANE:
                continue  # the floor
            mujoco.mj_contactForce(m, d, i, force)
            frame = con.frame.reshape(3, 3)
            f_world = frame.T @ force[:3] * (1 if mine[0] else -1)
            normal = frame[0] * (1 if mine[0] else -1)
            wrench = msgs.Wrench(force=msgs.vector3(rot.T @ f_world), torque=msgs.vector3(np.zeros(3)))
            out.append(
                msgs.ContactState(
                    info=f"Debug:  i:({i}/{d.ncon})",
                    collision1_name=self.bumper.collision,
                    collision2_name=_geom_name(m, other),
                    wrenches=[wrench],
                    total_wrench=wrench,
                    contact_positions=[msgs.vector3(rot.T @ (con.pos - pos0))],
                    contact_normals=[msgs.vector3(rot.T @ normal)],
                    depths=np.array([max(0.0, -float(con.dist))]),
                )
            )
        return out


def _geom_name(m: mujoco.MjModel, g: int) -> str:
    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g)
    body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g])) or "world"
    return name or f"{body}::geom{g}"


def sensor_plugins(executor: Executor, namespace: str, sim: Simulation) -> list[Node]:
    """One node per extra sensor of ``sim``'s robot (cameras, depth cameras, 3D lidars, ranges, bumpers)."""
    assert sim.robot is not None
    suite = sim.robot.sensors
    nodes: list[Node] = []
    for cam in suite.cameras:
        cls = DepthCameraPlugin if cam.kind == "depth" else CameraPlugin
        nodes.append(cls(executor, namespace=namespace, sim=sim, config=cam))
    nodes += [VelodynePlugin(executor, namespace=namespace, sim=sim, config=c) for c in suite.lidars3d]
    nodes += [RangePlugin(executor, namespace=namespace, sim=sim, config=c) for c in suite.ranges]
    nodes += [BumperPlugin(executor, namespace=namespace, sim=sim, config=c) for c in suite.bumpers]
    return nodes
