"""Navigation as ROS 1 move_base has it: costmap_2d layers, global planners (navfn, Theta*), controllers.

Subpackages: ``costmap`` (layers and the layered master grid), ``planners`` (global planners),
``controllers`` (local planners). The algorithms are pure (numpy in, numpy out); nodes wire them to topics.
Names in ``_EXPORTS`` (move_base, the controllers, ...) load their module on first use.
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports
from navlab.navigation.costmap import LayeredCostmap, costmap_params
from navlab.navigation.errors import NavigationError
from navlab.navigation.goal import GoalOutcome, GoalState, MoveBaseState, RecoveryTrigger
from navlab.navigation.planners import NavfnPlanner, ThetaStarPlanner, make_planner, path_length
from navlab.navigation.progress_checker import STUCK_PREFIX, SimpleProgressChecker, stuck_window

__all__ = [
    "STUCK_PREFIX",
    "DWAPlannerROS",
    "Footprint",
    "GoalOutcome",
    "GoalState",
    "InflationLayer",
    "LayeredCostmap",
    "MPPIController",
    "MoveBase",
    "MoveBaseState",
    "NavfnPlanner",
    "NavigationError",
    "ObservationSource",
    "PurePursuit",
    "RecoveryTrigger",
    "SimpleProgressChecker",
    "StaticLayer",
    "ThetaStarPlanner",
    "TrajectoryPlannerROS",
    "VoxelLayer",
    "check_plugin",
    "costmap_params",
    "iheap_pop",
    "iheap_update",
    "make_planner",
    "path_length",
    "stuck_window",
    "synthetic",
]

if TYPE_CHECKING:
    from navlab.navigation.controllers import DWAPlannerROS, TrajectoryPlannerROS, synthetic
    from navlab.navigation.controllers.mppi import MPPIController
    from navlab.navigation.controllers.pure_pursuit import PurePursuit
    from navlab.navigation.costmap import Footprint, InflationLayer, StaticLayer
    from navlab.navigation.costmap.params import ObservationSource
    from navlab.navigation.costmap.voxel_layer import VoxelLayer
    from navlab.navigation.move_base import MoveBase
    from navlab.navigation.planners.common import iheap_pop, iheap_update
    from navlab.navigation.plugin_check import check_plugin

_EXPORTS = {
    "check_plugin": "navlab.navigation.plugin_check",
    "DWAPlannerROS": "navlab.navigation.controllers",
    "Footprint": "navlab.navigation.costmap",
    "InflationLayer": "navlab.navigation.costmap",
    "MPPIController": "navlab.navigation.controllers.mppi",
    "MoveBase": "navlab.navigation.move_base",
    "ObservationSource": "navlab.navigation.costmap.params",
    "PurePursuit": "navlab.navigation.controllers.pure_pursuit",
    "StaticLayer": "navlab.navigation.costmap",
    "TrajectoryPlannerROS": "navlab.navigation.controllers",
    "VoxelLayer": "navlab.navigation.costmap.voxel_layer",
    "iheap_pop": "navlab.navigation.planners.common",
    "iheap_update": "navlab.navigation.planners.common",
    "synthetic": "navlab.navigation.controllers:synthetic",
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
