"""``navlab bench sensors``: what the 3-D sensors cost, alone and with the whole navigation stack.

Real-time factors (simulated s per CPU s of this process, ``time.process_time``: one core) of the navigation
stack (sim + lidar + amcl + costmaps + planner + controller, ``navlab bench nav``'s four goals in
room_obstacles.world) on the paper's robot with one sensor added and read every frame:

- ``depth_nav_rtf``: mybot_depth, its 320 x 240 depth camera at 15 Hz feeding costmap_2d's VoxelLayer in both
  costmaps (the shipped params/mybot_depth);
- ``velodyne_nav_rtf``: mybot plus a VLP-16-like lidar (16 rings, 1875 samples, +-15 degrees) at 10 Hz, its
  cloud subscribed;
- ``rgb_nav_rtf``: mybot plus a 320 x 240 RGB camera at 15 Hz (MuJoCo's offscreen renderer), its image
  subscribed;
- ``lidar_nav_rtf``: mybot alone, for comparison.

Per-frame costs (ms, CPU, medians): ``depth_frame_ms`` (the 320 x 240 depth image: shapes drawn into a depth
buffer, noise), ``depth_cloud_ms`` (its organised PointCloud2), ``velodyne_scan_ms`` (30,000 rays swept shape by
shape, noise), ``velodyne_cloud_ms`` (its PointCloud2), ``rgb_frame_ms`` (render + read), ``voxel_update_ms`` (one
depth cloud message into a 4 x 4 m voxel layer, as a costmap takes it: read in the camera's frame and moved point
by point). ``goals_succeeded`` per run shows the stack still drove.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from navlab import msgs
from navlab.bench.experiments import NAV_GOALS
from navlab.core import Node

GOALS = NAV_GOALS  # bench nav's

VELODYNE = """<?xml version="1.0"?>
<robot name="mybot_velodyne" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find mybot_description)/mybot.xacro"/>
  <gazebo reference="laser">
    <sensor type="ray" name="vlp16"><pose>0 0 0.12 0 0 0</pose><update_rate>10</update_rate>
      <ray><scan><horizontal><samples>1875</samples><min_angle>-3.14159265</min_angle><max_angle>3.14159265</max_angle>
      </horizontal><vertical><samples>16</samples><min_angle>-0.2617994</min_angle><max_angle>0.2617994</max_angle>
      </vertical></scan><range><min>0.3</min><max>131</max></range></ray>
      <plugin name="velodyne" filename="libgazebo_ros_velodyne_laser.so"><topicName>/velodyne_points</topicName>
        <frameName>velodyne</frameName><min_range>0.9</min_range><max_range>130.0</max_range>
        <gaussianNoise>0.008</gaussianNoise></plugin>
    </sensor>
  </gazebo>
</robot>
"""

RGB = """<?xml version="1.0"?>
<robot name="mybot_rgb" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find mybot_description)/mybot.xacro"/>
  <gazebo reference="laser">
    <sensor type="camera" name="rgb"><pose>0.1 0 0.1 0 0 0</pose><update_rate>15</update_rate>
      <camera><horizontal_fov>1.3962634</horizontal_fov><image><width>320</width><height>240</height>
      <format>R8G8B8</format></image><clip><near>0.05</near><far>20</far></clip></camera>
      <plugin name="cam" filename="libgazebo_ros_camera.so"><cameraName>camera</cameraName>
        <frameName>camera_optical</frameName></plugin>
    </sensor>
  </gazebo>
