"""The clutter benchmark's protocol: disjoint test and tuning sets, the speed limit per controller, and a world
that defeated the Jackal's MPPI before (its wheel odometry drifted 3.1 m: a false success) now reached."""

from __future__ import annotations

import pytest

from navlab.experiments.clutter_protocol import SETS, below_cap, speed_overrides
from navlab.experiments.clutter_run import OWN_FILES_PARAMS, barn_clock, clutter_params, run_clutter_world
from navlab.experiments.errors import ExperimentError
from navlab.world.clutter import clutter_suite, generate_clutter, suite_parameters


def test_tuning_and_test_sets_are_disjoint_and_graded() -> None:
    test, tuning = (clutter_suite(5, seed=SETS[k]) for k in ("test", "tuning"))
    assert not {w.name for w in test} & {w.name for w in tuning}
    assert [w.fill for w in test] == [w.fill for w in tuning] == sorted(w.fill for w in test)


def test_speed_limit_goes_to_the_controllers_own_parameter() -> None:
    assert speed_overrides("mppi", 2.0) == {"MPPIController.vx_max": 2.0}
    assert speed_overrides("rpp", 1.5) == {"RegulatedPurePursuitController.desired_linear_vel": 1.5}
    assert speed_overrides("dwa", 2.0) == {"DWAPlannerROS.max_vel_x": 2.0, "DWAPlannerROS.max_vel_trans": 2.0}
    assert speed_overrides("mppi", None) == {}
    with pytest.raises(ExperimentError, match="max-speed"):
        speed_overrides("my_pkg/Unknown", 2.0)


def test_clutter_settings_per_robot() -> None:
    """The Jackal's local window holds its MPPI horizon at 2 m/s (2 s, 4 m); mybot keeps 6 m; any other robot drives
    with its own files."""
    assert clutter_params("jackal")["local_costmap.width"] == clutter_params("jackal")["local_costmap.height"] == 8.0
    assert clutter_params("mybot")["local_costmap.width"] == 6.0
    key = "global_costmap.obstacle_layer.occluded_unknown_cost"  # shadows priced for the Jackal only (session 9)
    assert clutter_params("jackal")[key] == 20 and key not in clutter_params("mybot")
    assert clutter_params("jackal")["recovery_behaviors"] == clutter_params("mybot")["recovery_behaviors"]
    assert clutter_params("jackal_skid") == OWN_FILES_PARAMS


def test_a_world_that_defeated_the_jackals_mppi_is_now_reached() -> None:
    """Test world 21: in the suite before BARN's generator, move_base reported success 3.14 m from the true goal
    (odometry alone); with the IMU fused by the EKF (mapless default for a robot with an IMU) the robot truly
    arrives, with no contact (in the BARN-generated world 21 too)."""
    fill, smooth = suite_parameters(50)[21]
    world = generate_clutter(21, fill=fill, smooth=smooth)
    r = run_clutter_world(world, controller="mppi", robot="jackal")
    assert r["success"] and r["false_success"] == 0 and r["collisions"] == 0, r
    assert r["final_error_m"] <= 1.0 and r["near_goal_m"] <= r["final_error_m"]
    assert not r["near_miss"] and r["min_clearance_m"] >= 0.05
    # BARN's clock (first 0.1 m moved -> first within 1 m) is shorter than move_base's (sent -> stopped at it)
    assert 0 < r["barn_time_s"] < r["time_s"] and r["score"] >= r["score_to_stop"]


def test_the_tuning_world_where_mppi_stood_still_is_now_reached() -> None:
    """Tuning world 36 at seed 1: the Jackal backs out of a pocket into a gap facing away from its new plan, where
    MPPI's left and right turns averaged to standing still; it stood 57 s until move_base aborted. With the rotation
    shim (the Jackal's files) it turns in place toward the plan and reaches the goal without a contact."""
    world = clutter_suite(50, seed=SETS["tuning"])[36]
    r = run_clutter_world(
        world, controller="mppi", robot="jackal", seed=1, move_base_params=speed_overrides("mppi", 2.0)
    )
    assert r["success"] and r["collisions"] == 0 and r["final_error_m"] <= 1.0, r
    assert not r["near_miss"]


def test_barn_clock_runs_from_the_first_move_until_first_within_a_metre() -> None:
    one = {"time_s": 14.0, "moved_s": 0.6, "within_tolerance_s": 12.1}
    assert barn_clock([one]) == pytest.approx(11.5)
    first, second = {**one, "within_tolerance_s": 13.0}, {"time_s": 9.0, "moved_s": 0.2, "within_tolerance_s": 7.0}
    assert barn_clock([first, second]) == pytest.approx(14.0 - 0.6 + 7.0)  # a tour: the first goal's whole time
    assert barn_clock([{**one, "within_tolerance_s": None}]) is None  # never came within 1 m


def test_the_summary_names_each_success_under_the_cap_with_its_time() -> None:
    """A success slower than 2 T_opt is listed with its time and the time that scores the cap; a success at the cap
    and a failure are not."""
    slow = {"world": "w36", "success": True, "score": 0.21, "barn_time_s": 27.2, "t_opt_s": 5.705}
    fast = {"world": "w1", "success": True, "score": 0.5, "barn_time_s": 6.0, "t_opt_s": 5.3}
    failed = {"world": "w2", "success": False, "score": 0.0, "barn_time_s": None, "t_opt_s": 5.0}
    assert below_cap([slow, fast, failed]) == {"w36": {"barn_time_s": 27.2, "cap_time_s": 11.41}}
