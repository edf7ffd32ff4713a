"""``navlab bench sweep``: the wall time of one parameter sweep, run as a user runs it, with local workers and Ray."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import yaml

from navlab.experiments import ExperimentError

BENCH_TRIALS = 10  # per combination: 2 x 10 trials, a small real sweep (the shipped sweeps run 20 per value)
RAY_COSTS = """import json, time
t0 = time.perf_counter()
import ray
t1 = time.perf_counter()
from navlab.experiments.backends import init_ray
t2 = time.perf_counter()
init_ray(ray, 2)
t3 = time.perf_counter()
ray.shutdown()
t4 = time.perf_counter()
print(json.dumps({"ray_import_s": t1 - t0, "ray_init_s": t3 - t2, "ray_shutdown_s": t4 - t3}))
"""


def run(args: Any) -> dict[str, Any]:
    """``navlab bench sweep``: wall time of one sweep (2 combinations x ``--trials`` trials, default 10, of two
    goals in the empty room), each run as a user runs it — a fresh ``navlab experiment sweep`` process (imports,
    Numba's caches, worker or Ray start-up included) — with 1 local worker, 2 local workers and a local Ray
    instance of 2 CPUs, each twice (in the order A B C C B A; ``*_runs_s``), the faster of the two kept, and the
    speed-ups against 1 worker. ``*_cpu_s``: the CPU seconds the whole machine spent during the kept run (Ray's own
    processes included). Ray's fixed costs, timed apart in an idle process:
    ``ray_startup_s`` (``import ray`` + ``ray.init``) and ``ray_shutdown_s`` (which a sweep overlaps with
    writing its tables and plots); ``ray_overhead_s``: the Ray sweep's wall time over 2 local workers'."""
    per = int(getattr(args, "trials", None) or BENCH_TRIALS)
    scenario = {
        "name": "bench_sweep",
        "world": "room",
        "goals": [[3.5, 3.0, 1.57], [-3.5, 0.0, -1.57]],
        "trials": per,
        "seed": int(getattr(args, "seed", 0) or 0),
        "time_limit": 60,
    }
    out: dict[str, Any] = {
        "trials": 2 * per,
        "trials_per_combination": per,
        "cpus": os.cpu_count(),
        "load_1min": round(os.getloadavg()[0], 2),
    }
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}  # a local instance: this machine's figure
    with tempfile.TemporaryDirectory(prefix="navlab-bench-sweep-") as tmp:
        path = Path(tmp) / "bench_sweep.yaml"
        path.write_text(yaml.safe_dump(scenario))
        configs = [
            ("workers_1", ["--workers", "1"]),
            ("workers_2", ["--workers", "2"]),
            ("ray_2", ["--workers", "2", "--backend", "ray"]),
        ]
        for k, (key, extra) in enumerate(configs + configs[::-1]):  # A B C C B A: drifting load hits all alike
            cmd = [
                sys.executable,
                "-m",
                "navlab.cli",
                "experiment",
                "sweep",
                str(path),
                "--param",
                "controller=trajectory,dwa",
                "--out",
                str(Path(tmp) / f"{key}{k}"),
                "--quiet",
                "--json",
                *extra,
            ]
            cpu0, t0 = _machine_cpu_s(), time.perf_counter()
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
            wall, cpu1 = time.perf_counter() - t0, _machine_cpu_s()
            if done.returncode != 0:
                raise ExperimentError(f"bench sweep: {' '.join(cmd[3:])} failed: {done.stderr.strip()[-500:]}")
            runs = out[f"{key}_runs_s"] = [*out.get(f"{key}_runs_s", []), round(wall, 2)]
            if runs[-1] == min(runs):  # the less disturbed run is the figure
                out[f"{key}_s"] = runs[-1]
                out[f"{key}_cpu_s"] = round(cpu1 - cpu0, 1) if cpu0 is not None and cpu1 is not None else None
        costs = subprocess.run(
            [sys.executable, "-c", RAY_COSTS], env=env, capture_output=True, text=True, check=False, cwd=tmp
        )
        if costs.returncode != 0:
            raise ExperimentError(f"bench sweep: timing Ray's start-up failed: {costs.stderr.strip()[-500:]}")
    ray = json.loads(costs.stdout.strip().splitlines()[-1])
    out["ray_startup_s"] = round(ray["ray_import_s"] + ray["ray_init_s"], 2)
    out.update({k: round(v, 2) for k, v in ray.items()})
    out["ray_overhead_s"] = round(out["ray_2_s"] - out["workers_2_s"], 2)
    out["speedup_2"] = round(out["workers_1_s"] / out["workers_2_s"], 2)
    out["speedup_ray"] = round(out["workers_1_s"] / out["ray_2_s"], 2)
    out["load_1min_after"] = round(os.getloadavg()[0], 2)
    return out


def _machine_cpu_s() -> float | None:
    """CPU seconds the whole machine has been busy since boot (Linux's /proc/stat; None elsewhere)."""
    import os

    try:
        fields = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:8]]
    except (OSError, ValueError):
        return None
    user, nice, system, _idle, _iowait, irq, softirq = fields
    return (user + nice + system + irq + softirq) / os.sysconf("SC_CLK_TCK")
