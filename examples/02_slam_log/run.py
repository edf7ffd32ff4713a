"""02 — SLAM on a real laser log, scored like a benchmark paper.

Reads the MIT CSAIL CARMEN log, runs graph SLAM (scan matching + loop closure + pose-graph
optimisation) on its first scans, saves the map as map_server files, draws it, and scores the
trajectory and the raw odometry with the relations metric of Kümmerle et al. 2009.

The log is found through NAVLAB_DATA (default: ../shared/datasets relative to the repository root).

Run:  python examples/02_slam_log/run.py            (first 600 scans, a few seconds)
      python examples/02_slam_log/run.py --full     (the whole 424 s log)
      python examples/02_slam_log/run.py --mode gmapping   (the paper's particle filter)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from navlab.errors import NavlabError
from navlab.experiments import read_relations, relations_error
from navlab.io import dataset, read_carmen
from navlab.mapping import run_offline, write_outputs

try:
    DATA = dataset("mit-csail")  # under NAVLAB_DATA (default: ../shared/datasets beside the repository)
except NavlabError as exc:
    sys.exit(f"02_slam_log: {exc}")
OUT = Path("out/examples/02_slam_log")

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--full", action="store_true", help="the whole log instead of the first 600 scans")
parser.add_argument("--mode", choices=("graph", "gmapping"), default="graph")
args = parser.parse_args()

log = read_carmen(DATA / "mit-csail.clf")
n = None if args.full else 600
result = run_offline(log, mode=args.mode, max_scans=n, progress=sys.stderr.isatty())
files = write_outputs(result, OUT)
print("wrote", ", ".join(str(p) for p in files.values()))

# score only the relations between scans we processed
rel = read_relations(DATA / "mit-csail.relations")
t_end = result.timestamps[-1]
rel = rel[(rel[:, 0] <= t_end) & (rel[:, 1] <= t_end)]
odom = np.array([s.odom_pose for s in log.scans[: len(result.timestamps)]])
for name, poses in (("raw odometry", odom), (f"SLAM ({args.mode})", result.poses)):
    r = relations_error(result.timestamps, poses, rel)
    print(
        f"{name:>16}: {r['trans_abs_mean']:.3f} ± {r['trans_abs_std']:.3f} m, "
        f"{r['rot_abs_mean_deg']:.2f} ± {r['rot_abs_std_deg']:.2f} deg over {r['n_scored']} relations"
    )
