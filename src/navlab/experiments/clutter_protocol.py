"""The clutter benchmark's protocol (BARN's, as its challenge runs it) in one call: ``navlab bench clutter``.

Two disjoint generated suites of graded difficulty: the **test** set (``clutter_suite(50, seed=0)``, the one
results are reported on) and the **tuning** set (``clutter_suite(50, seed=1)``: tune parameters only on it).
The robot drives mapless at its real top speed (``max_speed`` m/s; the Jackal's 2 m/s, as the challenge
allows), 100 s per world, success = within 1 m of the goal by the simulator's truth with no contact. The
summary has success, collision, timeout, stuck and aborted rates, BARN's mean score, the mean time of the
successes, the closest clearance, the near misses and the successes under the score's cap (``below_cap``: each
one's time against 2 T_opt, the time that scores the cap); with ``out`` a picture of each failure (the costmap,
plans, the true path and the robot when it ended) goes to ``out/<world>.png``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

from navlab.experiments.clutter_run import CAP, run_clutter_world, summarize
from navlab.experiments.errors import ExperimentError

SETS = {"test": 0, "tuning": 1}  # clutter_suite seed of each set
JACKAL_MAX_SPEED = 2.0  # m/s: the Jackal's top speed, the challenge's limit
# the parameter that caps forward speed, per local planner (its ROS namespace and name)
SPEED_KEYS: dict[str, tuple[str, ...]] = {
    "nav2_mppi_controller::MPPIController": ("MPPIController.vx_max",),
    "base_local_planner/TrajectoryPlannerROS": ("TrajectoryPlannerROS.max_vel_x",),
    "dwa_local_planner/DWAPlannerROS": ("DWAPlannerROS.max_vel_x", "DWAPlannerROS.max_vel_trans"),
    "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController": (
        "RegulatedPurePursuitController.desired_linear_vel",
    ),
}


def speed_overrides(controller: str | None, max_speed: float | None) -> dict[str, Any]:
    """move_base overrides that set ``controller``'s top forward speed to ``max_speed`` m/s (None: its files')."""
    if max_speed is None or controller is None:
        return {}
    from navlab.plugins import resolve_name

    name = resolve_name("controller", controller)
    keys = SPEED_KEYS.get(name)
    if keys is None:
        raise ExperimentError(
            f"bench clutter: --max-speed needs a known local planner ({', '.join(SPEED_KEYS)}), got {controller!r}"
        )
    return dict.fromkeys(keys, float(max_speed))


def below_cap(trials: list[dict[str, Any]]) -> dict[str, dict[str, float]]:
    """The successes that scored under the cap: per world, its time on BARN's clock and the most it may take to
    score the cap (2 T_opt), s."""
    return {
        t["world"]: {"barn_time_s": t["barn_time_s"], "cap_time_s": round(2.0 * t["t_opt_s"], 2)}
        for t in trials
        if t["success"] and t["score"] < CAP
    }


def run_protocol(
    *,
    n: int = 50,
    which: str = "test",
    robot: str = "jackal",
    controller: str | None = "mppi",
    max_speed: float | None = JACKAL_MAX_SPEED,
    move_base_params: dict[str, Any] | None = None,
    out: str | Path | None = None,
    seed: int = 0,
    progress: bool = False,
    collision_monitor: bool = False,
) -> dict[str, Any]:
    """Run the ``which`` set's first ``n`` worlds (see the module docstring); ``{"summary", "trials"}``.
    ``collision_monitor``: Nav2's velocity smoother and collision monitor between move_base and the wheels."""
    from tqdm import tqdm

    from navlab.world import clutter_suite

    if which not in SETS:
        raise ExperimentError(f"bench clutter: --set must be one of {', '.join(SETS)}, got {which!r}")
    if not 1 <= n <= 50:
        raise ExperimentError(f"bench clutter: --worlds must be 1..50, got {n}")
    params = {**speed_overrides(controller, max_speed), **(move_base_params or {})}
    folder = Path(out) if out is not None else None
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    launch = {"collision_monitor": "true", "max_speed": str(max_speed or JACKAL_MAX_SPEED)} if collision_monitor else {}
    t0 = time.perf_counter()
    trials = []
    worlds = clutter_suite(50, seed=SETS[which])[:n]
    for world in tqdm(worlds, desc=f"clutter {which}", unit="world", disable=not progress, file=sys.stderr):
        trials.append(
            run_clutter_world(
                world,
                controller=controller,
                move_base_params=params,
                seed=seed,
                robot=robot,
                failure_picture=folder,
                launch_args=launch,
            )
        )
    s = summarize(trials)
    s.update(
        {
            "set": which,
            "robot": robot,
            "controller": controller or "(robot's files)",
            "max_speed_mps": max_speed,
            "collision_monitor": collision_monitor,
            "wall_s": round(time.perf_counter() - t0, 1),
            "failed_worlds": {t["world"]: t["failure"] for t in trials if not t["success"]},
            "below_cap": below_cap(trials),
        }
    )
    if folder is not None:
        s["pictures"] = [t["picture"] for t in trials if t.get("picture")]
    return {"summary": s, "trials": trials}
