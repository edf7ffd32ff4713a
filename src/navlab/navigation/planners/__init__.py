"""Global planners (``base_global_planner``): navfn (``navfn/NavfnROS``) and Theta* (Nav2's ThetaStarPlanner).

Each takes a costmap ``Grid`` (uint8 costmap_2d costs) and start/goal poses (x, y, yaw) in its frame and
returns a float (N, 2) path in metres from start to goal inclusive, or None when the goal is unreachable
(``planner.last_failure`` says why). :func:`make_planner` builds one by its ROS name.
"""

from __future__ import annotations

from typing import Any

from navlab.navigation.planners.common import path_length
from navlab.navigation.planners.navfn import GlobalPlanner, GlobalPlannerParams, NavfnParams, NavfnPlanner
from navlab.navigation.planners.theta_star import ThetaStarParams, ThetaStarPlanner
from navlab.plugins import make_plugin


def make_planner(name: str, params: dict[str, Any] | None = None) -> Any:
    """The global planner registered as ``name`` (``base_global_planner``), built from its parameter dict;
    an unknown name says "did you mean"."""
    return make_plugin("global_planner", name, params, param="base_global_planner")


__all__ = [
    "GlobalPlanner",
    "GlobalPlannerParams",
    "NavfnParams",
    "NavfnPlanner",
    "ThetaStarParams",
    "ThetaStarPlanner",
    "make_planner",
    "path_length",
]
