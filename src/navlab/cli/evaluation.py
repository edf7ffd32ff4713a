"""``navlab eval``: score SLAM results — the relations metric (Kümmerle et al. 2009) and the absolute
trajectory error on logs, and a map against a simulated world's true occupancy."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from navlab.cli.options import (
    add_pose_arguments,
    add_resource_path_arguments,
    add_run_options,
    apply_resource_paths,
    print_figures,
    start_pose,
)

# relations_error's keys -> the CLI's JSON keys with unit suffixes (the old keys are printed too, deprecated)
DEPRECATED_RELATION_KEYS = {
    "trans_abs_mean": "trans_abs_mean_m",
    "trans_abs_std": "trans_abs_std_m",
    "trans_sq_mean": "trans_sq_mean_m2",
}


def _cmd_eval_relations(args: argparse.Namespace) -> int:
    from navlab.experiments import read_relations, read_trajectory, relations_closure, relations_error

    ts, poses = read_trajectory(args.poses, carmen=args.carmen)
    from navlab.io import data_file

    rel = read_relations(data_file(args.relations))
    out = relations_error(ts, poses, rel, time_tolerance=args.tolerance)
    closure = relations_closure(rel, time_tolerance=args.tolerance)
    out.update({f"reference_{k}": v for k, v in closure.items()})
    for old, new in DEPRECATED_RELATION_KEYS.items():  # unit suffixes as everywhere; the old names stay one release
        if old in out:
            out[new] = out[old]
    if args.json:
        print_figures(out, True)
    else:
        print(f"relations scored: {out['n_scored']} of {out['n_relations']}")
        print(f"translation: {out['trans_abs_mean']:.4f} ± {out['trans_abs_std']:.4f} m")
        print(f"rotation:    {out['rot_abs_mean_deg']:.3f} ± {out['rot_abs_std_deg']:.3f} deg")
        if closure["n_triangles"]:
            n, median, floor = closure["n_triangles"], closure["closure_median_m"], closure["noise_floor_m"]
            print(
                f"the relations' own {n} triangles close to {median:.4f} m median: with independent errors, "
                f"poses without error would score about {floor:.4f} m"
            )
    return 0


def _cmd_eval_trajectory(args: argparse.Namespace) -> int:
    from navlab.experiments import read_trajectory, trajectory_ate

    est = read_trajectory(args.estimate, carmen=args.carmen)
    truth = read_trajectory(
        args.truth or args.estimate, carmen=args.carmen_truth, columns="estimate" if args.truth else "truth"
    )
    out = trajectory_ate(est, truth, tolerance=args.tolerance, align=not args.no_align, far=args.far)
    if args.json:
        print_figures(out, True)
    else:
        print(f"poses compared: {out['poses']} ({out['n_estimated']} estimated, {out['n_truth']} true)")
        print(f"ATE RMSE {out['rmse_m']:.4f} m, mean {out['mean_m']:.4f} m, max {out['max_m']:.4f} m")
        print(
            f"poses off by > {args.far} m: {100 * out['share_over_far']:.1f} %; mean yaw error "
            f"{out['yaw_mean_deg']:.3f} deg"
        )
    return 0


def _cmd_eval_map(args: argparse.Namespace) -> int:
    """Score a saved map against a world's true occupancy (start pose known, no alignment)."""
    from navlab.description import load_robot_named
    from navlab.experiments import free_coverage, read_map_trajectory, rounded, score_map, trajectory_error
    from navlab.mapping import load_map
    from navlab.world import load_world, true_occupancy, world_T_map

    apply_resource_paths(args)
    grid = load_map(args.map)
    truth = true_occupancy(load_world(args.world), grid)
    start = start_pose(args)
    map_in_world = world_T_map(load_robot_named(args.robot), start)  # the odometry source decides
    scores: dict[str, Any] = {"map_frame_in_world": list(map_in_world)}
    scores.update(score_map(grid, truth, world_T_map=map_in_world, start_xy=start[:2]))
    scores["coverage"] = free_coverage(grid, truth, world_T_map=map_in_world, start_xy=start[:2])
    traj = Path(args.trajectory) if args.trajectory else Path(args.map).with_name("trajectory.txt")
    if args.trajectory or traj.is_file():
        est, true = read_map_trajectory(traj)
        scores.update(trajectory_error(est, true))
    print_figures(rounded(scores), args.json)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``eval relations``, ``eval trajectory`` and ``eval map``."""
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
        "whose timestamps match no pose are counted as not scored. Also how far the relations' own triangles "
        "(a→b, b→c, a→c) fail to close, and the score that implies for poses without error (reference_*). "
        "JSON keys carry their units (trans_abs_mean_m, rot_abs_mean_deg, ...); trans_abs_mean, trans_abs_std "
        "and trans_sq_mean are deprecated aliases kept for one release.",
    )
    r.add_argument(
        "poses",
        help="poses file: 'timestamp x y theta' per line, a TUM file, or a CARMEN log (its own odometry: see --carmen)",
    )
    r.add_argument(
        "--carmen",
        choices=("flaser", "odom", "laser"),
        default="flaser",
        help="poses of a CARMEN log: flaser = the robot's odometry pose of each scan (default), "
        "odom = ODOM lines, laser = the laser's pose of each scan",
    )
    r.add_argument(
        "relations",
        help="relations file: 't1 t2 x y z roll pitch yaw' per line, or its path inside "
        "$NAVLAB_DATA (e.g. mit-csail/mit-csail.relations)",
    )
    r.add_argument("--tolerance", type=float, default=1e-3, help="timestamp match tolerance in s (default 0.001)")
    add_run_options(r, json=True)
    r.set_defaults(func=_cmd_eval_relations)
    t = esub.add_parser(
        "trajectory",
        help="absolute trajectory error: EST vs TRUTH after rigid SE(2) alignment (RMSE, max, share > 0.5 m)",
        description="Pairs EST's poses with TRUTH's by nearest timestamp (within --tolerance), aligns EST to "
        "TRUTH by the rigid 2-D transform minimising the squared position error (Umeyama/Horn, no scale) "
        "and prints the position error's RMSE, mean, median and max (m), the share of poses off by more "
        "than --far m, and the mean yaw error (deg). Files: 't x y theta' (navlab slam's poses.txt, TUM "
        "2-D), 't x y z qx qy qz qw' (TUM), CARMEN logs (see --carmen), and navlab map's trajectory.txt "
        "('t x y theta true_x true_y true_theta': without TRUTH its true columns are the truth).",
    )
    t.add_argument("estimate", metavar="EST", help="estimated trajectory file")
    t.add_argument(
        "truth",
        metavar="TRUTH",
        nargs="?",
        help="reference trajectory file (default: EST's true columns, for navlab map's trajectory.txt)",
    )
    t.add_argument(
        "--carmen",
        choices=("flaser", "odom", "laser"),
        default="flaser",
        help="poses of EST when it is a CARMEN log (default flaser: the robot pose of each scan)",
    )
    t.add_argument(
        "--carmen-truth",
        choices=("flaser", "odom", "laser"),
        default="flaser",
        help="poses of TRUTH when it is a CARMEN log (default flaser)",
    )
    t.add_argument("--tolerance", type=float, default=0.02, help="timestamp match tolerance in s (default 0.02)")
    t.add_argument("--far", type=float, default=0.5, help="error (m) counted as far off (default 0.5)")
    t.add_argument("--no-align", action="store_true", help="compare the poses as given (no rigid alignment)")
    add_run_options(t, json=True)
    t.set_defaults(func=_cmd_eval_trajectory)
    m = esub.add_parser(
        "map",
        help="score a map against a simulated world's true occupancy",
        description="Occupied-cell precision and recall (a match within one cell), mean wall error and "
        "free-space coverage of a map_server map against the world's true occupancy at lidar height, and the "
        "SLAM trajectory's error against ground truth when a trajectory file is there. "
        "The map frame is SLAM's odom frame at the start, decided by the robot's odometry source as navlab map "
        "does: the world frame for <odometrySource>world (Gazebo's default), the start pose (--x --y --yaw) for "
        "encoder odometry; so no alignment is searched.",
    )
    m.add_argument("map", help="map_server YAML file")
    m.add_argument("--world", required=True, help="world file or shipped name (room, room_obstacles)")
    m.add_argument(
        "--robot",
        default="mybot",
        help="the robot that mapped: .xacro/.urdf or shipped name (default mybot); its diff-drive "
        "odometry source decides the map frame",
    )
    add_pose_arguments(m, "robot start")
    add_resource_path_arguments(m)
    m.add_argument(
        "--trajectory",
        metavar="FILE",
        help="SLAM vs true trajectory to score too (default: trajectory.txt beside the map, as navlab map writes it)",
    )
    add_run_options(m, json=True)
    m.set_defaults(func=_cmd_eval_map)
