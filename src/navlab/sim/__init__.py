"""MuJoCo simulation of a ROS robot in a Gazebo world, with Gazebo-like plugins.

``Simulation`` is the pure stepping API (physics, wheel motors, lidar (a Numba planar caster that
matches ``mj_multiRay``, which still casts against meshes), IMU,
spawning); :mod:`navlab.sim.plugins` wraps it as nodes (diff_drive, lidar, imu, joint states,
ground truth); :func:`launch_sim` starts the ``gazebo`` node with all of them on an executor.
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.sim.camera_render import CameraRenderer
    from navlab.sim.decompose import concave_meshes, convex_parts, default_reach, default_workers, robot_reach
    from navlab.sim.disturbances import parse_disturbances
    from navlab.sim.errors import SimError
    from navlab.sim.gazebo import GazeboSim, launch_sim, load_robot_named, load_world_named
    from navlab.sim.lidar_rays import lidar_angles
    from navlab.sim.render import render_image, save_png
    from navlab.sim.sensor_plugins import DepthCameraPlugin, VelodynePlugin
    from navlab.sim.sensors3d import depth_image, depth_points, lidar3d_ranges, sensor_pose
    from navlab.sim.simulation import Pose3D, Simulation
    from navlab.sim.spawn import check_start_pose, parse_spawn_spec, primitive_model

_EXPORTS = {
    "GazeboSim": "navlab.sim.gazebo",
    "Pose3D": "navlab.sim.simulation",
    "SimError": "navlab.sim.errors",
    "Simulation": "navlab.sim.simulation",
    "launch_sim": "navlab.sim.gazebo",
    "load_robot_named": "navlab.sim.gazebo",
    "load_world_named": "navlab.sim.gazebo",
    "parse_spawn_spec": "navlab.sim.spawn",
    "primitive_model": "navlab.sim.spawn",
    "CameraRenderer": "navlab.sim.camera_render",
    "DepthCameraPlugin": "navlab.sim.sensor_plugins",
    "VelodynePlugin": "navlab.sim.sensor_plugins",
    "check_start_pose": "navlab.sim.spawn",
    "concave_meshes": "navlab.sim.decompose",
    "convex_parts": "navlab.sim.decompose",
    "default_reach": "navlab.sim.decompose",
    "default_workers": "navlab.sim.decompose",
    "depth_image": "navlab.sim.sensors3d",
    "depth_points": "navlab.sim.sensors3d",
    "lidar3d_ranges": "navlab.sim.sensors3d",
    "lidar_angles": "navlab.sim.lidar_rays",
    "parse_disturbances": "navlab.sim.disturbances",
    "render_image": "navlab.sim.render",
    "robot_reach": "navlab.sim.decompose",
    "save_png": "navlab.sim.render",
    "sensor_pose": "navlab.sim.sensors3d",
}
__all__ = [
    "CameraRenderer",
    "DepthCameraPlugin",
    "GazeboSim",
    "Pose3D",
    "SimError",
    "Simulation",
    "VelodynePlugin",
    "check_start_pose",
    "concave_meshes",
    "convex_parts",
    "default_reach",
    "default_workers",
    "depth_image",
    "depth_points",
    "launch_sim",
    "lidar3d_ranges",
    "lidar_angles",
    "load_robot_named",
    "load_world_named",
    "parse_disturbances",
    "parse_spawn_spec",
    "primitive_model",
    "render_image",
    "robot_reach",
    "save_png",
    "sensor_pose",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
