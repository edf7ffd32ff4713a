"""MuJoCo simulation of a ROS robot in a Gazebo world, with Gazebo-like plugins.

``Simulation`` is the pure stepping API (physics, wheel motors, lidar via ``mj_multiRay``, IMU,
spawning); :mod:`navlab.sim.plugins` wraps it as nodes (diff_drive, lidar, imu, joint states,
ground truth) for the executor; :func:`launch_sim` starts them all.
"""

from navlab.sim.errors import SimError
from navlab.sim.simulation import Pose3D, Simulation

__all__ = ["Pose3D", "SimError", "Simulation"]
