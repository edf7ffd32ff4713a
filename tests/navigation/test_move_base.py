"""move_base in the simulator (seeded): goals reached, obstacles not on the map avoided, bad goals refused.

Each test runs the shipped navigation launch (MuJoCo sim + map_server + amcl + move_base with the paper's
mybot parameter files) and judges it from ground truth and the simulator's contacts (/collisions).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from navlab.cli import main
from navlab.errors import NavlabError
from navlab.experiments.navigate_run import run_navigation
from navlab.mapping import save_map
from navlab.sim import primitive_model
from navlab.world import load_world, true_map

# Goals spread over room.world's free space (map frame = world frame), visited in this order.
ROOM_GOALS = [
    (3.5, 3.0, 1.57),
    (0.5, 2.5, 3.14),
    (-3.5, 3.0, 3.14),
    (-3.5, 0.0, -1.57),
    (-4.0, -3.0, -1.57),
    (-1.0, -2.5, 0.0),
    (2.0, -3.2, 0.0),
    (4.2, -1.0, 1.57),
    (3.0, 0.5, 3.14),
    (0.0, 0.0, 0.0),
]
REACHED_M = 0.25  # xy_goal_tolerance 0.15 m plus AMCL's error: the true pose's distance to the goal


@pytest.fixture(scope="module")
def room_map(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The map of the empty room (no obstacles), as the paper's mapping step would have saved it."""
    path = tmp_path_factory.mktemp("map") / "room.yaml"
    save_map(true_map(load_world("room"), (0.0, 0.0)), path)
    return path


def _ok(goal: dict) -> bool:
    return goal["outcome"] == "succeeded" and goal["collisions"] == 0 and goal["final_error_m"] <= REACHED_M


def test_ten_goals_over_the_room_are_all_reached_without_collision() -> None:
    r = run_navigation(ROOM_GOALS, world="room", goal_timeout=60)
    assert all(_ok(g) for g in r.goals), r.goals
    assert r.summary["collisions"] == 0
    assert all(g["min_clearance_m"] > 0.0 for g in r.goals), r.goals


def test_obstacles_added_after_mapping_are_seen_and_driven_around(room_map: Path) -> None:
    """The paper's experiment: the map has no obstacles, the world has them (room_obstacles)."""
    r = run_navigation(
        [(4.3, 1.0, 0.0), (-3.5, -0.5, 3.14)], world="room_obstacles", map_yaml=room_map, goal_timeout=60
    )
    assert all(_ok(g) for g in r.goals), r.goals
    # the straight line to the first goal crosses the cylinder at (3.6, 0.8): the drive had to detour
    assert r.goals[0]["path_m"] > math.hypot(4.3, 1.0) + 0.2


def test_a_cylinder_spawned_on_the_planned_path_is_avoided() -> None:
    cylinder = primitive_model("cylinder", "late", (0.2, 0.6), x=2.0, y=0.0)
    r = run_navigation([(4.0, 0.0, 0.0)], world="room", spawn=[(3.0, cylinder)], goal_timeout=60)
    assert _ok(r.goals[0]), r.goals


def test_a_slow_local_costmap_lets_the_robot_hit_what_appears_in_front_of_it() -> None:
    """The paper's finding: with the local costmap refreshed slowly, an obstacle that appears ahead is not
    seen in time (planner_frequency 0: no global replanning to save it). The paper's move_base drives the wheels
    itself: no collision monitor (mybot's default has one: tests/experiments/test_scenarios.py)."""
    paper = {"collision_monitor": "false"}

    def ahead(sim: object) -> object:
        x, y, yaw = sim.base_pose2d()  # type: ignore[attr-defined]
        return primitive_model("cylinder", "sudden", (0.15, 0.6), x=x + 0.7 * math.cos(yaw), y=y + 0.7 * math.sin(yaw))

    # at 7 s the robot drives forward (a 0.2 Hz local costmap is first filled at 5 s, next at 10 s); at 4 s it
    # was still backing off its empty costmap and saw the cylinder in that first update
    slow = run_navigation(
        [(4.0, 0.0, 0.0)],
        world="room",
        spawn=[(7.0, ahead)],
        goal_timeout=60,
        move_base_params={"local_costmap.update_frequency": 0.2, "planner_frequency": 0.0},
        launch_args=paper,
    )
    assert slow.goals[0]["collisions"] >= 1, slow.goals
    fast = run_navigation(
        [(4.0, 0.0, 0.0)],
        world="room",
        spawn=[(7.0, ahead)],
        goal_timeout=60,
        move_base_params={"local_costmap.update_frequency": 5.0, "planner_frequency": 0.0},
        launch_args=paper,
    )
    assert fast.goals[0]["collisions"] == 0, fast.goals


