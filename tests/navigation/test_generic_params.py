"""Issue 23: a robot other than the paper's, with no parameter files and no params:=, navigates with navlab's
generic ROS-default set sized from its own footprint, and the run says so (never another robot's files)."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from navlab.experiments.navigate_run import run_navigation

ROBOT = Path(__file__).parents[1] / "fixtures" / "ros_ws" / "my_description" / "urdf" / "my_robot.urdf.xacro"


def test_a_turtlebot3_sized_robot_without_parameters_navigates_with_the_generic_set(
    caplog: pytest.LogCaptureFixture,
) -> None:
    seen: dict[str, object] = {}

    def on_start(run: object) -> None:
        move_base = run.session.node("move_base")  # type: ignore[attr-defined]
        seen["footprint"] = move_base.local_costmap.layered.footprint.polygon.tolist()

    with caplog.at_level(logging.WARNING, logger="navlab.launch"):
        result = run_navigation([(1.5, 0.5, 0.0)], world="room", robot=str(ROBOT), goal_timeout=45, on_start=on_start)
    (note,) = [r.getMessage() for r in caplog.records if "generic ROS-default set" in r.getMessage()]
    assert "my_robot" in note and "params/generic" in note and "pass params:=DIR" in note
    xs = [p[0] for p in seen["footprint"]]  # type: ignore[union-attr]
    assert min(xs) == pytest.approx(-0.12, abs=0.005) and max(xs) == pytest.approx(0.06, abs=0.005)  # + padding
    assert result.goals[0]["outcome"] == "succeeded" and result.goals[0]["collisions"] == 0
