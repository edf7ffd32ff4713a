"""``navlab bench slam``: graph SLAM over the MIT CSAIL log (real-time factor on this machine, relations
error); ``navlab bench slam-office``: both SLAM modes on sparse simulator logs of the generated office
floor (ATE and map precision against the true walls, over 5 seeds)."""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

CSAIL = "mit-csail/mit-csail.clf"  # under NAVLAB_DATA (default ../shared/datasets beside the repository)
RELATIONS = "mit-csail/mit-csail.relations"
OFFICE_SEEDS = 5


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Time ``run_offline`` (graph mode, including the final map) on the CSAIL log and score its poses
    with the relations metric.

    A missing log raises ``DatasetNotFoundError`` saying where it was looked for and how to provide it.
    """
    from navlab.experiments import read_relations, relations_closure, relations_error
    from navlab.io import dataset, read_carmen
    from navlab.mapping import run_offline, warmup

    log = read_carmen(dataset(CSAIL))
    warmup()  # numba compilation is not part of the figure (it is cached on disk after the first run)
    t0, c0 = time.perf_counter(), time.process_time()
    result = run_offline(log, mode="graph", seed=getattr(args, "seed", 0))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    relations = read_relations(dataset(RELATIONS))
    rel = relations_error(result.timestamps, result.poses, relations)
    # cpu_s is this process's CPU time: on a busy machine it shows what one free core would take
    return {
        "log_s": round(log.duration, 3),
        "wall_s": round(wall, 3),
        "rtf": round(log.duration / wall, 2),
        "cpu_s": round(cpu, 3),
        "rtf_cpu": round(log.duration / cpu, 2),
        "relations_scored": rel["n_scored"],
        "relations_trans_m": round(float(rel["trans_abs_mean"]), 4),
        "relations_rot_deg": round(float(rel["rot_abs_mean_deg"]), 3),
        # what poses without error would score, from the relations' own triangles (their error, not ours)
        "relations_noise_floor_m": round(relations_closure(relations)["noise_floor_m"], 4),
    }


def office_truth(resolution: float = 0.05) -> Any:
    """The default office floor's true occupancy (a boolean ``Grid``, world frame)."""
    from navlab.world import generate_office, load_world, occupancy, truth_grid

    office = generate_office()
    with tempfile.TemporaryDirectory(prefix="navlab-office-") as tmp:
        world = load_world(office.write_world(Path(tmp) / "office.world"))
    bounds = (-1.0, -1.0, office.width + 1.0, office.depth + 1.0)
    occ = occupancy(world, resolution, bounds, static_only=True)
    return truth_grid(occ, resolution, (bounds[0], bounds[1]))


def office_scores(sim_log: Any, result: Any, truth: Any) -> dict[str, float]:
    """ATE of a SLAM ``result``'s robot poses against the log's truth, and the map's precision and recall
    against ``truth`` (``office_truth``) with the map placed by the same rigid alignment (a map's gauge,
    its first pose, is free)."""
    from navlab.experiments import apply_se2, ate, score_map
    from navlab.geometry import compose2, inverse2

    truth_in_map = apply_se2(tuple(inverse2(sim_log.start)), sim_log.truth)  # map frame = the start pose
    a = ate(result.poses, truth_in_map)
    world_T_map = compose2(sim_log.start, (a["align_x"], a["align_y"], a["align_yaw"]))
    m = score_map(result.grid, truth, world_T_map=(float(world_T_map[0]), float(world_T_map[1]), float(world_T_map[2])))
    return {
        "ate_rmse_m": a["rmse_m"],
        "ate_max_m": a["max_m"],
        "ate_share_over_0.5m": a["share_over_far"],
        "precision": float(m["precision"]),
        "recall": float(m["recall"]),
    }


def run_office(args: argparse.Namespace) -> dict[str, Any]:
    """Both SLAM modes on the office floor's sparse logs (seeds ``seed`` .. ``seed + 4``): per mode the
    worst and mean ATE RMSE, the worst ATE max, the worst map precision, and SLAM's CPU time per log."""
    from navlab.mapping import office_log, run_offline, warmup

    warmup()
    seed0 = getattr(args, "seed", 0)
    truth = office_truth()
    rows: dict[str, list[dict[str, float]]] = {"graph": [], "gmapping": []}
    log_s = 0.0
    for seed in range(seed0, seed0 + OFFICE_SEEDS):
        sim_log = office_log(seed)
        log_s = sim_log.log.duration
        for mode, out in rows.items():
            c0 = time.process_time()
            result = run_offline(sim_log.log, mode=mode, seed=seed)
            out.append({**office_scores(sim_log, result, truth), "cpu_s": time.process_time() - c0})
    summary: dict[str, Any] = {"seeds": OFFICE_SEEDS, "scans": len(sim_log.log.scans), "log_s": round(log_s, 1)}
    for mode, out in rows.items():
        col = {k: np.array([r[k] for r in out]) for k in out[0]}
        summary[mode] = {
            "ate_rmse_m_max": round(float(col["ate_rmse_m"].max()), 4),
            "ate_rmse_m_mean": round(float(col["ate_rmse_m"].mean()), 4),
            "ate_max_m_max": round(float(col["ate_max_m"].max()), 4),
            "share_over_0.5m_max": round(float(col["ate_share_over_0.5m"].max()), 4),
            "precision_min": round(float(col["precision"].min()), 4),
            "recall_mean": round(float(col["recall"].mean()), 4),
            "cpu_s_mean": round(float(col["cpu_s"].mean()), 2),
        }
    return summary


def run_gmapping(args: argparse.Namespace) -> dict[str, Any]:
    """``navlab slam --mode gmapping`` on the CSAIL log in child processes: CPU seconds, peak RSS (MB) and the
    relations metric of the poses, with slam_gmapping's defaults (the filter plus the offline refinement) and,
    as ``filter_*``, with ``--set refine=false`` (the filter alone)."""
    import sys

    from navlab.bench.core import run_child
    from navlab.experiments import read_relations, relations_error
    from navlab.io import dataset

    clf, relations = dataset(CSAIL), read_relations(dataset(RELATIONS))
    out: dict[str, Any] = {}
    for prefix, extra in (("", []), ("filter_", ["--set", "refine=false"])):
        with tempfile.TemporaryDirectory(prefix="navlab-bench-") as tmp:
            cmd = [
                sys.executable,
                "-m",
                "navlab.cli",
                "slam",
                "--log",
                str(clf),
                "--mode",
                "gmapping",
                "--out",
                tmp,
                "--quiet",
                "--seed",
                str(getattr(args, "seed", 0)),
                *extra,
            ]
            usage = run_child(cmd)
            poses = np.loadtxt(Path(tmp) / "poses.txt")
        rel = relations_error(poses[:, 0], poses[:, 1:4], relations)
        out.update(
            {
                **{prefix + k: round(v, 2) for k, v in usage.items()},
                prefix + "relations_trans_m": round(float(rel["trans_abs_mean"]), 4),
                prefix + "relations_rot_deg": round(float(rel["rot_abs_mean_deg"]), 3),
                prefix + "relations_rot_max_deg": round(float(rel["rot_max_deg"]), 2),
                prefix + "relations_over_5deg": rel["rot_over_5deg"],
            }
        )
    return out
