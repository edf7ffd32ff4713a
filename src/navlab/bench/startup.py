"""``navlab bench startup``: start-up of the ``navlab`` command in child processes."""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from typing import Any

# a worker's second trial (its first loads the imports, Numba's cache and MuJoCo): the shortest trial, a goal
# at the start pose in the room
_TRIAL = r"""
import json, time
from navlab.experiments.scenario import scenario_from_dict
from navlab.experiments.trials import run_trial
sc = scenario_from_dict({"name": "startup", "world": "room", "goals": [[0.0, 0.0, 0.0]], "trials": 2})
run_trial(sc, 0)
c0, t0 = time.process_time(), time.perf_counter()
r = run_trial(sc, 1)
print(json.dumps({"cpu_s": time.process_time() - c0, "wall_s": time.perf_counter() - t0, "sim_s": r["sim_s"]}))
"""


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Start-up of the ``navlab`` command in child processes, medians of 3 after one untimed run: ``VERB
    --help`` (sim, slam, navigate) and ``sim --duration 0`` (the shortest run: imports, world, robot, MuJoCo
    model; Numba's cache warm), each in CPU seconds (user + system) and wall seconds; and ``trial_*``: a
    trial in a warm worker (an experiment's second trial in one process: a goal at the start pose, about 1
    simulated s), CPU and wall seconds, median of 3 processes."""
    from navlab.bench.core import run_child

    def median(cmd: list[str]) -> dict[str, float]:
        run_child(cmd)  # warm: Numba's cache, the OS's file cache
        runs = [run_child(cmd) for _ in range(3)]
        return {k: statistics.median(r[k] for r in runs) for k in ("cpu_s", "wall_s")}

    navlab = [sys.executable, "-m", "navlab.cli"]
    helps = [median([*navlab, verb, "--help"]) for verb in ("sim", "slam", "navigate")]
    sim = median([*navlab, "sim", "--duration", "0", "--quiet"])
    trials = [
        json.loads(
            subprocess.run(
                [sys.executable, "-c", _TRIAL], capture_output=True, text=True, check=True
            ).stdout.splitlines()[-1]
        )
        for _ in range(3)
    ]
    return {
        "help_cpu_s": round(max(h["cpu_s"] for h in helps), 3),
        "help_wall_s": round(max(h["wall_s"] for h in helps), 3),
        "sim_start_cpu_s": round(sim["cpu_s"], 3),
        "sim_start_wall_s": round(sim["wall_s"], 3),
        **{f"trial_{k}": round(statistics.median(t[k] for t in trials), 3) for k in ("cpu_s", "wall_s", "sim_s")},
    }
