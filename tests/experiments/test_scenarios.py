"""Shipped sweep scenarios: clutter worlds in scenarios (BARN's score per trial, trial i = world i) and obstacles
placed in the robot's way at a drawn time (the slow-refresh collision of the paper)."""

from __future__ import annotations

import pytest

from navlab.experiments.clutter_run import clutter_for_trial
from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import load_scenario, scenario_from_dict
from navlab.experiments.trials import run_trial
from navlab.world.clutter import clutter_suite, generate_clutter


def test_a_suite_scenario_drives_world_i_in_trial_i() -> None:
    suite = clutter_suite(3, seed=2)
    for trial, k in ((0, 0), (2, 2), (4, 1)):  # trial i drives world i mod n
        w = clutter_for_trial("clutter_suite:n=3,seed=2", trial)
        assert w.name == suite[k].name and (w.cylinders == suite[k].cylinders).all()
    assert clutter_for_trial("room", 0) is None
    sc = load_scenario("clutter_suite")
    assert sc.trials == 50 and sc.map == "none" and sc.goals == [(10.0, 0.0, 0.0)]


def test_bad_clutter_worlds_are_refused_with_the_key() -> None:
    with pytest.raises(ExperimentError, match="did you mean 'smooth'"):
        scenario_from_dict({"world": "clutter:seed=1,fill=0.2,smoth=2"})
    with pytest.raises(ExperimentError, match="fill in"):
        scenario_from_dict({"world": "clutter:fill=1.5,smooth=2"})
    with pytest.raises(ExperimentError, match="sets its own start and is mapless"):
        scenario_from_dict({"world": "clutter_suite:n=5", "map": "true"})
    with pytest.raises(ExperimentError, match=r"obstacles\[0\]\.frame: expected world or robot"):
        scenario_from_dict({"goals": [[1, 0, 0]], "obstacles": [{"t": 1, "spec": "box:x=1", "frame": "map"}]})
    with pytest.raises(ExperimentError, match=r"obstacles\[0\]\.t: expected seconds or \[lo, hi\]"):
        scenario_from_dict({"goals": [[1, 0, 0]], "obstacles": [{"t": [5, 2], "spec": "box:x=1"}]})


def test_a_clutter_trial_is_scored_as_barn_scores_it() -> None:
    sc = scenario_from_dict({"world": "clutter:seed=4,fill=0.1,smooth=1", "controller": "mppi", "time_limit": 60})
    r = run_trial(sc, 0)
    assert r["success"] and r["collisions"] == 0 and r["world"] == "clutter_s4_f10_k1", r
    # T_opt by BARN's protocol: its generator's path (here from row 7 to row 22 of the field: 11.45 m) at 2 m/s;
    # navlab's stricter one: the shortest way, a straight 10 m
    barn = generate_clutter(4, fill=0.1, smooth=1).barn_t_opt()
    assert r["t_opt_s"] == pytest.approx(barn, abs=1e-4) and r["t_opt_s"] > 5.5
    assert r["t_opt_shortest_s"] == pytest.approx(5.0, abs=0.1)
    assert r["score_shortest"] == pytest.approx(
        r["t_opt_shortest_s"] / max(r["barn_time_s"], 2 * r["t_opt_shortest_s"]), abs=1e-3
    )
    # BARN's clock: from the first 0.1 m moved until first within 1 m (shorter than move_base's time to stop)
    assert 0.0 < r["barn_time_s"] < r["time_s"]
    assert 0.0 < r["score"] <= 0.5 and r["score"] == pytest.approx(
        r["t_opt_s"] / max(r["barn_time_s"], 2 * r["t_opt_s"]), abs=1e-3
    )
    assert r["score_to_stop"] == pytest.approx(r["t_opt_s"] / max(r["time_s"], 2 * r["t_opt_s"]), abs=1e-3)


def test_a_slow_local_costmap_hits_the_cylinder_and_the_collision_monitor_stops_the_robot() -> None:
    """refresh_rate.yaml: the same trial (cylinder 0.7 m ahead at the same drawn time) at 0.5 Hz without Nav2's
    collision monitor (the paper's move_base), at 0.5 Hz with it (mybot's default), and at 5 Hz."""
    sc = load_scenario("refresh_rate")
    assert sc.obstacles[0]["frame"] == "robot" and sc.overrides["planner_frequency"] == 0.0
    sc.time_limit = 15.0  # the cylinder appears within 8 s: enough to see who hits it
    sc.overrides["local_costmap.update_frequency"] = 0.5
    sc.collision_monitor = False
    slow = run_trial(sc, 1)
    assert slow["collisions"] >= 1 and slow["failure"] == "collision", slow
    sc.collision_monitor = None  # the robot's default: on for mybot, on the raw scan whatever the costmap's rate
    guarded = run_trial(sc, 1)
    assert guarded["collisions"] == 0 and guarded["min_clearance_m"] >= 0.05, guarded
    sc.overrides["local_costmap.update_frequency"] = 5.0
    fast = run_trial(sc, 1)
    assert fast["collisions"] == 0, fast
    with pytest.raises(ExperimentError, match="collision_monitor: expected true or false"):
        scenario_from_dict({"goals": [[1, 0, 0]], "collision_monitor": "yes"})