def test_goals_outside_the_map_or_in_an_obstacle_are_aborted_with_a_reason() -> None:
    r = run_navigation([(30.0, 0.0, 0.0), (-2.75, 2.4, 0.0), (1.0, 1.0, 0.0)], world="room", goal_timeout=60)
    outside, inside, fine = r.goals
    assert outside["outcome"] == "aborted" and "outside the map" in outside["reason"]
    assert outside["time_s"] < 1.0  # refused at once
    assert inside["outcome"] == "aborted" and "in an obstacle" in inside["reason"]
    assert inside["time_s"] < 2.0 and inside["path_m"] < 0.1  # the robot did not move
    assert _ok(fine), r.goals  # and move_base takes the next goal as usual


def test_a_walled_off_goal_runs_the_recoveries_then_aborts(tmp_path: Path) -> None:
    grid = true_map(load_world("room"), (0.0, 0.0))
    ring = grid.world_to_cell(np.array([[1.4, -0.6], [2.6, 0.6]]))  # a closed square wall around (2, 0)
    (i0, j0), (i1, j1) = ring
    grid.data[j0 : j1 + 1, [i0, i1]] = 100
    grid.data[[j0, j1], i0 : i1 + 1] = 100
    save_map(grid, tmp_path / "walled.yaml")
    r = run_navigation([(2.0, 0.0, 0.0)], world="room", map_yaml=tmp_path / "walled.yaml", goal_timeout=120)
    g = r.goals[0]
    assert g["outcome"] == "aborted" and "Failed to find a valid plan" in g["reason"], g
    assert g["collisions"] == 0


def test_a_boxed_in_robot_tries_every_recovery_then_aborts() -> None:
    from navlab.experiments.session import start_run

    run = start_run("navigation", world="room", map=str(_room_true_map()))
    for k, (x, y, size) in enumerate(
        [
            (0.6, 0.0, (0.1, 1.4, 0.5)),
            (-0.6, 0.0, (0.1, 1.4, 0.5)),
            (0.0, 0.6, (1.4, 0.1, 0.5)),
            (0.0, -0.6, (1.4, 0.1, 0.5)),
        ]
    ):
        run.gazebo.spawn(primitive_model("box", f"box{k}", size, x=x, y=y))
    run.run(1.0)
    mb = run.node("move_base")
    handle = mb.send_goal(3.0, 0.0, 0.0)  # type: ignore[attr-defined]
    run.run(120.0, until=handle.done)
    assert handle.state == "ABORTED" and "Even after executing recovery behaviors" in handle.reason
    assert mb.recovery_log == [
        "conservative_reset",
        "rotate_recovery",
        "aggressive_reset",  # type: ignore[attr-defined]
        "rotate_recovery",
        "back_up",
    ]
    bumper = next(p for p in run.gazebo.plugins if type(p).__name__ == "CollisionPlugin")  # type: ignore[attr-defined]
    assert bumper.collisions == 0


def _room_true_map() -> Path:
    import tempfile

    path = Path(tempfile.mkdtemp(prefix="navlab-test-")) / "room.yaml"
    save_map(true_map(load_world("room"), (0.0, 0.0)), path)
    return path


