"""``navlab bench description``: how long loading the paper's robot and world takes."""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

from navlab import resources


def _median_ms(fn: Callable[[], Any], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return round(statistics.median(times) * 1e3, 3)


def run(args: argparse.Namespace) -> dict[str, float]:
    """Median wall time (ms) of: mybot xacro → RobotModel, room_obstacles.world → WorldModel, and
    its true occupancy grid at 5 cm (220 x 180 cells)."""
    from navlab.description import load_robot
    from navlab.world import load_world, occupancy

    robot_path, world_path = resources.robot("mybot"), resources.world("room_obstacles")
    world = load_world(world_path)
    return {
        "load_robot_ms": _median_ms(lambda: load_robot(robot_path), 20),
        "load_world_ms": _median_ms(lambda: load_world(world_path), 20),
        "occupancy_ms": _median_ms(lambda: occupancy(world, 0.05, (-5.5, -4.5, 5.5, 4.5)), 20),
    }
