"""MuJoCo simulation of a ROS robot in a Gazebo world, with Gazebo-like plugins.

``Simulation`` is the pure stepping API (physics, wheel motors, lidar (a Numba planar caster that
matches ``mj_multiRay``, which still casts against meshes), IMU,
spawning); :mod:`navlab.sim.plugins` wraps it as nodes (diff_drive, lidar, imu, joint states,
ground truth); :func:`launch_sim` starts the ``gazebo`` node with all of them on an executor.
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.sim.errors import SimError
    from navlab.sim.gazebo import GazeboSim, launch_sim, load_robot_named, load_world_named
    from navlab.sim.simulation import Pose3D, Simulation
    from navlab.sim.spawn import parse_spawn_spec, primitive_model

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
}
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
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