def test_navigate_cli_prints_json_and_pictures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["navigate", "--world", "room", "--goal", "1.5", "0.5", "0.0", "--out", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    goal = out["goals"][0]
    assert set(goal) >= {"outcome", "reason", "time_s", "path_m", "min_clearance_m", "collisions"}
    assert goal["outcome"] == "succeeded" and {"sim_s", "wall_s", "rtf"} <= set(out)
    assert Path(out["pictures"][0]).stat().st_size > 20_000


def test_bad_parameters_get_one_line_errors(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(NavlabError, match="did you mean 'navfn/NavfnROS'"):
        run_navigation([(1.0, 0.0, 0.0)], world="room", move_base_params={"base_global_planner": "navfn/NavFnROS"})
    assert (
        main(["navigate", "--world", "room", "--goal", "1", "0", "0", "--set", "local_costmap.inflation_radius=-0.5"])
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert "inflation_radius" in err and len(err.splitlines()) == 1


def test_mapless_navigation_through_a_generated_clutter_world() -> None:
    """No map, no amcl: move_base's global costmap rolls in odom; MPPI drives a BARN-style field."""
    from navlab.experiments.clutter_run import run_clutter_world
    from navlab.world.clutter import generate_clutter

    world = generate_clutter(7, fill=0.3, smooth=2)
    r = run_clutter_world(world, controller="mppi")
    assert r["success"] and r["collisions"] == 0, r
    assert r["time_s"] < 8 * world.t_opt() and r["score"] > 0.0


def test_a_robot_with_a_polygon_footprint_navigates_with_its_own_parameter_files() -> None:
    """The Jackal-sized robot: box footprint, another base frame (base_link) and scan topic (front/scan)."""
    from navlab import resources

    r = run_navigation(
        [(3.0, 0.5, 0.0), (-3.0, -0.5, 3.14)],
        world="room",
        robot="jackal",
        params_dir=resources.root() / "params" / "jackal",
        controller="mppi",
        goal_timeout=60,
    )
    assert all(_ok(g) for g in r.goals), r.goals


def test_move_base_publishes_costmaps_plans_and_status_as_ros_does() -> None:
    from navlab import msgs
    from navlab.core import Node
    from navlab.experiments.session import start_run

    run = start_run("navigation", world="room_obstacles", map=str(_room_true_map()))
    got: dict[str, list] = {}
    listener = run.add(Node, name="listener")
    for topic, kind in [
        ("/move_base/global_costmap/costmap", msgs.OccupancyGrid),
        ("/move_base/local_costmap/costmap", msgs.OccupancyGrid),
        ("/move_base/local_costmap/footprint", msgs.PolygonStamped),
        ("/move_base/NavfnROS/plan", msgs.Path),
        ("/move_base/TrajectoryPlannerROS/local_plan", msgs.Path),
        ("/move_base/status", msgs.GoalStatusArray),
        ("/cmd_vel", msgs.Twist),
    ]:
        listener.create_subscription(kind, topic, lambda m, t=topic: got.setdefault(t, []).append(m))
    run.run(1.0)
    goal = msgs.pose_stamped(run.executor.now_ns, "map", 4.3, 1.0, 0.0)
    listener.create_publisher(msgs.PoseStamped, "/move_base_simple/goal").publish(goal)  # rviz's 2D Nav Goal
    run.run(4.0)
    assert all(
        got.get(t)
        for t in [
            "/move_base/global_costmap/costmap",
            "/move_base/local_costmap/costmap",
            "/move_base/local_costmap/footprint",
            "/move_base/NavfnROS/plan",
            "/move_base/TrajectoryPlannerROS/local_plan",
            "/cmd_vel",
        ]
    ), sorted(got)
    local = got["/move_base/local_costmap/costmap"][-1]
    assert local.header.frame_id == "odom" and local.info.width == 80  # a 4 m rolling window at 5 cm
    assert set(np.unique(local.data)) <= set(range(-1, 101))  # costmap_2d's translation to 0..100, -1
    plan = got["/move_base/NavfnROS/plan"][-1]
    assert plan.header.frame_id == "map" and len(plan.poses) > 10
    assert got["/move_base/status"][-1].status_list[-1].status == msgs.GoalStatus.STATUS_EXECUTING


def test_a_key_ros_ignores_warns_naming_the_file_and_a_typo_still_fails(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """ROS reads what it knows and ignores the rest of a namespace: ``meter_scoring`` (TrajectoryPlannerROS's)
    in costmap_common_params.yaml loads with a warning naming key and file; a misspelt known key is refused."""
    import shutil

    from navlab import resources
    from navlab.experiments.session import start_run

    params = tmp_path / "params"
    shutil.copytree(resources.root() / "params" / "mybot", params)
    common = params / "costmap_common_params.yaml"
    common.write_text(common.read_text() + "meter_scoring: true\n")
    with caplog.at_level("WARNING"):
        run = start_run("navigation", world="room", map=str(_room_true_map()), params=str(params))
    warned = [r.getMessage() for r in caplog.records if "meter_scoring" in r.getMessage()]
    assert warned and all("costmap_common_params.yaml" in m and "ignored" in m for m in warned), warned
    assert run.node("move_base") is not None
    common.write_text(common.read_text() + "inflation_raduis: 0.3\n")
    with pytest.raises(NavlabError, match=r"did you mean 'inflation_radius'.*costmap_common_params\.yaml"):
        start_run("navigation", world="room", map=str(_room_true_map()), params=str(params))


def test_costmaps_are_not_published_until_someone_subscribes_then_are() -> None:
    """costmap_2d's publisher does no work without subscribers; a late subscriber gets the costmap at the next
    publish tick (publish_frequency 1 Hz global, 2 Hz local), and move_base's status likewise."""
    from navlab import msgs
    from navlab.core import Node
    from navlab.experiments.session import start_run

    run = start_run("navigation", world="room", map=str(_room_true_map()))
    topics = ["/move_base/global_costmap/costmap", "/move_base/local_costmap/costmap"]
    run.run(2.5)
    assert all(not run.executor.topic(t, msgs.OccupancyGrid).latched for t in topics)
    got: dict[str, list] = {}
    listener = run.add(Node, name="late_listener")
    for topic in topics:
        listener.create_subscription(msgs.OccupancyGrid, topic, lambda m, t=topic: got.setdefault(t, []).append(m))
    listener.create_subscription(msgs.GoalStatusArray, "/move_base/status", got.setdefault("status", []).append)
    run.run(1.0)
    assert [len(got.get(t, [])) for t in topics] == [1, 2]
    assert len(got["status"]) == 5  # move_base's status timer (5 Hz) parked too, and woke
    g = got[topics[0]][-1]
    assert g.header.frame_id == "map" and min(g.data) >= -1 and max(g.data) == 100
