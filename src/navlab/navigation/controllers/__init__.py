"""Local controllers (move_base's ``base_local_planner``): ROS 1's TrajectoryPlannerROS and DWAPlannerROS,
and a Nav2-style MPPI controller. Each follows a global plan over a local costmap and implements
``navlab.plugins.Controller``: ``from_params``, ``set_plan``, ``compute_velocity(pose, velocity, costmap) ->
ControlResult(v, w, valid, local_plan)`` (the chosen rollout, (N, 3), for ``/local_plan``), ``is_goal_reached``.
The rollout planners share their cycle in ``rollout_controller``.
"""

from navlab.navigation.controllers.dwa import DWAPlannerROS, DWBLocalPlanner
from navlab.navigation.controllers.params import DWAPlannerParams, TrajectoryPlannerParams
from navlab.navigation.controllers.trajectory import TrajectoryPlannerROS

__all__ = ["DWAPlannerParams", "DWAPlannerROS", "DWBLocalPlanner", "TrajectoryPlannerParams", "TrajectoryPlannerROS"]
