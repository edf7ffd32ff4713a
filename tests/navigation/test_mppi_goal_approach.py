"""The Jackal's MPPI (params/jackal) keeps its speed until the goal is near: within ``prune_distance`` of the goal
GoalCritic steers instead of PathFollowCritic, whose pull of every trajectory's end to the plan's end (inside the
2 s horizon from ~3 m out) slowed the robot from 1.6 to 1.2 m/s before BARN's 1 m goal circle."""

import math

import numpy as np
import yaml

from navlab import resources
from navlab.grid import Grid
from navlab.navigation.controllers import synthetic as syn
from navlab.navigation.controllers.mppi import MPPIController

DT = 0.05  # s
BOX = [[-0.254, -0.215], [-0.254, 0.215], [0.254, 0.215], [0.254, -0.215]]  # the Jackal's footprint
NAV2_THRESHOLDS = {"GoalCritic": 1.4, "PathFollowCritic": 1.4, "PathAlignCritic": 0.5}  # Nav2's defaults, m


def jackal_mppi(**critics: float) -> dict:
    """The Jackal's MPPIController section at bench clutter's 2 m/s; ``critics``: threshold_to_consider per critic."""
    p = yaml.safe_load(resources.path("params/jackal/base_local_planner_params.yaml").read_text())["MPPIController"]
    p = {**p, "vx_max": 2.0}
    for name, threshold in critics.items():
        p[name] = {**p.get(name, {}), "threshold_to_consider": threshold}
    return p


def time_to_goal_circle(params: dict) -> tuple[float, float]:
    """From rest, 6 m of open ground straight to the goal: the time (s) until the robot is within 1 m of it, and
    where it stands (m from the goal) 3 s later."""
    ground = Grid(np.zeros((300, 300), dtype=np.uint8), 0.05, (-5.0, -5.0, 0.0), "odom")
    ctrl = MPPIController(params, rng=np.random.default_rng(0), footprint=BOX)
    ctrl.set_plan(np.column_stack([np.linspace(0.0, 6.0, 121), np.zeros(121), np.zeros(121)]))
    pose, vel, reached = (0.0, 0.0, 0.0), (0.0, 0.0), math.inf
    for k in range(400):
        vel = ctrl.compute_velocity(pose, vel, syn.window(ground, pose[0], pose[1], 8.0))
        x, y, th = pose
        pose = (x + vel[0] * math.cos(th) * DT, y + vel[0] * math.sin(th) * DT, th + vel[1] * DT)
        if math.hypot(pose[0] - 6.0, pose[1]) <= 1.0 and reached == math.inf:
            reached = (k + 1) * DT
        if k * DT >= reached + 3.0:
            break
    return reached, math.hypot(pose[0] - 6.0, pose[1])


def test_jackal_keeps_its_speed_into_the_goal_circle_and_stops_at_the_goal():
    files, end = time_to_goal_circle(jackal_mppi())
    nav2, _ = time_to_goal_circle(jackal_mppi(**NAV2_THRESHOLDS))
    assert files < nav2 - 0.1  # seconds sooner within 1 m of the goal
    assert end < 0.3  # and it still stops at the goal
