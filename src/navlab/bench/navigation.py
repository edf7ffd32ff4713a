"""``navlab bench controller`` and ``navlab bench planner``: navigation benchmarks (one section per part).

Controllers: one control cycle of DWAPlannerROS with 20 x 40 velocity samples (vx_samples,
vth_samples; sim_time 1.7 s at 2.5 cm) and of the MPPI controller with 1000 samples x 56 steps, on a
4 m x 4 m rolling local costmap at 5 cm cut from a cluttered 8 m room (30 round obstacles, inflated
as costmap_2d does: inscribed radius 0.2 m, inflation radius 0.55 m), the robot placed along a
planned path moving at 0.4 m/s. Windows are cut outside the timed region; Numba compiles first.

Planner: a 400 x 400-cell (20 m x 20 m, 5 cm) serpentine maze whose walls the global costmap inflates
(static + inflation layers, the paper's robot_radius 0.2 m, inflation_radius 0.55 m); navfn plans from
one corner to the far end (about 180 m of path, nearly every free cell settled). Numba compiles and
warms up first; times are medians (wall clock; ``cpu_ms`` is process time, steadier on a shared machine).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

from navlab.grid import Grid, GridMap
from navlab.navigation import (
    DWAPlannerROS,
    LayeredCostmap,
    MPPIController,
    NavfnPlanner,
    ThetaStarPlanner,
    TrajectoryPlannerROS,
    path_length,
)
from navlab.navigation import synthetic as syn

# --- controllers ------------------------------------------------------------------------------------


def _time_cycles(
    ctrl: Any, plan: np.ndarray, scenes: list[tuple[tuple[float, float, float], Grid]], repeat: int
) -> np.ndarray:
    """Milliseconds of each ``compute_velocity`` over ``scenes`` (pose, local costmap), after a warm-up."""
    ctrl.set_plan(plan)
    for pose, local in scenes[:3]:
        ctrl.compute_velocity(pose, (0.4, 0.0), local)
    out = []
    for _ in range(repeat):
        for pose, local in scenes:
            t0 = time.perf_counter()
            ctrl.compute_velocity(pose, (0.4, 0.0), local)
            out.append((time.perf_counter() - t0) * 1e3)
    return np.array(out)


def run_controller(args: argparse.Namespace) -> dict[str, Any]:
    """Median and 95th-percentile cycle times (ms) of DWA (20 x 40), TrajectoryPlanner and MPPI (1000 x 56)."""
    seed = int(getattr(args, "seed", 0))
    rng = np.random.default_rng(seed)
    start, goal = (0.8, 0.8), (7.2, 7.2)
    mask = syn.clutter(rng, count=30, keep_clear=(start, goal))
    world = Grid(syn.inflated(mask, 0.05), 0.05, (0.0, 0.0, 0.0), "odom")
    plan = syn.grid_plan(world, start, goal)
    scenes = []
    for k in range(10, len(plan) - 40, 12):
        x, y, yaw = plan[k]
        scenes.append(((float(x), float(y), float(yaw)), syn.window(world, x, y)))
    dwa = DWAPlannerROS({"vx_samples": 20, "vth_samples": 40})
    tp = TrajectoryPlannerROS({"vx_samples": 20, "vtheta_samples": 40})
    mppi = MPPIController({}, rng=np.random.default_rng(seed))
    t_dwa = _time_cycles(dwa, plan, scenes, 5)
    t_tp = _time_cycles(tp, plan, scenes, 5)
    t_mppi = _time_cycles(mppi, plan, scenes, 3)
    return {
        "dwa_cycle_ms": round(float(np.median(t_dwa)), 3),
        "dwa_cycle_ms_p95": round(float(np.percentile(t_dwa, 95)), 3),
        "dwa_samples": len(dwa.samples),
        "trajectory_planner_cycle_ms": round(float(np.median(t_tp)), 3),
        "mppi_cycle_ms": round(float(np.median(t_mppi)), 3),
        "mppi_cycle_ms_p95": round(float(np.percentile(t_mppi, 95)), 3),
        "mppi_samples": mppi.params.batch_size,
        "mppi_steps": mppi.params.time_steps,
        "local_costmap_cells": list(scenes[0][1].data.shape),
        "cycles": len(scenes),
    }


# --- planner ----------------------------------------------------------------------------------------

MAZE_CELLS = 400
MAZE_RESOLUTION = 0.05
MAZE_WALL_EVERY = 40  # cells between maze walls
PLANNER_RUNS = 7


def maze(n: int = MAZE_CELLS) -> GridMap:
    """A serpentine maze (occupancy 0/100): a border and walls every ``MAZE_WALL_EVERY`` cells, the gap
    alternately at the top and the bottom, so the only way across winds through every corridor."""
    data = np.zeros((n, n), np.int8)
    data[:2, :] = data[-2:, :] = data[:, :2] = data[:, -2:] = 100
    for k, x in enumerate(range(MAZE_WALL_EVERY, n - MAZE_WALL_EVERY // 2, MAZE_WALL_EVERY)):
        if k % 2 == 0:
            data[2 : n - MAZE_WALL_EVERY, x : x + 2] = 100
        else:
            data[MAZE_WALL_EVERY : n - 2, x : x + 2] = 100
    return GridMap(data, MAZE_RESOLUTION, (0.0, 0.0, 0.0))


def _median_ms(fn: Any, runs: int) -> tuple[float, float, Any]:
    """(median wall ms, median process ms, last result) of ``runs`` calls after one warm-up call."""
    fn()
    wall, cpu, out = [], [], None
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)) * 1e3, float(np.median(cpu)) * 1e3, out


def run_planner(args: argparse.Namespace) -> dict[str, Any]:
    """navfn (Dijkstra, and A*) and Theta* on the inflated maze; ``plan_ms`` is navfn's (target <= 30 ms)."""
    del args  # the maze is fixed: nothing random
    costmap = LayeredCostmap({"robot_radius": 0.2, "inflation_radius": 0.55, "static_map": True})
    costmap.set_map(maze())
    update_ms, _, grid = _median_ms(lambda: costmap.update_map((0.5, 0.5, 0.0)), PLANNER_RUNS)
    start, goal = (0.5, 0.5, 0.0), (MAZE_CELLS * MAZE_RESOLUTION - 0.5, 0.5, 0.0)
    navfn = NavfnPlanner()
    plan_ms, cpu_ms, path = _median_ms(lambda: navfn.make_plan(grid, start, goal), PLANNER_RUNS)
    astar = NavfnPlanner({"use_dijkstra": False})
    astar_ms, _, _ = _median_ms(lambda: astar.make_plan(grid, start, goal), PLANNER_RUNS)
    theta = ThetaStarPlanner()
    theta_ms, _, theta_path = _median_ms(lambda: theta.make_plan(grid, start, goal), 3)
    return {
        "plan_ms": round(plan_ms, 2),
        "cpu_ms": round(cpu_ms, 2),
        "cells": navfn.stats["cells"],
        "path_m": round(path_length(path), 2),
        "grid": f"{grid.width}x{grid.height}",
        "astar_ms": round(astar_ms, 2),
        "astar_cells": astar.stats["cells"],
        "theta_star_ms": round(theta_ms, 2),
        "theta_star_path_m": round(path_length(theta_path), 2),
        "costmap_update_ms": round(update_ms, 2),
    }
