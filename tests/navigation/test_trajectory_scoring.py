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


def test_meter_scoring_scales_all_three_biases_as_noetic_scores_once_running():
    """Noetic's start-up reconfigure re-reads the biases and scales pdist, gdist and occdist together (its
    meter_scoring_ reading true) or none (reading false): costs x resolution, the same choice, either way."""
    world = gap_world(0.7)
    start = (0.1, 0.0, 0.0)  # facing the gap: every rollout's footprint reaches the inflated band
    plan = syn.grid_plan(world, start[:2], (3.0, 0.0))
    costs, commands = {}, {}
    for meter in (True, False):
        for weights in ((0.0, 0.0, 0.1), (0.75, 1.0, 0.0), (0.75, 1.0, 0.1)):
            tp = planner(meter_scoring=meter, pdist_scale=weights[0], gdist_scale=weights[1], occdist_scale=weights[2])
            tp.set_plan(plan)
            commands[meter, weights] = tp.compute_velocity(start, (0.0, 0.0), syn.window(world, *start[:2], 6.0))[:2]
            costs[meter, weights] = tp.costs
    for weights in ((0.0, 0.0, 0.1), (0.75, 1.0, 0.0), (0.75, 1.0, 0.1)):
        ok = costs[False, weights] >= 0
        assert ok.sum() > 10 and costs[False, weights][ok].max() > 0
        np.testing.assert_allclose(costs[True, weights][ok], RES * costs[False, weights][ok])
        assert commands[True, weights] == commands[False, weights]


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


def closed_loop(world: Grid, tp: TrajectoryPlannerROS, start: tuple[float, float, float], seconds: float = 30.0):
    """The controller alone (no move_base: no oscillation timeout, no recovery) driving a kinematic robot from
    rest at ``start`` to (3, 0) at 20 Hz, the commanded velocity being the next cycle's; (reached, in-place
    turns commanded, final pose)."""
    tp.set_plan(syn.grid_plan(world, start[:2], (3.0, 0.0)))
    pose, vel, turns = start, (0.0, 0.0), 0
    for _ in range(round(seconds * 20)):
        if math.hypot(pose[0] - 3.0, pose[1]) <= 0.25:
            return True, turns, pose
        vel = tuple(tp.compute_velocity(pose, vel, syn.window(world, pose[0], pose[1], 6.0))[:2])
        assert tp.valid
        turns += vel[0] == 0.0 and vel[1] != 0.0
        x, y, th = pose
        pose = (x + vel[0] * math.cos(th) * 0.05, y + vel[0] * math.sin(th) * 0.05, th + vel[1] * 0.05)
    return False, turns, pose


def test_benchmark_settings_drive_through_a_gap_wider_than_the_padded_robot_and_its_inflation():
    """dwa: true at 0.5 m/s, no oscillation timeout (the controller alone): through a 1.2 m gap to the goal 3 m
    past the start, in a kinematic closed loop (the commanded velocity is the next cycle's)."""
    reached, _, pose = closed_loop(gap_world(1.2), planner(), (-1.0, 0.2, 0.3))
    assert reached, pose


def test_a_spot_where_the_old_scoring_spun_now_moves_on():
    """The benchmark's settings (dwa: true, 0.5 m/s, meter_scoring, the controller alone: oscillation timeout 0),
    at rest 0.55 m before an 0.8 m gap, turned 0.5 rad away from it: turning in place sweeps the padded corners
    through the blocks' inflation (cost ~200). Scored as noetic scores once running (the three biases x the
    resolution), a forward move through the gap (occdist x 253 in the inscribed band, less 1 m of progress) is
    cheaper than that turn, and the robot drives through. The old scoring (pdist and gdist x the resolution,
    occdist as given: initialize's values, which noetic's start-up reconfigure replaces) valued the same metre of
    progress 20 times less: the turn won, cycle after cycle, and the robot spun for ever."""
    world, start = gap_world(0.8), (0.25, 0.0, 0.5)
    reached, turns, pose = closed_loop(world, planner(), start)
    assert reached and turns <= 20, (turns, pose)
    old = planner(meter_scoring=False, pdist_scale=0.75 * RES, gdist_scale=1.0 * RES)  # the old weights
    reached, turns, pose = closed_loop(world, old, start)
    assert not reached and turns > 300 and pose[0] < 0.8, (turns, pose)  # never into the gap
