"""The experiments' benchmarks, each a whole stack run as ``navlab`` runs it: ``navlab bench mapping`` (SLAM
exploring room), ``nav`` (move_base to four goals), ``clutter`` (mapless navigation over generated clutter
worlds) and ``odom`` (odometry drift per robot, route and EKF setting)."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from navlab.experiments import JACKAL_MAX_SPEED, ROBOTS, ROUTES, run_drift, run_mapping, run_navigation, run_protocol

WARMUP_S = 5.0  # simulated s of `bench mapping`'s untimed warm-up run


def run_mapping_bench(args: Any) -> dict[str, Any]:
    """``navlab bench mapping``: the whole mapping stack (sim + lidar + slam_gmapping + exploration)
    exploring room.world until done; real-time factor of the run loop (sim s / wall s), after an untimed
    ``WARMUP_S`` warm-up run."""
    with tempfile.TemporaryDirectory() as tmp:
        # a short untimed run first: Numba's kernels load (or compile, on a cold cache) outside the figure
        run_mapping(world="room", out=Path(tmp) / "warmup", driver="explore", duration=WARMUP_S, quiet=True)
        r = run_mapping(
            world="room", out=tmp, driver="explore", duration=300, seed=getattr(args, "seed", 0), quiet=True
        )
    keys = ("sim_s", "wall_s", "rtf", "finished", "scans_processed", "coverage", "precision", "recall")
    out = {k: r.scores[k] for k in keys}
    # this process's CPU time in the run loop: on a busy machine it shows what one free core would take
    out["cpu_s"] = round(r.cpu_s, 2)
    out["rtf_cpu"] = round(r.sim_s / r.cpu_s, 1) if r.cpu_s > 0 else None
    return out


NAV_GOALS = ((4.3, 1.0, 0.0), (-3.5, -0.5, 3.14), (1.5, -2.5, 0.0), (0.0, 0.0, 0.0))  # room_obstacles, map frame
NAV_WARMUP_GOAL = (0.6, 0.0, 3.14)  # 0.6 m ahead of the start, turned round: reached in a few seconds


def run_nav(args: Any) -> dict[str, Any]:
    """``navlab bench nav``: the whole navigation stack (sim + lidar + amcl + costmaps + planner + controller)
    driving across room_obstacles.world to four goals; real-time factor of the run loop by wall time (``rtf``) and
    by this process's CPU time (``rtf_cpu``: what one free core gives, as ``bench sim``'s ``rtf``)."""
    goals = list(NAV_GOALS)
    # warm-up (Numba caches): a goal it reaches, so the stop-and-rotate path is loaded before the timed run too
    run_navigation([NAV_WARMUP_GOAL], world="room_obstacles", goal_timeout=10, seed=getattr(args, "seed", 0))
    r = run_navigation(goals, world="room_obstacles", goal_timeout=90, seed=getattr(args, "seed", 0))
    s = r.summary
    return {
        **{k: s[k] for k in ("sim_s", "wall_s", "rtf", "cpu_s")},
        "rtf_cpu": round(s["sim_s"] / s["cpu_s"], 1) if s["cpu_s"] > 0 else None,
        "goals_succeeded": s["goals_succeeded"],
        "goals": len(goals),
        "collisions": s["collisions"],
    }


def run_clutter(args: Any) -> dict[str, Any]:
    """``navlab bench clutter``: the clutter benchmark's protocol (``experiments.clutter_protocol``): ``--set``
    (test | tuning), ``--worlds``, ``--robot`` (jackal), ``--controller`` (mppi for the robots whose files tune it,
    else the robot's own), ``--max-speed`` (2 m/s; 0 keeps the files'), ``--out`` (a picture of each failure)."""
    robot = getattr(args, "robot", None) or "jackal"
    controller = getattr(args, "controller", None) or ("mppi" if robot in ("mybot", "jackal") else None)
    speed = getattr(args, "max_speed", None)
    out = run_protocol(
        n=int(getattr(args, "worlds", 0) or 50),
        which=getattr(args, "set", None) or "test",
        robot=robot,
        controller=controller,
        max_speed=(JACKAL_MAX_SPEED if controller else None) if speed is None else (speed or None),
        out=getattr(args, "out", None),
        seed=getattr(args, "seed", 0),
        progress=not getattr(args, "quiet", False),
    )
    return out["summary"]


def run_odom(args: Any) -> dict[str, Any]:
    """``navlab bench odom``: drift per robot, route and EKF setting (see the module)."""
    t0 = time.perf_counter()
    runs = [
        run_drift(robot, route, ekf=ekf, seed=getattr(args, "seed", 0))
        for robot in ROBOTS
        for route in ROUTES
        for ekf in (False, True)
    ]
    out: dict[str, Any] = {}
    for r in runs:
        key = f"{r['robot']}/{r['route']}/{'ekf' if r['ekf'] else 'wheels'}"
        out[key] = {
            k: r[k]
            for k in (
                "error_per_m",
                "yaw_error_per_rad",
                "final_error_m",
                "max_error_m",
                "distance_m",
                "turned_rad",
                "completed",
            )
        }
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    return out
