"""TrajectoryPlannerROS scored as base_local_planner scores, with a clutter benchmark's own settings (BARN's
TrajectoryPlannerROS file: dwa at 0.5 m/s, 2 s rollouts, meter scoring, occdist_scale 0.1; a 0.42 m x 0.33 m
footprint padded by 0.1 m, 0.30 m inflation). Hand-made costmaps, one planning cycle or a kinematic closed loop.
"""

from __future__ import annotations

import math

import numpy as np
import yaml

from navlab.core.launch import resources_dir
from navlab.grid import Grid
from navlab.navigation.controllers import TrajectoryPlannerROS
from navlab.navigation.controllers import synthetic as syn

RES = 0.05
FOOTPRINT = [[-0.31, -0.265], [-0.31, 0.265], [0.31, 0.265], [0.31, -0.265]]  # 0.42 x 0.33 padded by 0.1


def benchmark_params(**over: object) -> dict:
    """jackal_skid's shipped TrajectoryPlannerROS section (the benchmark's values), with overrides."""
    path = resources_dir() / "params" / "jackal_skid" / "base_local_planner_params.yaml"
    return {**yaml.safe_load(path.read_text())["TrajectoryPlannerROS"], **over}


def gap_world(gap: float, size: float = 8.0) -> Grid:
    """Two blocks 0.8 m deep across the way at x 0.8..1.6 m leaving a ``gap`` m wide opening at y = 0, side walls
    at |y| = 1.5 m; inflated as the benchmark's costmap does (inscribed 0.265 m, inflation 0.30 m)."""
    n = round(size / RES)
    c = (np.arange(n) + 0.5) * RES - size / 2
    x, y = np.meshgrid(c, c)
    mask = (x >= 0.8) & (x <= 1.6) & (np.abs(y) >= gap / 2) & (np.abs(y) <= 1.5)
    mask |= (np.abs(y) >= 1.5) & (x > -2.5) & (x < 3.5)
    cost = syn.inflated(mask, RES, inscribed_radius=0.265, inflation_radius=0.30)
    return Grid(cost, RES, (-size / 2, -size / 2, 0.0), "odom")


def planner(**over: object) -> TrajectoryPlannerROS:
    return TrajectoryPlannerROS(benchmark_params(**over), footprint=FOOTPRINT)


def test_meter_scoring_scales_the_distance_biases_not_occdist():
    """ROS 1: meter_scoring multiplies pdist_scale and gdist_scale by the resolution; occdist_scale stays as given."""
    world = gap_world(0.7)
    start = (0.1, 0.0, 0.0)  # facing the gap: every rollout's footprint reaches the inflated band
    plan = syn.grid_plan(world, start[:2], (3.0, 0.0))
    costs = {}
    for meter in (True, False):
        for weights in ((0.0, 0.0, 0.1), (0.75, 1.0, 0.0)):
            tp = planner(meter_scoring=meter, pdist_scale=weights[0], gdist_scale=weights[1], occdist_scale=weights[2])
            tp.set_plan(plan)
            tp.compute_velocity(start, (0.0, 0.0), syn.window(world, *start[:2], 6.0))
            costs[meter, weights[2] > 0] = tp.costs
    ok = costs[False, True] >= 0
    assert ok.sum() > 10 and costs[False, True][ok].max() > 0  # obstacle costs are in play
    np.testing.assert_allclose(costs[True, True][ok], costs[False, True][ok])  # occupancy: not scaled
    ok = costs[False, False] >= 0
    np.testing.assert_allclose(costs[True, False][ok], RES * costs[False, False][ok])  # distances: x resolution


def test_in_place_turn_scores_the_standstill_distances_and_wins_only_when_no_dearer():
    """createTrajectories: an in-place turn ends where the robot stands (its path and goal distances are the
    standstill's); it replaces the best forward move only when its cost is no higher. Before a 0.7 m gap, every
    forward move of the benchmark's robot brings its padded edges within the inscribed radius of the blocks
    (occdist 0.1 x 253) while a turn sweeps free cells: it turns. Before a 1.2 m gap it drives on."""
    start = (0.2, 0.0, 0.0)  # its padded nose 0.29 m from the blocks' inflation
    for gap, turns in ((0.7, True), (1.2, False)):
        world = gap_world(gap)
        tp = planner()
        tp.set_plan(syn.grid_plan(world, start[:2], (3.0, 0.0)))
        v, w = tp.compute_velocity(start, (0.0, 0.0), syn.window(world, *start[:2], 6.0))
        in_place = (tp.samples[:, 0] == 0.0) & (tp.costs >= 0)
        forward = (tp.samples[:, 0] > 0.0) & (tp.costs >= 0)
        assert in_place.any() and forward.any()
        ends = tp.trajectories[in_place, -1, :2]
        assert np.allclose(ends, start[:2], atol=1e-9)  # from a standstill an in-place turn stays put
        assert (v == 0.0 and w != 0.0) == turns, (gap, v, w)
        assert (tp.costs[in_place].min() <= tp.costs[forward].min()) == turns


def test_benchmark_settings_drive_through_a_gap_wider_than_the_padded_robot_and_its_inflation():
    """dwa: true at 0.5 m/s, no oscillation timeout (the controller alone): through a 1.2 m gap to the goal 3 m
    past the start, in a kinematic closed loop (the commanded velocity is the next cycle's)."""
    world = gap_world(1.2)
    start = (-1.0, 0.2, 0.3)
    tp = planner()
    tp.set_plan(syn.grid_plan(world, start[:2], (3.0, 0.0)))
    pose, vel = start, (0.0, 0.0)
    for _ in range(600):  # 30 s
        if math.hypot(pose[0] - 3.0, pose[1]) <= 0.25:
            break
        vel = tp.compute_velocity(pose, vel, syn.window(world, pose[0], pose[1], 6.0))
        assert tp.valid
        x, y, th = pose
        pose = (x + vel[0] * math.cos(th) * 0.05, y + vel[0] * math.sin(th) * 0.05, th + vel[1] * 0.05)
    assert math.hypot(pose[0] - 3.0, pose[1]) <= 0.25, pose
