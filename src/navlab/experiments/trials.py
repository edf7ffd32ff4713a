"""Trials of a scenario: each one a headless run with its own seed, its figures one JSON line in
``results.jsonl`` (written whole or not at all), so a run that is killed resumes where it stopped.

Per trial, judged by the simulator's truth: ``success`` (every goal truly reached — within the scenario's
``goal_tolerance_m`` at its end — with no collision), ``failure`` (collision, not_reached, timeout, aborted,
preempted — with move_base's reason), ``time_s``, ``path_m``, ``spl`` (success × shortest / max(path,
shortest), shortest from the true map), ``min_clearance_m`` (the robot's collision geometry to the world's),
``collisions``, localization error (mean, max) and the mean |jerk| of cmd_vel; beside them move_base's own
verdict, ``move_base_success``, and ``false_success``: goals move_base called reached that the truth did not.
The summary has the success rate with a 95 % Wilson interval (and move_base's rate and the false successes
beside it), medians and quartiles.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import Scenario
from navlab.experiments.scenario_obstacles import check_fixed_obstacles, placements, robot_reach
from navlab.experiments.session import rounded


def wilson_interval(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a success rate (0, 1 for no trials)."""
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def shortest_length(
    world: str, start: tuple[float, float, float], goals: list[tuple[float, float, float]], robot_radius: float = 0.2
) -> float | None:
    """Length (m) of the shortest collision-free route start -> goals on the world's true map (None if any
    leg has none): SPL's reference."""
    from navlab.drivers import exploration_costmap
    from navlab.navigation import ThetaStarPlanner
    from navlab.world import load_world, true_map

    costmap = exploration_costmap(true_map(load_world(world), start[:2]), robot_radius, comfort=0.01)
    planner = ThetaStarPlanner({"w_traversal_cost": 0.0})  # any-angle: the geometric shortest route
    total, here = 0.0, start
    for goal in goals:
        path = planner.make_plan(costmap, here, goal)
        if path is None:
            return None
        total += float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
        here = goal
    return total


def run_trial(sc: Scenario, index: int) -> dict[str, Any]:
    """Trial ``index`` of ``sc`` (seed = sc.seed + index); its figures (plus BARN's in a clutter world)."""
    from navlab.experiments.clutter_run import SUCCESS_M, barn_outcome, clutter_for_trial, clutter_params
    from navlab.experiments.mapping_run import run_mapping
    from navlab.experiments.navigate_run import run_navigation

    seed = sc.seed + index
    obstacles = placements(sc, seed)
    world = sc.resolve(sc.world) or sc.world
    clutter = clutter_for_trial(sc.world, index)
    start, overrides = sc.start, sc.overrides
    with tempfile.TemporaryDirectory(prefix="navlab-trial-") as tmp:
        map_yaml: str | Path | None = None
        if clutter is not None:
            world = str(clutter.write_world(Path(tmp) / f"{clutter.name}.world"))
            start, overrides = clutter.start, {**clutter_params(sc.robot), **sc.overrides}
        if sc.map == "map_first":
            mapped = run_mapping(
                world=sc.resolve(sc.map_world) or sc.map_world or world,
                robot=sc.robot,
                pose=start,
                out=Path(tmp) / "map",
                seed=seed,
                quiet=True,
            )
            map_yaml = mapped.map_yaml
        elif sc.map not in ("true", "none"):
            map_yaml = sc.resolve(sc.map)
        r = run_navigation(
            sc.goals,
            world=world,
            map_yaml=map_yaml,
            robot=sc.robot,
            pose=start,
            controller=sc.controller,
            params_dir=sc.resolve(sc.params),
            move_base_params=overrides,
            spawn=[(p.first_s, p) for p in obstacles],
            goal_timeout=sc.time_limit,
            seed=seed,
            mapless=sc.map == "none",
            goal_tolerance=SUCCESS_M if clutter is not None else sc.goal_tolerance_m,
            **sc.navigation_options(),
        )
    goals = r.goals
    failed = next((g for g in goals if g["outcome"] != "succeeded" or g["collisions"]), None)
    success = failed is None
    move_base_success = all(g["move_base_outcome"] == "succeeded" and not g["collisions"] for g in goals)
    failure = "" if failed is None else ("collision" if failed["collisions"] else failed["outcome"])
    path_m = sum(g["path_m"] for g in goals)
    shortest = shortest_length(world, sc.start, sc.goals) if sc.map != "none" else None
    barn: dict[str, Any] = {}
    if clutter is not None:
        barn = barn_outcome(clutter, goals)
        success, failure = barn.pop("success"), barn.pop("failure")
        shortest = clutter.reference_path_m if len(goals) == 1 else None
    spl = (float(success) * shortest / max(path_m, shortest)) if shortest else None
    return rounded(
        {
            "trial": index,
            "seed": seed,
            "success": success,
            "failure": failure,
            "reason": "" if failed is None else failed["reason"],
            "move_base_success": move_base_success,
            "false_success": sum(g["false_success"] for g in goals),
            "goals_succeeded": sum(g["outcome"] == "succeeded" for g in goals),
            "goals": len(goals),
            "goals_succeeded_move_base": sum(g["move_base_outcome"] == "succeeded" for g in goals),
            "time_s": sum(g["time_s"] for g in goals),
            "path_m": path_m,
            "shortest_m": shortest,
            "spl": spl,
            "min_clearance_m": min(g["min_clearance_m"] for g in goals),
            "collisions": sum(g["collisions"] for g in goals),
            "near_miss": any(g.get("near_miss", False) for g in goals),
            "time_under_safety_s": sum(g.get("time_under_safety_s", 0.0) for g in goals),
            "near_goal_m": min(g.get("near_goal_m", g["final_error_m"]) for g in goals[-1:]),
            "localization_error_mean_m": r.summary.get("localization_error_mean_m"),
            "localization_error_max_m": r.summary.get("localization_error_max_m"),
            "cmd_jerk_mean": r.summary.get("cmd_jerk_mean"),
            "sim_s": r.summary["sim_s"],
            "wall_s": r.summary["wall_s"],
            "tracking_error_m": _mean(goals, "tracking_error_m"),
            "final_error_m": _mean(goals, "final_error_m"),
            **barn,
            # where and when each obstacle appeared ([t s, x m, y m] in the world; null: left out)
            **({"obstacles": [p.placed and list(p.placed) for p in obstacles]} if obstacles else {}),
            "per_goal": goals,
            "world_file": str(world) if clutter is None else None,
            "start": list(start),
            "path_xy": _thin(r.path[:, 1:]),  # for the report's trajectory picture
        }
    )


