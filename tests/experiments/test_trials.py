"""Scenarios and trials: crash-safe results, resume, seeds, summaries, bad keys."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import load_scenario, scenario_from_dict
from navlab.experiments.trials import read_results, run_experiment, wilson_interval

SMALL = {"name": "small", "world": "room", "goals": [[1.5, 0.5, 0.0]], "trials": 3, "seed": 5, "time_limit": 40}
METRICS = {
    "trial",
    "seed",
    "success",
    "failure",
    "reason",
    "time_s",
    "path_m",
    "shortest_m",
    "spl",
    "min_clearance_m",
    "collisions",
    "localization_error_mean_m",
    "localization_error_max_m",
    "cmd_jerk_mean",
    "per_goal",
}


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines()


def test_three_trials_write_three_lines_with_every_metric(tmp_path: Path) -> None:
    summary = run_experiment(scenario_from_dict(SMALL), tmp_path)
    rows = read_results(tmp_path / "results.jsonl")
    assert [r["trial"] for r in rows] == [0, 1, 2] and [r["seed"] for r in rows] == [5, 6, 7]
    for r in rows:
        assert set(r) >= METRICS, METRICS - set(r)
        assert r["success"] and r["collisions"] == 0 and 0.9 <= r["spl"] <= 1.0
        assert r["shortest_m"] == pytest.approx(1.581, abs=0.01)  # the straight line: nothing in the way
        assert r["localization_error_mean_m"] < 0.1
    assert summary["trials"] == 3 and summary["success_rate"] == 1.0
    assert summary["success_ci95"][0] == pytest.approx(0.4385, abs=1e-3) and summary["success_ci95"][1] == 1.0
    assert json.loads((tmp_path / "summary.json").read_text()) == summary


def test_a_killed_run_resumes_without_redoing_finished_trials(tmp_path: Path) -> None:
    run_experiment(scenario_from_dict(SMALL), tmp_path, trials=1)  # as if killed after the first trial
    first = _lines(tmp_path / "results.jsonl")
    with (tmp_path / "results.jsonl").open("a") as f:
        f.write('{"trial": 1, "seed": 6, "succ')  # a line torn by the kill
    run_experiment(scenario_from_dict(SMALL), tmp_path)
    rows = read_results(tmp_path / "results.jsonl")
    assert sorted(r["trial"] for r in rows) == [0, 1, 2]
    assert _lines(tmp_path / "results.jsonl")[0] == first[0]  # trial 0 was not run again


def test_the_same_seed_gives_the_same_metrics(tmp_path: Path) -> None:
    a = run_experiment(scenario_from_dict({**SMALL, "trials": 1}), tmp_path / "a")
    b = run_experiment(scenario_from_dict({**SMALL, "trials": 1}), tmp_path / "b")
    ra, rb = read_results(tmp_path / "a" / "results.jsonl")[0], read_results(tmp_path / "b" / "results.jsonl")[0]
    ra.pop("wall_s"), rb.pop("wall_s")
    assert ra == rb and a["median_time_s"] == b["median_time_s"]


def test_bad_scenarios_are_refused_with_the_key(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ExperimentError, match="unknown key 'goal'; did you mean 'goals'"):
        scenario_from_dict({"goal": [[1, 0, 0]]})
    with pytest.raises(ExperimentError, match=r"goals\[0\]: expected \[x, y, yaw\]"):
        scenario_from_dict({"goals": [[1, 0]]})
    with pytest.raises(ExperimentError, match="trials: expected an integer >= 1"):
        scenario_from_dict({"goals": [[1, 0, 0]], "trials": 0})
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\ngoals: [[1, 0, 0]]\ntime_limt: 5\n")
    assert main(["experiment", "run", str(bad), "--quiet"]) == 2
    assert "did you mean 'time_limit'" in capsys.readouterr().err


def test_shipped_scenarios_load_and_wilson_interval() -> None:
    assert load_scenario("empty_room").trials == 20
    sc = load_scenario("obstacles_after_mapping")
    assert sc.map == "map_first" and sc.map_world == "room" and len(sc.obstacles) == 1
    lo, hi = wilson_interval(19, 20)
    assert lo == pytest.approx(0.7639, abs=1e-3) and hi == pytest.approx(0.9911, abs=1e-3)


def test_a_two_by_two_sweep_writes_its_table_and_plots(tmp_path: Path) -> None:
    from navlab.experiments.sweep import parse_params, run_sweep

    params = parse_params(["local_costmap.update_frequency=1,5", "controller=trajectory,mppi"])
    rows = run_sweep(scenario_from_dict({**SMALL, "trials": 1}), params, tmp_path)
    assert [(r["local_costmap.update_frequency"], r["controller"]) for r in rows] == [
        (1, "trajectory"),
        (1, "mppi"),
        (5, "trajectory"),
        (5, "mppi"),
    ]
    assert all(r["success_rate"] == 1.0 and r["collisions"] == 0 for r in rows), rows
    table = (tmp_path / "sweep.md").read_text().splitlines()
    assert len(table) == 2 + 4 and "local_costmap.update_frequency" in table[0]
    assert len((tmp_path / "sweep.csv").read_text().splitlines()) == 5
    for name in ("local_costmap.update_frequency", "controller"):
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    with pytest.raises(ExperimentError, match="expected name=value1,value2"):
        parse_params(["max_vel_x"])
