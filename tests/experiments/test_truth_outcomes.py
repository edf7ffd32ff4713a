"""Outcomes judged by the simulator's truth, with move_base's own verdict beside them (issue 30)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from navlab.core import Node
from navlab.experiments.navigate_run import run_navigation
from navlab.experiments.scenario import scenario_from_dict
from navlab.experiments.trials import read_results, run_experiment

# no map, no amcl: move_base trusts the wheel odometry, and wheels 30 % larger than described make it drift:
# the robot truly ends ~0.4 m from the goal when odometry says it is within move_base's 0.15 m
DRIFT = {
    "name": "drift",
    "world": "room",
    "map": "none",
    "goals": [[2.0, 0.0, 0.0]],
    "time_limit": 40,
    "disturbances": {"wheel_radius_error": [0.3, 0.3]},
}


def test_odometry_drift_is_move_base_success_but_truth_failure(tmp_path: Path) -> None:
    summary = run_experiment(scenario_from_dict(DRIFT), tmp_path)
    (trial,) = read_results(tmp_path / "results.jsonl")
    (goal,) = trial["per_goal"]
    assert goal["move_base_outcome"] == "succeeded"  # move_base's verdict, from odometry
    assert goal["final_error_m"] > goal["goal_tolerance_m"] == 0.3  # the truth: not there
    assert goal["outcome"] == "not_reached" and goal["false_success"]
    assert "move_base reported success" in goal["reason"]
    assert not trial["success"] and trial["move_base_success"] and trial["failure"] == "not_reached"
    assert trial["false_success"] == 1 and trial["spl"] in (0.0, None)
    assert summary["success_rate"] == 0.0 and summary["move_base_success_rate"] == 1.0
    assert summary["false_success"] == 1 and summary["final_error_mean_m"] > 0.3


def test_a_goal_cancelled_at_13_s_reads_preempted_at_13_s() -> None:
    def cancel_later(run: Any) -> None:  # the goal is sent after the run's first second
        node = run.add(Node, name="canceller")
        timer: list[Any] = []

        def cancel() -> None:
            timer[0].cancel()
            run.node("move_base").cancel_goal()  # what actionlib's cancel does

        timer.append(node.create_timer(14.0, cancel))

    r = run_navigation(
        [(-3.5, -0.5, 3.14)], world="room_obstacles", pose=(4.3, 1.0, 0.0), goal_timeout=110, on_start=cancel_later
    )
    (goal,) = r.goals
    assert goal["outcome"] == "preempted" and goal["move_base_outcome"] == "preempted", goal
    assert goal["reason"] == "cancelled" and goal["time_s"] == pytest.approx(13.0, abs=0.01)
    assert not goal["false_success"] and r.summary["goals_succeeded"] == 0
