"""``navlab bench sim``: real-time factor of mybot in room_obstacles.world with physics, the 40 Hz lidar
and the 30 Hz diff drive running (the robot driving a 0.5 m circle), plus per-step and per-scan costs;
``rtf_all_plugins`` adds joint states (30 Hz) and ground truth (50 Hz), ``rtf_timestep_1ms`` uses
Gazebo's usual 1 ms physics step instead of the default 2 ms.

``rtf`` is simulated seconds per CPU second of this process (``time.process_time``: the "one core"
of the budget, robust to other processes sharing the machine); ``rtf_wall`` divides by wall-clock
time instead. Each figure is the median of three runs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

from navlab import msgs
from navlab.core import Executor, Node
from navlab.sim import GazeboSim, launch_sim

WORLD, ROBOT = "room_obstacles", "mybot"
SIM_SECONDS = 10.0
REPEATS = 3


def _rtf(seed: int, seconds: float, **params: Any) -> tuple[float, float, GazeboSim]:
    """(rtf by CPU time, rtf by wall time, the gazebo node) of one run."""
    ex = Executor(seed=seed)
    gazebo = launch_sim(ex, world=WORLD, robot=ROBOT, **params)
    driver = Node(ex, name="bench_driver")
    cmd = driver.create_publisher(msgs.Twist, "cmd_vel", 10)
    driver.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.3, 0.6)))
    ex.run(1.0)  # warm up (Numba loads its cache, first contacts)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    ex.run(seconds)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    return seconds / cpu, seconds / wall, gazebo


def _median_rtf(seed: int, **params: Any) -> tuple[float, float, GazeboSim]:
    runs = [_rtf(seed, SIM_SECONDS, **params) for _ in range(REPEATS)]
    return (statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs), runs[-1][2])


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Measure and return {"rtf", "step_us", "scan_ms", ...} (see the module docstring)."""
    seed = int(getattr(args, "seed", 0))
    # the benchmark as specified: physics (default 2 ms step) + 40 Hz lidar + 30 Hz diff drive
    rtf, rtf_wall, gazebo = _median_rtf(seed, joint_state_rate=0.0, ground_truth_rate=0.0)
    sim = gazebo.sim
    steps = []
    for _ in range(5):
        t0 = time.process_time()
        sim.step(2000)
        steps.append((time.process_time() - t0) / 2000 * 1e6)
    scans = []
    for _ in range(5):
        t0 = time.process_time()
        for _ in range(100):
            sim.scan(0)
        scans.append((time.process_time() - t0) / 100 * 1e3)
    rtf_all, _, _ = _median_rtf(seed, joint_state_rate=30.0, ground_truth_rate=50.0)
    rtf_1ms, _, _ = _median_rtf(seed, joint_state_rate=0.0, ground_truth_rate=0.0, timestep=0.001)
    return {
        "rtf": round(rtf, 1),
        "step_us": round(statistics.median(steps), 2),
        "scan_ms": round(statistics.median(scans), 4),
        "rtf_wall": round(rtf_wall, 1),
        "timestep_s": sim.timestep,
        "rtf_all_plugins": round(rtf_all, 1),
        "rtf_timestep_1ms": round(rtf_1ms, 1),
        "sim_s_per_run": SIM_SECONDS,
        "world": WORLD,
        "robot": ROBOT,
        "lidar_rays": sim.robot.lidars[0].samples if sim.robot else 0,
    }
