"""CLI verbs of the mapping package: ``navlab slam`` (offline SLAM on a log) and ``navlab eval``."""

from __future__ import annotations

import argparse
import json
import sys
import time

import yaml

from navlab.mapping.run_cli import add_eval_map


def _params_file(path: str | None) -> dict:
    if not path:
        return {}
    from navlab.mapping.errors import MappingError

    try:
        with open(path) as fh:
            doc = yaml.safe_load(fh) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise MappingError(f"cannot read SLAM parameter file {path}: {exc}") from None
    if not isinstance(doc, dict):
        raise MappingError(f"{path}: expected a mapping of parameter names to values")
    # accept ROS layouts: {node: {ros__parameters: {...}}} or {node: {...}}
    if len(doc) == 1 and isinstance(next(iter(doc.values())), dict):
        inner = next(iter(doc.values()))
        doc = inner.get("ros__parameters", inner)
    return doc


def _cmd_slam(args: argparse.Namespace) -> int:
    from navlab.io.carmen import read_carmen, skipped_summary
    from navlab.mapping.slam import run_offline, write_outputs

    log = read_carmen(args.log)
    note = skipped_summary(log)
    if note:
        print(f"navlab slam: warning: {note}", file=sys.stderr)
    t0 = time.perf_counter()
    result = run_offline(
        log,
        mode=args.mode,
        params=_params_file(args.params),
        seed=args.seed,
        resolution=args.resolution,
        max_scans=args.max_scans,
        progress=not args.quiet and sys.stderr.isatty(),
    )
    wall = time.perf_counter() - t0
    paths = write_outputs(result, args.out, title=f"{log.path.name if log.path else ''} ({args.mode})")
    summary = {
        "scans": len(result.timestamps),
        "skipped_lines": len(log.skipped),
        "log_seconds": float(result.timestamps[-1] - result.timestamps[0]),
        "wall_seconds": wall,
        **result.stats,
        **{k: str(v) for k, v in paths.items()},
    }
    if args.json:
        print(json.dumps(summary))
    elif not args.quiet:
        for k, v in summary.items():
            print(f"{k}: {v}")
    return 0


def _cmd_eval_relations(args: argparse.Namespace) -> int:
    from navlab.experiments.metrics import read_poses, read_relations, relations_error

    ts, poses = read_poses(args.poses)
    rel = read_relations(args.relations)
    out = relations_error(ts, poses, rel, time_tolerance=args.tolerance)
    if args.json:
        print(json.dumps(out))
    else:
        print(f"relations scored: {out['n_scored']} of {out['n_relations']}")
        print(f"translation: {out['trans_abs_mean']:.4f} ± {out['trans_abs_std']:.4f} m")
        print(f"rotation:    {out['rot_abs_mean_deg']:.3f} ± {out['rot_abs_std_deg']:.3f} deg")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``slam`` and ``eval`` verbs."""
    p = sub.add_parser(
        "slam",
        help="run SLAM offline on a laser log and save the map and trajectory",
        description="Run SLAM on a CARMEN log (FLASER, ODOM, ROBOTLASER1 lines) and write DIR/map.yaml + "
        "DIR/map.pgm (map_server format), DIR/poses.txt (one 'timestamp x y theta' line per scan, robot "
        "pose in the map frame) and DIR/map.png (map and trajectory).",
    )
    p.add_argument("--log", required=True, metavar="FILE.clf", help="CARMEN log file")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument(
        "--mode",
        default="graph",
        help="graph: scan-to-map matching + loop closure + pose-graph optimisation (default); "
        "gmapping: the paper's Rao-Blackwellized particle filter",
    )
    p.add_argument("--params", metavar="YAML", help="SLAM parameters: slam_gmapping's names (graph mode's own "
                   "under 'graph:')")
    p.add_argument("--resolution", type=float, default=0.05, help="map resolution in m/cell (default 0.05)")
    p.add_argument("--max-scans", type=int, default=None, help="only the first N scans")
    p.add_argument("--seed", type=int, default=0, help="random seed (gmapping mode; default 0)")
    p.add_argument("--json", action="store_true", help="print a JSON summary")
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")
    p.set_defaults(func=_cmd_slam)

    e = sub.add_parser(
        "eval",
        help="score SLAM results (relations metric of Kümmerle et al. 2009; maps against a simulated world)",
        description="Evaluate SLAM output against ground truth.",
    )
    esub = e.add_subparsers(dest="eval_kind", metavar="KIND", required=True)
    r = esub.add_parser(
        "relations",
        help="relations metric: POSES (timestamp x y theta) vs RELATIONS (t1 t2 x y z roll pitch yaw)",
        description="For each relation, error = relation ⊖ (pose(t1)^-1 ∘ pose(t2)); prints mean ± std of "
        "absolute translational (m) and rotational (deg) errors and the means of their squares. Relations "
        "whose timestamps match no pose are counted as not scored.",
    )
    r.add_argument("poses", help="poses file: 'timestamp x y theta' per line")
    r.add_argument("relations", help="relations file: 't1 t2 x y z roll pitch yaw' per line")
    r.add_argument("--tolerance", type=float, default=1e-3, help="timestamp match tolerance in s (default 0.001)")
    r.add_argument("--json", action="store_true", help="print one JSON object")
    r.set_defaults(func=_cmd_eval_relations)
    add_eval_map(esub)
