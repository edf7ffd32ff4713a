"""Scenario obstacles are placed as an experimenter would: never on the start, a goal or the robot, so every
trial is a trial of navigation (a refused goal is not)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import load_scenario, scenario_from_dict
from navlab.experiments.scenario_obstacles import check_fixed_obstacles, placements, robot_reach
from navlab.experiments.trials import run_trial


class Drive:
    """The robot's true pose on straight legs start -> goal 1 -> goal 2 ... at ``speed`` m/s from ``t0`` s, as
    ``Simulation.base_pose2d`` gives it; ``t`` is set before each call."""

    def __init__(self, points: list[tuple[float, float]], speed: float = 0.45, t0: float = 1.0) -> None:
        self.points, self.speed, self.t0, self.t = np.asarray(points, dtype=np.float64), speed, t0, 0.0

    def base_pose2d(self) -> tuple[float, float, float]:
        left = max(0.0, self.t - self.t0) * self.speed
        for a, b in zip(self.points[:-1], self.points[1:], strict=True):
            d = b - a
            n = float(np.hypot(*d))
            yaw = math.atan2(d[1], d[0])
            if left <= n:
                x, y = a + d * (left / n)
                return float(x), float(y), yaw
            left -= n
        return float(self.points[-1][0]), float(self.points[-1][1]), yaw


@pytest.mark.parametrize(
    ("name", "speed"), [("refresh_rate", 0.45), ("refresh_rate", 0.3), ("obstacles_after_mapping", 0.45)]
)
def test_shipped_obstacles_stay_off_the_start_and_the_goals_over_many_seeds(name: str, speed: float) -> None:
    sc = load_scenario(name)
    keep = np.array([sc.start[:2], *(g[:2] for g in sc.goals)])
    early = 0
    for seed in range(200):
        robot = Drive([sc.start[:2], *(g[:2] for g in sc.goals)], speed)
        for p in placements(sc, seed):
            when, model = p.first_s, None
            while model is None:
                robot.t = when
                out = p(robot)
                assert out is not None, f"seed {seed}: no clear place in the window"
                when, model = (out, None) if isinstance(out, float) else (when, out)
            xy = np.asarray(model.pose[:2])
            assert np.hypot(*(keep - xy).T).min() >= p.clear, (seed, xy)
            assert math.dist(xy, robot.base_pose2d()[:2]) >= p.clear
            assert p.clear >= 0.15 + robot_reach(sc.robot) + 0.1 - 1e-9  # cylinder + wheels + safety distance
            assert p.lo - 1e-9 <= when <= p.t + 1e-9  # in the window, never later than drawn
            early += when < p.t - 1e-9
            # the drawn time is kept whenever its place was clear; an earlier one only when it was not
            robot.t = p.t
            at_t = np.asarray(p.where(robot.base_pose2d()).pose[:2])
            assert (when == p.t) == (np.hypot(*(keep - at_t).T).min() >= p.clear), seed
    # at full speed refresh_rate's cylinder 0.7 m ahead would land on the goal late in the window: placed earlier
    assert (early > 0) == (name == "refresh_rate" and speed == 0.45), early


def test_a_fixed_obstacle_on_a_goal_is_one_clear_error() -> None:
    sc = scenario_from_dict(
        {"goals": [[2.0, 0.0, 0.0]], "obstacles": [{"t": 5.0, "spec": "cylinder:x=2.3,y=0.0,radius=0.15,length=0.6"}]}
    )
    with pytest.raises(ExperimentError, match=r"obstacles\[0\] at \(2.3, 0\) is 0.30 m from goal 1: keep it at least"):
        check_fixed_obstacles(sc, robot_reach(sc.robot))
    sc.obstacles[0]["spec"] = "cylinder:x=1.0,y=1.0,radius=0.15,length=0.6"
    check_fixed_obstacles(sc, robot_reach(sc.robot))


def test_the_trial_whose_cylinder_landed_on_the_goal_now_drives_to_it() -> None:
    """refresh_rate trial 6: the cylinder, drawn at 7.89 s, fell on the goal and move_base refused it."""
    r = run_trial(load_scenario("refresh_rate"), 6)
    ((t, x, y),) = r["obstacles"]
    assert t < 7.88 and math.hypot(4.0 - x, y) >= 0.15 + robot_reach("mybot") + 0.1, r["obstacles"]
    assert r["success"] and r["collisions"] == 0 and r["min_clearance_m"] >= 0.05, r
