"""Navigation as ROS 1 move_base has it: costmap_2d layers, global planners (navfn, Theta*), controllers.

Subpackages: ``costmap`` (layers and the layered master grid), ``planners`` (global planners),
``controllers`` (local planners). The algorithms are pure (numpy in, numpy out); nodes wire them to topics.
"""

from navlab.navigation.costmap import LayeredCostmap, costmap_params
from navlab.navigation.errors import NavigationError
from navlab.navigation.goal import GoalOutcome, GoalState, MoveBaseState, RecoveryTrigger
from navlab.navigation.planners import NavfnPlanner, ThetaStarPlanner, make_planner, path_length
from navlab.navigation.progress_checker import STUCK_PREFIX, SimpleProgressChecker, stuck_window

__all__ = [
    "STUCK_PREFIX",
    "GoalOutcome",
    "GoalState",
    "LayeredCostmap",
    "MoveBaseState",
    "NavfnPlanner",
    "NavigationError",
    "RecoveryTrigger",
    "SimpleProgressChecker",
    "ThetaStarPlanner",
    "costmap_params",
    "make_planner",
    "path_length",
    "stuck_window",
]
