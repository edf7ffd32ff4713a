"""The goal checker and Nav2's progress checker: a goal that settles within tolerance, a robot that cannot make
progress reported ``stuck`` (not ``timeout``), and the closest approach to the goal reported honestly."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.experiments.navigate_run import run_navigation
from navlab.grid import COST_LETHAL, Grid
from navlab.navigation.errors import NavigationError
from navlab.navigation.keepout import held_up_at, with_keepouts
from navlab.navigation.progress_checker import SimpleProgressChecker, stuck_window


def test_progress_checker_counts_time_near_one_pose() -> None:
    pc = SimpleProgressChecker({"required_movement_radius": 0.5, "movement_time_allowance": 10.0})
    assert pc.check((0.0, 0.0, 0.0), 0.0)
    assert pc.check((0.4, 0.0, 1.0), 9.0)  # turning and creeping within 0.5 m is not progress ...
    assert not pc.check((0.3, 0.1, 2.0), 10.5)  # ... and after 10 s it is stuck
    assert pc.check((0.6, 0.0, 0.0), 11.0)  # moving 0.5 m starts the clock again
    assert pc.idle_s(15.0) == pytest.approx(4.0)
    off = SimpleProgressChecker({"movement_time_allowance": 0.0})
    assert off.check((0.0, 0.0, 0.0), 0.0) and off.check((0.0, 0.0, 0.0), 1e6)
    with pytest.raises(NavigationError, match="required_movement_radius"):
        SimpleProgressChecker({"required_movement_radius": -1.0})


def test_progress_toward_the_goal_catches_a_robot_that_shuttles_in_and_out_of_a_pocket() -> None:
    """Driving 1 m into a pocket and back out every 4 s is movement (Nav2's checker is content) but never
    brings the goal nearer: with navlab's goal-progress allowance the checker reports no progress."""
    params = {"required_movement_radius": 0.5, "movement_time_allowance": 10.0}
    nav2 = SimpleProgressChecker(params)
    toward = SimpleProgressChecker({**params, "required_goal_progress": 0.5, "goal_progress_time_allowance": 20.0})
    goal, verdicts = (-5.0, 0.0), []  # the pocket leads away from the goal
    for k in range(61):  # 30 s, a check every 0.5 s
        pose = (abs((k % 8) - 4) * 0.25, 0.0, 0.0)  # 0 -> 1 m -> 0 every 4 s
        assert nav2.check(pose, k * 0.5)
        verdicts.append(toward.check(pose, k * 0.5, goal))
    assert all(verdicts[:41]) and not verdicts[-1] and toward.toward_goal
    assert toward.stuck_reason(30.0).startswith("stuck: the robot came no nearer the goal by 0.5 m in 28.5 s")
    toward.restart_clocks(30.0)  # after a recovery the robot has its allowance again
    assert toward.check((0.0, 0.0, 0.0), 31.0, goal)
    assert toward.check((-0.6, 0.0, 0.0), 49.0, goal) and toward.progressed  # 0.6 m nearer: progress
    assert toward.check((-0.6, 0.0, 0.0), 52.0, None)  # no goal known: Nav2's check alone


def test_a_keepout_closes_the_gap_that_held_the_robot_up() -> None:
    """The costliest cell of the plan ahead becomes a lethal disc for the planner; the costmap itself is kept."""
    costmap = Grid(np.zeros((40, 60), dtype=np.uint8), 0.05, (-1.0, -1.0, 0.0), "odom")
    costmap.data[20, 30] = 200  # a gap's costly middle at (0.525, 0.025)
    plan = np.stack([np.linspace(-0.9, 1.9, 57), np.full(57, 0.025)], axis=1)
    assert held_up_at(plan, costmap, (-0.9, 0.0, 0.0)) == pytest.approx((0.5, 0.025))
    assert held_up_at(plan, costmap, (1.5, 0.0, 0.0)) is None  # past it: nothing ahead holds the robot up
    blocked = with_keepouts(costmap, [(0.525, 0.025)])
    assert blocked.value_at(np.array([[0.525, 0.025], [0.525, 0.35]]), outside=0).tolist() == [COST_LETHAL, 0]
    assert costmap.data.max() == 200 and with_keepouts(costmap, []) is costmap


def test_stuck_window_reads_a_true_path() -> None:
    still = [(t * 0.1, 1.0 + 0.001 * t, 2.0) for t in range(300)]  # 30 s within a few cm
    assert stuck_window(still, 20.0, 0.5)
    moving = [(t * 0.1, 0.05 * t, 0.0) for t in range(300)]
    assert not stuck_window(moving, 20.0, 0.5)
    assert not stuck_window(still[:100], 20.0, 0.5)  # 10 s of path cannot show 20 s of standing still


def test_a_goal_settles_within_tolerance_and_a_crawling_robot_is_reported_stuck() -> None:
    """The first goal is reached: the truth's final error is within the tolerance, and the closest approach is
    no farther than where it ended. Then a controller capped at 2 cm/s cannot make 0.5 m of progress in 2 s:
    the progress checker runs the recoveries and then ends the goal ``stuck``, with how near it came."""
    r = run_navigation([(1.0, 0.0, 0.0)], world="room", controller="mppi", goal_timeout=30)
    g = r.goals[0]
    assert g["outcome"] == "succeeded" and g["final_error_m"] <= g["goal_tolerance_m"]
    assert g["near_goal_m"] <= g["final_error_m"] + 1e-9
    assert not g["near_miss"] and g["time_under_safety_s"] == 0.0 and g["min_clearance_m"] > 0.1
    crawl = {
        "MPPIController.vx_max": 0.02,
        "progress_checker.movement_time_allowance": 2.0,
        "recovery_behaviors": [{"name": "back_up", "type": "nav2_behaviors/BackUp"}],
    }
    r = run_navigation([(2.0, 0.0, 0.0)], world="room", controller="mppi", goal_timeout=30, move_base_params=crawl)
    g = r.goals[0]
    assert g["outcome"] == "stuck" and g["move_base_outcome"] == "aborted", g
    assert g["reason"].startswith("stuck") and g["time_s"] < 15.0
    assert 1.8 <= g["near_goal_m"] <= 2.0 and g["near_goal_m"] <= g["final_error_m"]
