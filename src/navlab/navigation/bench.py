"""``navlab bench planner``: navigation benchmarks (one section per part).

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

from navlab.grid import GridMap
from navlab.navigation.costmap import LayeredCostmap
from navlab.navigation.planners import NavfnPlanner, ThetaStarPlanner, path_length

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