def _thin(xy: np.ndarray, step: float = 0.05) -> list[list[float]]:
    """A path (N, 2; m) with points at least ``step`` m apart (the last kept), rounded to mm, as lists."""
    keep: list[np.ndarray] = []
    for p in xy:
        if not keep or np.hypot(*(p - keep[-1])) >= step:
            keep.append(p)
    if len(xy) and (not keep or keep[-1] is not xy[-1]):
        keep.append(xy[-1])
    return [[round(float(a), 3), round(float(b), 3)] for a, b in keep]


def _append_line(path: Path, record: dict[str, Any]) -> None:
    """One JSON line, written with a single ``write`` on an O_APPEND file and synced: whole or not at all."""
    data = (json.dumps(record) + "\n").encode()
    fd = os.open(path, os.O_RDWR | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        size = os.fstat(fd).st_size
        if size and os.pread(fd, 1, size - 1) != b"\n":  # a line torn by a crash: end it, keep it unparseable
            data = b"\n" + data
        os.write(fd, data)
        os.fsync(fd)
    finally:
        os.close(fd)


def read_results(path: Path) -> list[dict[str, Any]]:
    """The finished trials in ``results.jsonl`` (a torn last line from a crash is ignored)."""
    if not path.is_file():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return out


def summarize_trials(results: list[dict[str, Any]]) -> dict[str, Any]:
    """Success rate with a 95 % Wilson interval, collisions (``collisions``: contact episodes over all trials;
    ``trials_with_collision``: trials, as ``failures`` counts trials by kind), medians and quartiles."""
    n = len(results)
    ok = sum(bool(r["success"]) for r in results)
    lo, hi = wilson_interval(ok, n)

    def quartiles(key: str) -> list[float] | None:
        vals = [r[key] for r in results if r.get(key) is not None]
        return [float(v) for v in np.percentile(vals, [25, 50, 75])] if vals else None

    times = quartiles("time_s")
    failures: dict[str, int] = {}
    for r in results:
        if not r["success"]:
            failures[r["failure"]] = failures.get(r["failure"], 0) + 1
    return rounded(
        {
            "trials": n,
            "success_rate": ok / n if n else None,
            "success_ci95": [lo, hi],
            # move_base's own verdict beside the truth's (trials recorded by older navlab releases have neither key)
            "move_base_success_rate": _rate(results, "move_base_success"),
            "false_success": sum(int(r.get("false_success") or 0) for r in results),
            "collisions": sum(r["collisions"] for r in results),  # contact episodes (events), over all trials
            "trials_with_collision": sum(bool(r["collisions"]) for r in results),  # trials, as "failures" counts
            "failures": failures,
            "median_time_s": times[1] if times else None,
            "time_s_quartiles": times,
            "median_path_m": _median(results, "path_m"),
            "spl_mean": _mean(results, "spl"),
            "min_clearance_m": min((r["min_clearance_m"] for r in results), default=None),
            "near_misses": sum(bool(r.get("near_miss")) for r in results),  # trials under 5 cm without a contact
            "time_under_safety_s_mean": _mean(results, "time_under_safety_s"),
            "localization_error_mean_m": _mean(results, "localization_error_mean_m"),
            "cmd_jerk_mean": _mean(results, "cmd_jerk_mean"),
            "tracking_error_mean_m": _mean(results, "tracking_error_m"),
            "final_error_mean_m": _mean(results, "final_error_m"),
            **({"score_mean": _mean(results, "score")} if any("score" in r for r in results) else {}),  # BARN
            **(
                {"score_shortest_mean": _mean(results, "score_shortest")}  # navlab's stricter T_opt
                if any("score_shortest" in r for r in results)
                else {}
            ),
        }
    )


def _rate(results: list[dict[str, Any]], key: str) -> float | None:
    """Fraction of the results whose boolean ``key`` is true (None if none has it)."""
    vals = [bool(r[key]) for r in results if key in r]
    return sum(vals) / len(vals) if vals else None


def _median(results: list[dict[str, Any]], key: str) -> float | None:
    vals = [r[key] for r in results if r.get(key) is not None]
    return float(np.median(vals)) if vals else None


def _mean(results: list[dict[str, Any]], key: str) -> float | None:
    vals = [r[key] for r in results if r.get(key) is not None]
    return float(np.mean(vals)) if vals else None


def _trial_in_worker(args: tuple[Scenario, int]) -> dict[str, Any]:
    return run_trial(*args)


def run_experiment(
    sc: Scenario,
    out: str | Path,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = 1,
    backend: str = "local",
    progress: bool = False,
) -> dict[str, Any]:
    """Run the scenario's trials not yet in ``out``/results.jsonl (in ``workers`` processes, or on Ray with
    ``backend="ray"``), append each as it finishes, and return (and write ``summary.json``) the summary over
    all of them."""
    job = (with_run_options(sc, trials, seed), Path(out))
    return run_experiments([job], workers=workers, backend=backend, progress=progress, desc=sc.name)[0]


def with_run_options(sc: Scenario, trials: int | None, seed: int | None) -> Scenario:
    """``sc`` with its trial count and seed set, where given (in place; returned for chaining)."""
    if trials is not None:
        sc.trials = trials
    if seed is not None:
        sc.seed = seed
    return sc


def run_experiments(
    jobs: list[tuple[Scenario, Path]],
    *,
    workers: int | None = 1,
    backend: str = "local",
    progress: bool = False,
    desc: str = "trials",
) -> list[dict[str, Any]]:
    """Several experiments (scenario, results folder) at once: every unfinished trial of every one goes to the
    same workers (see ``backends.run_tasks``); the driver appends each trial's line to its folder's
    results.jsonl as it finishes, then writes each ``summary.json``. Returns the summaries in order."""
    from tqdm import tqdm

    from navlab.experiments.backends import run_tasks
    from navlab.io import write_text_atomic

    done: list[dict[int, dict[str, Any]]] = []
    tasks: list[tuple[Scenario, int]] = []
    owner: list[int] = []
    for j, (sc, folder) in enumerate(jobs):
        if sc.trials < 1:
            raise ExperimentError(f"trials: expected an integer >= 1, got {sc.trials}")
        if sc.obstacles:
            check_fixed_obstacles(sc, robot_reach(sc.robot))
        folder.mkdir(parents=True, exist_ok=True)
        finished = {
            int(r["trial"]): r
            for r in read_results(folder / "results.jsonl")
            if r.get("seed") == sc.seed + int(r["trial"])
        }
        done.append(finished)
        for k in range(sc.trials):
            if k not in finished:
                tasks.append((sc, k))
                owner.append(j)
    total = sum(sc.trials for sc, _ in jobs)
    bar = tqdm(total=total, initial=total - len(tasks), desc=desc, unit="trial", file=sys.stderr, disable=not progress)
    try:
        # closed here, also on Ctrl-C between two results: the workers stop now, not at the interpreter's exit
        with contextlib.closing(run_tasks(_trial_in_worker, tasks, backend=backend, workers=workers)) as outcomes:
            for i, rec in outcomes:
                j = owner[i]
                done[j][int(rec["trial"])] = rec
                _append_line(jobs[j][1] / "results.jsonl", rec)
                bar.update(1)
    finally:
        bar.close()
    summaries = []
    for (sc, folder), finished in zip(jobs, done, strict=True):
        results = [finished[k] for k in sorted(finished) if k < sc.trials]
        summary = {"scenario": sc.name, **summarize_trials(results)}
        write_text_atomic(folder / "summary.json", json.dumps(summary, indent=1) + "\n")
        summaries.append(summary)
    return summaries
