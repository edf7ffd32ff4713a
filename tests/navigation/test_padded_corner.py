"""Issue 24: the sensor variants of the paper's robot carry footprint padding that holds their collision geometry
and still leave an obstacle's corner. In tables_sonar's goal 3, padded to 0.04 m with mybot's occdist_scale 0.05,
TrajectoryPlannerROS turned on the spot for the rest of the goal in free space beside the step: each forward rollout
raised the obstacle term (the padded 16-gon's edge cost, 0.05 x it) more than it lowered the path and goal distances
round the corner, so an in-place turn, which keeps the cost where it is, won every cycle (ROS's rule)."""

from __future__ import annotations

import math
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
import yaml

from navlab import resources
from navlab.description import load_robot_named
from navlab.description.footprint import collision_points_xy, collision_reach
from navlab.mapping import load_map
from navlab.navigation.controllers.common import circle_footprint
from navlab.navigation.controllers.trajectory import TrajectoryPlannerROS
from navlab.navigation.costmap import LayeredCostmap
from navlab.navigation.costmap.footprint import points_in_polygon

FIXTURES = Path(__file__).parents[1] / "fixtures" / "maps"
# the stuck trial's global plan through its local window (m, grid-local), every 8th pose: over the step's corner
# and west to the window's edge
PLAN = [(1.99, 1.98), (1.83, 2.11), (1.66, 2.22), (1.47, 2.29), (1.28, 2.33), (1.08, 2.35), (0.88, 2.35)]
PLAN += [(0.68, 2.33), (0.49, 2.27), (0.32, 2.17), (0.16, 2.05), (0.0, 1.92), (-0.15, 1.8)]


def _params(robot: str, name: str) -> dict:
    return yaml.safe_load(resources.path(f"params/{robot}/{name}.yaml").read_text())


def _drive(robot: str, occdist_scale: float | None = None, seconds: float = 10.0) -> float:
    """Where (x, m) the robot is after ``seconds`` of TrajectoryPlannerROS at 20 Hz from the stuck pose (heading
    north-west along the plan), on the stuck trial's obstacles inflated with ``robot``'s costmap parameters."""
    common = {k: v for k, v in _params(robot, "costmap_common_params").items() if not k.endswith("_layer")}
    costmap = LayeredCostmap({**common, "global_frame": "map", "robot_base_frame": "chassis", "static_map": True})
    costmap.set_map(load_map(FIXTURES / "tables_goal3_corner.yaml"))
    grid = costmap.update_map((2.0, 2.0, 0.0))
    params = _params(robot, "base_local_planner_params")["TrajectoryPlannerROS"]
    if occdist_scale is not None:
        params["occdist_scale"] = occdist_scale
    planner = TrajectoryPlannerROS(params, robot_radius=costmap.inscribed_radius, controller_frequency=20.0)
    dense = np.vstack([np.linspace(a, b, 8, endpoint=False) for a, b in pairwise(PLAN)] + [PLAN[-1:]])
    planner.set_plan(dense)
    x, y, yaw, v, w, dt = 1.994, 1.984, 2.3, 0.0, 0.0, 0.05
    for _ in range(round(seconds / dt)):
        v, w = planner.compute_velocity((x, y, yaw), (v, w), grid)
        x, y, yaw = x + v * math.cos(yaw) * dt, y + v * math.sin(yaw) * dt, yaw + w * dt
    return x


@pytest.mark.parametrize("robot", ["mybot_sonar", "mybot_depth"])
def test_padded_sensor_robots_hold_their_geometry_and_leave_the_corner(robot: str) -> None:
    model = load_robot_named(robot)
    common = _params(robot, "costmap_common_params")
    radius = common["robot_radius"] + common["footprint_padding"]
    assert collision_reach(model) <= radius
    assert points_in_polygon(collision_points_xy(model), circle_footprint(radius)).all()  # the 16-gon holds it
    assert _drive(robot) < 0.5  # round the corner and 1.5 m on towards the window's edge
    assert _drive(robot, occdist_scale=0.05) > 1.9  # mybot's obstacle weight: turns on the spot
