"""MuJoCo simulation of a ROS robot in a Gazebo world, with Gazebo-like plugins.

``Simulation`` is the pure stepping API (physics, wheel motors, lidar (a Numba planar caster that
matches ``mj_multiRay``, which still casts against meshes), IMU,
spawning); :mod:`navlab.sim.plugins` wraps it as nodes (diff_drive, lidar, imu, joint states,
ground truth); :func:`launch_sim` starts the ``gazebo`` node with all of them on an executor.
"""

from navlab.sim.errors import SimError
from navlab.sim.gazebo import GazeboSim, launch_sim, load_robot_named, load_world_named
from navlab.sim.simulation import Pose3D, Simulation
from navlab.sim.spawn import parse_spawn_spec, primitive_model

__all__ = [
    "GazeboSim",
    "Pose3D",
    "SimError",
    "Simulation",
    "launch_sim",
    "load_robot_named",
    "load_world_named",
    "parse_spawn_spec",
    "primitive_model",
]
