"""Issue 15's experiment keys: wheel controller, EKF and disturbances in scenarios; the path tracking metric."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.experiments.errors import ExperimentError
from navlab.experiments.metrics import distance_to_path
from navlab.experiments.navigate_run import run_navigation
from navlab.experiments.scenario import load_scenario, scenario_from_dict


def test_distance_to_path() -> None:
    plan = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]])
    pts = np.array([[1.0, 0.5], [3.0, 1.0], [-1.0, 0.0], [2.5, 3.0]])
    assert distance_to_path(pts, plan) == pytest.approx([0.5, 1.0, 1.0, math.hypot(0.5, 1.0)])
    assert distance_to_path(pts[:1], plan[:1]) == pytest.approx([math.hypot(1.0, 0.5)])


def test_shipped_comparison_scenarios() -> None:
    a, b, c = (load_scenario(f"slip_{k}") for k in ("baseline", "controller", "ekf"))
    assert (a.wheel_controller, a.ekf) == ("gazebo_ros_diff_drive", None)
    assert (b.wheel_controller, b.ekf) == ("diff_drive_controller", None)
    assert (c.wheel_controller, c.ekf) == ("diff_drive_controller", "default")
    assert a.goals == b.goals == c.goals and a.disturbances == b.disturbances == c.disturbances
    assert c.navigation_options()["disturbances"]["wheel_radius_error"] == [0.03, 0.0]


@pytest.mark.parametrize(
    "extra, message",
    [
        ({"ekf": True}, "ekf needs wheel_controller: diff_drive_controller"),
        ({"disturbances": {"slip_pathces": []}}, "did you mean 'slip_patches'"),
        ({"disturbances": {"wheel_radius_error": [0.1]}}, "expected \\[left, right\\]"),
        ({"wheel_controller": 3}, "wheel_controller: expected"),
    ],
)
def test_bad_future_work_keys(extra: dict, message: str) -> None:
    with pytest.raises(ExperimentError, match=message):
        scenario_from_dict({"goals": [[1.0, 0.0, 0.0]], **extra})


def test_controller_and_ekf_drive_a_goal_and_report_tracking_error() -> None:
    r = run_navigation(
        [(1.5, 0.0, 0.0)],
        world="room",
        wheel_controller="diff_drive_controller",
        ekf="default",
        disturbances={"slip_patches": [{"x": 0.0, "y": 0.0, "radius": 0.5, "mu": 0.05}]},
        goal_timeout=30.0,
        seed=0,
    )
    (goal,) = r.goals
    assert goal["outcome"] == "succeeded" and goal["collisions"] == 0
    assert 0.0 <= goal["tracking_error_m"] < 0.15 and goal["final_error_m"] < 0.25
    assert r.summary["localization_error_mean_m"] < 0.15
