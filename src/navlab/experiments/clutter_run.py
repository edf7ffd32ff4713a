"""Mapless navigation through BARN-style clutter worlds (Perille et al. 2020), scored as BARN scores.

Each world (``world.clutter``) is written as an SDF ``.world``, the robot starts 2 m before the field and
drives with ``move_base`` on a rolling global costmap to the goal 10 m ahead (given in ``odom``). A trial
succeeds when the robot ends within 1 m of the goal without a collision inside ``timeout`` s; its score is
``success x T_opt / clip(T, 2 T_opt, 8 T_opt)`` with ``T_opt`` = reference path length / 2 m/s. The judgement
is the simulator's truth; move_base's own verdict is beside it (``move_base_success``, ``false_success``: it
reported the goal reached while the robot truly ended more than 1 m away).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

from navlab.experiments.navigate_run import run_navigation
from navlab.experiments.session import rounded
from navlab.geometry import between2

SUCCESS_M = 1.0  # BARN: within 1 m of the goal
TIMEOUT_S = 100.0  # BARN's time limit
# At 1 m/s the shipped 4 m local window is too short a view: BARN runs use the ROS tutorial's 6 m x 6 m.
CLUTTER_PARAMS: dict[str, Any] = {"local_costmap.width": 6.0, "local_costmap.height": 6.0}


def run_clutter_world(
    world: Any,
    *,
    controller: str | None = "mppi",
    move_base_params: dict[str, Any] | None = None,
    seed: int = 0,
    timeout: float = TIMEOUT_S,
    workdir: str | Path | None = None,
    robot: str = "mybot",
) -> dict[str, Any]:
    """One BARN trial in ``world`` (a ``world.clutter.ClutterWorld``) with ``robot`` (and the move_base files the
    launch picks for it: navlab's params/<robot> where it ships some); returns its figures."""
    with tempfile.TemporaryDirectory(prefix="navlab-clutter-", dir=workdir) as tmp:
        path = world.write_world(Path(tmp) / f"{world.name}.world")
        gx, gy, gyaw = (float(v) for v in between2(world.start, world.goal))  # the goal in odom (= the start)
        sx, sy, syaw = (float(v) for v in world.start)
        params = {**CLUTTER_PARAMS, **(move_base_params or {})}
        r = run_navigation([(gx, gy, gyaw)], world=str(path), pose=(sx, sy, syaw), mapless=True, controller=controller,
                           move_base_params=params, seed=seed, goal_timeout=timeout, goal_tolerance=SUCCESS_M,
                           robot=robot)  # fmt: skip
    g = r.goals[0]
    return rounded({
        **barn_outcome(world, [g]), "reason": g["reason"], "time_s": g["time_s"], "collisions": g["collisions"],
        "path_m": g["path_m"], "min_clearance_m": g["min_clearance_m"], "wall_s": r.summary["wall_s"],
    })  # fmt: skip


def barn_outcome(world: Any, goals: list[dict[str, Any]]) -> dict[str, Any]:
    """BARN's judgement of a drive through ``world`` (its goals' figures from ``run_navigation``): success (the
    last goal ended within 1 m, no collision on the way), failure, score, T_opt, the world and its difficulty."""
    from navlab.world.clutter import barn_score

    g = goals[-1]
    collisions = sum(x["collisions"] for x in goals)
    time_s = sum(x["time_s"] for x in goals)
    success = collisions == 0 and g["final_error_m"] is not None and g["final_error_m"] <= SUCCESS_M
    missed = "missed" if g["outcome"] == "succeeded" else g["outcome"]  # move_base's tolerance is not BARN's
    failure = "" if success else ("collision" if collisions else missed)
    return {"world": world.name, "difficulty": world.difficulty, "success": success, "failure": failure,
            "move_base_success": collisions == 0 and all(x["move_base_outcome"] == "succeeded" for x in goals),
            "false_success": sum(x["move_base_outcome"] == "succeeded" and x["final_error_m"] > SUCCESS_M
                                 for x in goals),
            "t_opt_s": world.t_opt(), "score": barn_score(success, time_s, world.t_opt())}  # fmt: skip


def clutter_for_trial(world: str, index: int) -> Any:
    """The generated world of trial ``index`` for a scenario's ``world`` (``clutter:...`` the same world every
    trial; ``clutter_suite:n=N,seed=S`` world ``index mod N`` of ``clutter_suite(N, S)``), None for a file."""
    from navlab.experiments.scenario import clutter_world_spec
    from navlab.world.clutter import generate_clutter, suite_parameters

    spec = clutter_world_spec(world)
    if spec is None:
        return None
    if spec["kind"] == "clutter":
        return generate_clutter(spec.get("seed", 0), fill=spec["fill"], smooth=spec["smooth"])
    n, k = spec.get("n", 50), index % spec.get("n", 50)
    fill, smooth = suite_parameters(n)[k]
    return generate_clutter(spec.get("seed", 0) * 1000 + k, fill=fill, smooth=smooth)  # as clutter_suite(n, seed)


def run_clutter_suite(
    n: int = 50,
    *,
    seed: int = 0,
    controller: str | None = "mppi",
    move_base_params: dict[str, Any] | None = None,
    progress: bool = False,
    robot: str = "mybot",
) -> dict[str, Any]:
    """The ``clutter_suite(n, seed)`` worlds in turn with ``robot``; the per-world figures and their summary."""
    import sys

    from tqdm import tqdm

    from navlab.world.clutter import clutter_suite

    trials = []
    for world in tqdm(clutter_suite(n, seed=seed), desc="clutter", unit="world", disable=not progress, file=sys.stderr):
        trials.append(run_clutter_world(world, controller=controller, move_base_params=move_base_params, seed=seed,
                                        robot=robot))
    return {"summary": summarize(trials), "trials": trials}


def summarize(trials: list[dict[str, Any]]) -> dict[str, Any]:
    """BARN's figures over trials: success, collision and timeout rates, mean score."""
    n = len(trials)
    if n == 0:
        return {"worlds": 0}
    return rounded({
        "worlds": n,
        "success": sum(t["success"] for t in trials) / n,
        "collision": sum(t["failure"] == "collision" for t in trials) / n,
        "timeout": sum(t["failure"] == "timeout" for t in trials) / n,
        "aborted": sum(t["failure"] == "aborted" for t in trials) / n,
        "move_base_success": sum(t["move_base_success"] for t in trials) / n,
        "false_success": sum(t["false_success"] for t in trials),
        "score": sum(t["score"] for t in trials) / n,
        "mean_time_s": sum(t["time_s"] for t in trials if t["success"]) / max(1, sum(t["success"] for t in trials)),
    })  # fmt: skip
