"""The obstacles-under-the-scan-plane experiment (scenarios tables_lidar / tables_depth / tables_sonar), first goal
only: the paper's robot with its lidar alone drives into the pallet it cannot see; with the depth camera and the
voxel layer, or with the sonar ring and range_sensor_layer, it drives around it and reaches the goal without
touching anything."""

from __future__ import annotations

import pytest

from navlab.experiments.navigate_run import run_navigation
from navlab.experiments.scenario import load_scenario


def _first_goal(name: str) -> dict:
    sc = load_scenario(name)
    r = run_navigation(sc.goals[:1], world=sc.world, robot=sc.robot, pose=sc.start, goal_timeout=25.0, seed=sc.seed)
    return r.goals[0]


@pytest.mark.parametrize(
    ("scenario", "reached", "collides"),
    [("tables_lidar", False, True), ("tables_depth", True, False), ("tables_sonar", True, False)],
)
def test_depth_camera_and_sonars_avoid_what_the_lidar_misses(scenario: str, reached: bool, collides: bool) -> None:
    goal = _first_goal(scenario)
    assert (goal["outcome"] == "succeeded") is reached, goal
    assert (goal["collisions"] > 0) is collides, goal


def test_the_sonar_robot_has_five_sonars_and_a_bumper() -> None:
    from navlab.description import load_robot

    robot = load_robot("mybot_sonar")
    sonars = robot.sensors.ranges
    assert len(sonars) == 5 and {s.radiation for s in sonars} == {"ultrasound"}
    assert all(s.topic.startswith("/sonar/") and s.fov == pytest.approx(0.26) for s in sonars)
    (bumper,) = robot.sensors.bumpers
    assert bumper.collision == "chassis_collision" and bumper.topic == "bumper"
