"""``navlab bench startup``: start-up of the ``navlab`` command in child processes."""

from __future__ import annotations

import argparse
import statistics
import sys
from typing import Any


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Start-up of the ``navlab`` command in child processes, medians of 3 after one untimed run: ``VERB
    --help`` (sim, slam, navigate) and ``sim --duration 0.01`` (the shortest run: imports, world, robot,
    MuJoCo model, one step; Numba's cache warm), each in CPU seconds (user + system) and wall seconds."""
    from navlab.bench.core import run_child

    def median(cmd: list[str]) -> dict[str, float]:
        run_child(cmd)  # warm: Numba's cache, the OS's file cache
        runs = [run_child(cmd) for _ in range(3)]
        return {k: statistics.median(r[k] for r in runs) for k in ("cpu_s", "wall_s")}

    navlab = [sys.executable, "-m", "navlab.cli"]
    helps = [median([*navlab, verb, "--help"]) for verb in ("sim", "slam", "navigate")]
    sim = median([*navlab, "sim", "--duration", "0.01", "--quiet"])
    return {
        "help_cpu_s": round(max(h["cpu_s"] for h in helps), 3),
        "help_wall_s": round(max(h["wall_s"] for h in helps), 3),
        "sim_start_cpu_s": round(sim["cpu_s"], 3),
        "sim_start_wall_s": round(sim["wall_s"], 3),
    }
