"""``navlab bench slam``: graph SLAM over the MIT CSAIL log, real-time factor on this machine."""

from __future__ import annotations

import argparse
import time
from typing import Any

CSAIL = "mit-csail/mit-csail.clf"  # under NAVLAB_DATA (default ../shared/datasets beside the repository)


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Time ``run_offline`` (graph mode, including the final map) on the CSAIL log.

    A missing log raises ``DatasetNotFoundError`` saying where it was looked for and how to provide it.
    """
    from navlab.io.carmen import read_carmen
    from navlab.io.datasets import dataset
    from navlab.mapping.scanmatch import warmup
    from navlab.mapping.slam import run_offline

    log = read_carmen(dataset(CSAIL))
    warmup()  # numba compilation is not part of the figure (it is cached on disk after the first run)
    t0, c0 = time.perf_counter(), time.process_time()
    run_offline(log, mode="graph", seed=getattr(args, "seed", 0))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    # cpu_s is this process's CPU time: on a busy machine it shows what one free core would take
    return {
        "log_s": round(log.duration, 3),
        "wall_s": round(wall, 3),
        "rtf": round(log.duration / wall, 2),
        "cpu_s": round(cpu, 3),
        "rtf_cpu": round(log.duration / cpu, 2),
    }
