"""Issue 24: the paper's robot's costmap footprint holds the whole robot, so the planners keep its wheels off the
walls. mybot's base is a 0.2 m-radius disc (Table I) but its wheels stick out of it (0.229 m from the centre); a
footprint of the base alone (ROS's 0.01 m padding) let navfn thread gaps the wheels graze and the local planners
drive the wheels into what the 16-gon they check left out."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from navlab import resources
from navlab.description import load_robot_named
from navlab.description.footprint import collision_points_xy, collision_reach
from navlab.grid import COST_LETHAL, GridMap
from navlab.navigation.controllers.common import circle_footprint
from navlab.navigation.costmap import LayeredCostmap
from navlab.navigation.costmap.footprint import points_in_polygon
from navlab.navigation.planners import NavfnPlanner

RES = 0.02  # m: fine enough that a doorway 2 cm narrower than the wheels is a different map from one 2 cm wider


def _costmap() -> LayeredCostmap:
    common = yaml.safe_load(resources.path("params/mybot/costmap_common_params.yaml").read_text())
    return LayeredCostmap({**common, "global_frame": "map", "robot_base_frame": "chassis", "static_map": True})


def test_the_shipped_footprint_holds_the_robots_collision_geometry() -> None:
    """The costmaps' circle (navfn, inflation) and the 16-gon costmap_2d makes of it (what TrajectoryPlannerROS and
    DWA check; its edges lie 2 % inside the circle) both hold every collision shape seen from above."""
    model = load_robot_named("mybot")
    assert collision_reach(model) == pytest.approx(0.2294, abs=1e-4)  # the wheels' outer corners
    radius = _costmap().inscribed_radius
    assert collision_reach(model) <= radius
    assert points_in_polygon(collision_points_xy(model), circle_footprint(radius)).all()


def test_navfn_takes_mybot_round_a_doorway_its_wheels_do_not_fit() -> None:
    """A wall across a 4 m x 3 m room with two doorways: 0.42 m (wider than the 0.4 m base, narrower than the
    0.43 m the wheels span) on the straight line, 1 m on a detour. The plan takes the wide one and keeps the
    robot's whole reach off every wall cell."""
    w, h = round(4.0 / RES), round(3.0 / RES)
    grid = GridMap.empty(w, h, RES, (0.0, 0.0, 0.0), fill=0)
    grid.data[0, :] = grid.data[-1, :] = grid.data[:, 0] = grid.data[:, -1] = 100
    wall = round(2.0 / RES)
    grid.data[:, wall] = 100
    narrow = round(0.8 / RES)
    grid.data[narrow : narrow + 21, wall] = 0  # 21 free cells: 0.42 m between the wall's faces
    wide = round(2.0 / RES)
    grid.data[wide : wide + 50, wall] = 0  # 1 m
    cm = _costmap()
    cm.set_map(grid)
    costs = cm.update_map((1.0, 1.0, 0.0))
    path = NavfnPlanner({}).make_plan(costs, (1.0, 1.01, 0.0), (3.0, 1.01, 0.0))
    assert path is not None
    crossing = path[np.argmin(np.abs(path[:, 0] - 2.01))]
    assert crossing[1] > 2.0  # through the wide doorway
    lethal = np.argwhere(costs.data == COST_LETHAL)
    cells = (lethal[:, ::-1] + 0.5) * RES
    nearest = min(float(np.hypot(*(cells - p).T).min()) for p in path)
    assert nearest >= collision_reach(load_robot_named("mybot"))