</robot>
"""


def _nav_rtf(robot: str, seed: int, topic: str | None = None, params: str | None = None) -> dict[str, Any]:
    """RTF (CPU) of the navigation run to ``GOALS`` with ``topic`` subscribed (a reader keeps the sensor on)."""
    from navlab.experiments import run_navigation

    def reader(run: Any) -> None:
        if topic:
            kind = msgs.PointCloud2 if "points" in topic else msgs.Image
            run.add(_Reader, parameters={"topic": topic, "image": kind is msgs.Image})

    kw: dict[str, Any] = {"world": "room_obstacles", "robot": robot, "seed": seed, "on_start": reader}
    if params:
        kw["params_dir"] = params
    run_navigation(list(GOALS[:1]), goal_timeout=3, **kw)  # warm-up: Numba's caches, the GL context
    cpu0 = time.process_time()
    r = run_navigation(list(GOALS), goal_timeout=90, **kw)
    cpu = time.process_time() - cpu0
    return {
        "rtf": round(r.summary["sim_s"] / cpu, 1),
        "rtf_wall": r.summary["rtf"],
        "goals_succeeded": r.summary["goals_succeeded"],
        "collisions": r.summary["collisions"],
    }


class _Reader(Node):
    """Subscribes ``topic`` (an Image if ``image``, else a PointCloud2) so that the sensor computes every frame."""

    def __init__(
        self,
        executor: Any,
        *,
        name: str = "bench_reader",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        kind = msgs.Image if self.declare_parameter("image", False) else msgs.PointCloud2
        self.frames = 0
        self.create_subscription(kind, str(self.declare_parameter("topic", "points")), self._count, 1)

    def _count(self, _msg: Any) -> None:
        self.frames += 1


def _per_frame(fn: Any, repeat: int = 20) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        times.append((time.process_time() - t0) * 1e3)
    return round(statistics.median(times), 3)


def _frames() -> dict[str, float]:
    """Per-frame CPU costs of the sensors and the voxel update, in room_obstacles from the origin."""
    from navlab.core import Executor
    from navlab.description import load_robot
    from navlab.grid import Grid
    from navlab.io import read_xyz
    from navlab.navigation import ObservationSource, VoxelLayer
    from navlab.sim import DepthCameraPlugin, Simulation, VelodynePlugin, depth_image, lidar3d_ranges, sensor_pose
    from navlab.world import load_world

    with tempfile.TemporaryDirectory(prefix="navlab-bench-sensors-") as tmp:
        vel = Path(tmp) / "mybot_velodyne.xacro"
        vel.write_text(VELODYNE)
        lidar = load_robot(vel).sensors.lidars3d[0]
    robot = load_robot("mybot_depth")
    cam = robot.sensors.cameras[0]
    sim = Simulation(robot, load_world("room_obstacles"), visuals=True)
    rng = np.random.default_rng(0)
    depth = depth_image(sim, cam, rng)
    camera = DepthCameraPlugin(Executor(), sim=sim, config=cam)
    out = {
        "depth_frame_ms": _per_frame(lambda: depth_image(sim, cam, rng)),
        "depth_cloud_ms": _per_frame(lambda: camera.cloud(depth, 0)),
    }
    lidar.link = "chassis"
    ranges = lidar3d_ranges(sim, lidar, rng)
    velodyne = VelodynePlugin(Executor(), sim=sim, config=lidar)
    out["velodyne_scan_ms"] = _per_frame(lambda: lidar3d_ranges(sim, lidar, rng))
    out["velodyne_cloud_ms"] = _per_frame(lambda: velodyne.cloud(ranges, 0))
    try:
        from navlab.sim import CameraRenderer

        renderer = CameraRenderer(sim, cam)
        out["rgb_frame_ms"] = _per_frame(renderer.render)
        renderer.close()
    except Exception:  # no offscreen GL here
        out["rgb_frame_ms"] = float("nan")
    pos, rot = sensor_pose(sim, cam.link, cam.origin)
    optical = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # optical -> camera body axes
    points = read_xyz(camera.cloud(depth, 0), copy=False)
    layer = VoxelLayer(
        {"z_resolution": 0.05, "z_voxels": 8},
        name="voxel",
        sources={
            "cam": ObservationSource(
                data_type="PointCloud2", clearing=True, min_obstacle_height=0.04, max_obstacle_height=0.35
            )
        },
    )
    layer.match_size(Grid(np.zeros((80, 80), np.uint8), 0.05, (-2.0, -2.0, 0.0), "odom"))
    out["voxel_update_ms"] = _per_frame(lambda: layer.add_sensor_cloud(pos, rot @ optical, points, source="cam"))
    return out


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Measure and return the figures of the module docstring."""
    from navlab import resources

    seed = int(getattr(args, "seed", 0))
    out: dict[str, Any] = dict(_frames())
    with tempfile.TemporaryDirectory(prefix="navlab-bench-sensors-") as tmp:
        vel, rgb = Path(tmp) / "mybot_velodyne.xacro", Path(tmp) / "mybot_rgb.xacro"
        vel.write_text(VELODYNE)
        rgb.write_text(RGB)
        mybot_params = str(resources.root() / "params" / "mybot")
        runs = {
            "lidar": _nav_rtf("mybot", seed),
            "depth": _nav_rtf("mybot_depth", seed),
            "velodyne": _nav_rtf(str(vel), seed, "/velodyne_points", mybot_params),
            "rgb": _nav_rtf(str(rgb), seed, "/camera/image_raw", mybot_params),
        }
    for name, r in runs.items():
        out[f"{name}_nav_rtf"] = r["rtf"]
        out[f"{name}_nav_rtf_wall"] = r["rtf_wall"]
        out[f"{name}_goals_succeeded"] = r["goals_succeeded"]
    out["goals"] = len(GOALS)
    return out
