"""``navlab bench sim``: real-time factor of mybot in room_obstacles.world with physics, the 40 Hz lidar
and the 30 Hz diff drive running (the robot driving a 0.5 m circle), plus per-step and per-scan costs."""

from __future__ import annotations

import argparse
import time
from typing import Any

from navlab import msgs
from navlab.core import Executor, Node
from navlab.sim.gazebo import GazeboSim, launch_sim

WORLD, ROBOT = "room_obstacles", "mybot"
SIM_SECONDS = 30.0


def _rtf(seed: int, seconds: float, **params: Any) -> tuple[float, GazeboSim]:
    ex = Executor(seed=seed)
    gazebo = launch_sim(ex, world=WORLD, robot=ROBOT, **params)
    driver = Node("bench_driver", ex)
    cmd = driver.create_publisher(msgs.Twist, "cmd_vel", 10)
    driver.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.3, 0.6)))
    ex.run(1.0)  # warm up (Numba loads its cache, first contacts)
    t0 = time.perf_counter()
    ex.run(seconds)
    return seconds / (time.perf_counter() - t0), gazebo


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Measure and return {"rtf", "step_us", "scan_ms", ...} (see the module docstring)."""
    seed = int(getattr(args, "seed", 0))
    # the benchmark as specified: physics + 40 Hz lidar + 30 Hz diff drive
    rtf, gazebo = _rtf(seed, SIM_SECONDS, joint_state_rate=0.0, ground_truth_rate=0.0)
    sim = gazebo.sim
    n = 5000
    t0 = time.perf_counter()
    sim.step(n)
    step_us = (time.perf_counter() - t0) / n * 1e6
    scans = 300
    t0 = time.perf_counter()
    for _ in range(scans):
        sim.scan(0)
    scan_ms = (time.perf_counter() - t0) / scans * 1e3
    rtf_all, _ = _rtf(seed, SIM_SECONDS / 3, joint_state_rate=30.0, ground_truth_rate=50.0)
    rtf_2ms, _ = _rtf(seed, SIM_SECONDS / 3, joint_state_rate=0.0, ground_truth_rate=0.0, timestep=0.002)
    return {
        "rtf": round(rtf, 1),
        "step_us": round(step_us, 2),
        "scan_ms": round(scan_ms, 4),
        "timestep_s": sim.timestep,
        "sim_seconds": SIM_SECONDS,
        "rtf_all_plugins": round(rtf_all, 1),
        "rtf_timestep_2ms": round(rtf_2ms, 1),
        "world": WORLD,
        "robot": ROBOT,
        "lidar_rays": sim.robot.lidars[0].samples if sim.robot else 0,
    }
