"""CLI verbs of the mapping package: ``navlab teleop``, ``navlab slam`` (offline SLAM on a log) and ``navlab eval``."""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from pathlib import Path
from typing import Any

from navlab.cli_common import add_pose_arguments, add_set_argument, parse_sets, print_figures, start_pose
from navlab.experiments.cli import add_eval_map


def _params_file(path: str | None) -> dict:
    if not path:
        return {}
    from navlab.core.params import read_yaml
    from navlab.mapping.errors import MappingError

    doc = read_yaml(path) or {}  # a regular UTF-8 file of bounded size and nesting (no FIFO, no alias bomb)
    if not isinstance(doc, dict):
        raise MappingError(f"{path}: expected a mapping of parameter names to values")
    # accept ROS layouts: {node: {ros__parameters: {...}}} or {node: {...}}
    if len(doc) == 1 and isinstance(next(iter(doc.values())), dict):
        inner = next(iter(doc.values()))
        doc = inner.get("ros__parameters", inner)
    return doc


def _cmd_slam(args: argparse.Namespace) -> int:
    from navlab.io.carmen import read_carmen, skipped_summary
    from navlab.io.datasets import data_file

    log = read_carmen(data_file(args.log))  # a bad log is reported before the SLAM's and the plots' imports

    from navlab.experiments.plots import Track, plot_run
    from navlab.experiments.session import rounded
    from navlab.mapping.slam import run_offline, write_outputs

    note = skipped_summary(log)
    if note:
        print(f"navlab slam: warning: {note}", file=sys.stderr)
    t0 = time.perf_counter()
    result = run_offline(
        log,
        mode=args.mode,
        params={**_params_file(args.params), **parse_sets(args.set)},
        seed=args.seed,
        resolution=args.resolution,
        max_scans=args.max_scans,
        progress=not args.quiet and sys.stderr.isatty(),
    )
    wall = time.perf_counter() - t0
    paths = write_outputs(result, args.out)
    paths["figure"] = Path(args.out) / "map.png"
    plot_run(result.grid, [Track(result.poses, "SLAM trajectory", "r-", width=0.7)], paths["figure"],
             title=f"{log.path.name if log.path else ''} ({args.mode})", crop=False)  # fmt: skip
    log_s = float(result.timestamps[-1] - result.timestamps[0])
    summary = rounded({
        "scans": len(result.timestamps),
        "skipped_lines": len(log.skipped),
        "log_s": log_s,
        "wall_s": wall,
        "rtf": log_s / wall if wall > 0 else None,
        **result.stats,
        **{k: str(v) for k, v in paths.items()},
    })  # fmt: skip
    if args.json or not args.quiet:
        print_figures(summary, args.json)
    return 0


def _cmd_teleop(args: argparse.Namespace) -> int:
    """Drive the robot from the keyboard (teleop_twist_keyboard) or a joystick, in real time: the robot
    of a `navlab launch` running in another shell, or (with --world, or when none runs) a simulator
    started here."""
    from navlab.core import CoreError, Executor
    from navlab.core.introspect import RemotePublisher, find_running
    from navlab.drivers import HELP, TeleopKeyboard, terminal_keys
    from navlab.experiments.session import start_run

    gazebo = remote = None
    if args.world is None:
        with contextlib.suppress(CoreError):
            remote = RemotePublisher(find_running(args.pid))
    if remote is not None:  # forward our cmd_vel into the running launch
        ex = Executor(seed=args.seed, rate=args.rate)
        ex.add_listener(lambda topic, msg, _t: remote.publish(topic, msg) if topic == "/cmd_vel" else None)
        print("driving the robot of the running navlab launch")
    else:  # the sim launch, here, in real time
        run = start_run("sim", world=args.world or "room", robot=args.robot, pose=start_pose(args), seed=args.seed,
                        pace=args.rate)  # fmt: skip
        ex, gazebo = run.executor, run.gazebo
    if args.joy:
        from navlab import msgs
        from navlab.core import Node
        from navlab.drivers import JoyMapping, joystick_thread

        pub = Node(ex, name="teleop_twist_joy").create_publisher(msgs.Twist, "cmd_vel", 1)
        joystick_thread(ex, pub, JoyMapping(scale_linear=args.speed, scale_angular=args.turn))
        print("joystick: hold button 0 and move the left stick; Ctrl-C to quit")
    else:
        if not sys.stdin.isatty():
            from navlab.mapping.errors import MappingError

            raise MappingError("navlab teleop reads keys from a terminal; run it in an interactive shell")
        teleop = TeleopKeyboard(ex, parameters={"speed": args.speed, "turn": args.turn})
        print(HELP)
        terminal_keys(teleop, ex)
        teleop.create_timer(0.25, lambda: _show_teleop(teleop, gazebo))
    with contextlib.suppress(KeyboardInterrupt):
        ex.spin()
    if remote is not None:
        remote.close()
    if gazebo is not None:
        x, y, yaw = gazebo.sim.base_pose2d()
        print(f"\nstopped at x={x:.2f} y={y:.2f} yaw={yaw:.2f} after {ex.now_ns / 1e9:.1f} simulated s")
    return 0


# relations_error's keys -> the CLI's JSON keys with unit suffixes (the old keys are printed too, deprecated)
DEPRECATED_RELATION_KEYS = {"trans_abs_mean": "trans_abs_mean_m", "trans_abs_std": "trans_abs_std_m",
                            "trans_sq_mean": "trans_sq_mean_m2"}


def _show_teleop(teleop: Any, gazebo: Any) -> None:
    """One status line, rewritten in place on stderr: simulated time, the command being sent, the speeds (and
    the robot's pose when the simulator runs here), as teleop_twist_keyboard prints its 'currently:' line."""
    st, tw = teleop.state, teleop.state.twist()
    where = ""
    if gazebo is not None:
        x, y, yaw = gazebo.sim.base_pose2d()
        where = f"  robot at ({x:.2f}, {y:.2f}, {yaw:.2f} rad)"
    sys.stderr.write(f"\rt={teleop.executor.now_ns / 1e9:7.1f} s  sending linear.x {tw.linear.x:+.2f} m/s  angular.z "
                     f"{tw.angular.z:+.2f} rad/s  (currently: speed {st.speed:.2f} turn {st.turn:.2f}){where}  ")
    sys.stderr.flush()


def _cmd_eval_relations(args: argparse.Namespace) -> int:
    from navlab.experiments.metrics import read_relations, relations_closure, relations_error
    from navlab.experiments.trajectory import read_trajectory

    ts, poses = read_trajectory(args.poses, carmen=args.carmen)
    from navlab.io.datasets import data_file

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
            print(f"the relations' own {n} triangles close to {median:.4f} m median: with independent errors, "
                  f"poses without error would score about {floor:.4f} m")  # fmt: skip
    return 0


def _cmd_eval_trajectory(args: argparse.Namespace) -> int:
    from navlab.experiments.trajectory import read_trajectory, trajectory_ate

    est = read_trajectory(args.estimate, carmen=args.carmen)
    truth = read_trajectory(args.truth or args.estimate, carmen=args.carmen_truth,
                            columns="estimate" if args.truth else "truth")  # fmt: skip
    out = trajectory_ate(est, truth, tolerance=args.tolerance, align=not args.no_align, far=args.far)
    if args.json:
        print_figures(out, True)
    else:
        print(f"poses compared: {out['poses']} ({out['n_estimated']} estimated, {out['n_truth']} true)")
        print(f"ATE RMSE {out['rmse_m']:.4f} m, mean {out['mean_m']:.4f} m, max {out['max_m']:.4f} m")
        print(f"poses off by > {args.far} m: {100 * out['share_over_far']:.1f} %; mean yaw error "
              f"{out['yaw_mean_deg']:.3f} deg")  # fmt: skip
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``teleop``, ``slam`` and ``eval`` verbs."""
    p = sub.add_parser(
        "teleop",
        help="drive the robot from the keyboard (teleop_twist_keyboard) or a joystick",
        description="Publishes cmd_vel from keys (u i o / j k l / m , . to move, q/z w/x e/c to change speeds, "
        "k to stop, Ctrl-C to quit) into the `navlab launch` running in another shell, as "
        "teleop_twist_keyboard does next to a ROS launch (e.g. `navlab launch mapping explore:=false`). "
        "With --world, or when no launch runs, it starts the simulator here in real time.",
    )
    p.add_argument("--world", default=None,
                   help="start this world here (file or shipped name) instead of driving a running launch")
    p.add_argument("--pid", type=int, help="which running navlab launch to drive, when several run")
    p.add_argument("--robot", default="mybot", help="robot file or shipped name (default mybot)")
    add_pose_arguments(p)
    p.add_argument("--speed", type=float, default=0.5, help="linear speed, m/s (default 0.5)")
    p.add_argument("--turn", type=float, default=1.0, help="angular speed, rad/s (default 1.0)")
    p.add_argument("--rate", type=float, default=1.0, help="pacing (default 1 = real time)")
    p.add_argument("--joy", action="store_true",
                   help="drive with the first joystick (pygame; teleop_twist_joy's axes and deadman button 0)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.set_defaults(func=_cmd_teleop)

    p = sub.add_parser(
        "slam",
        help="run SLAM offline on a laser log and save the map and trajectory",
        description="Run SLAM on a CARMEN log (FLASER, ODOM, ROBOTLASER1 lines) and write DIR/map.yaml + "
        "DIR/map.pgm (map_server format), DIR/poses.txt (one 'timestamp x y theta' line per scan, robot "
        "pose in the map frame) and DIR/map.png (map and trajectory).",
    )
    p.add_argument("--log", required=True, metavar="FILE.clf",
                   help="CARMEN log file, or its path inside $NAVLAB_DATA (e.g. mit-csail/mit-csail.clf)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument(
        "--mode",
        default="gmapping",
        help="slam_gmapping's mode, a SLAM plugin: gmapping: the paper's Rao-Blackwellized particle filter "
        "(default, as in navlab map); graph: scan-to-map matching + loop closure + pose-graph optimisation",
    )
    p.add_argument("--params", metavar="YAML", help="SLAM parameters: slam_gmapping's names (graph mode's own "
                   "under 'graph:')")
    add_set_argument(p, "slam_gmapping", "particles=50")
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
        "whose timestamps match no pose are counted as not scored. Also how far the relations' own triangles "
        "(a→b, b→c, a→c) fail to close, and the score that implies for poses without error (reference_*). "
        "JSON keys carry their units (trans_abs_mean_m, rot_abs_mean_deg, ...); trans_abs_mean, trans_abs_std "
        "and trans_sq_mean are deprecated aliases kept for one release.",
    )
    r.add_argument("poses", help="poses file: 'timestamp x y theta' per line, a TUM file, or a CARMEN log "
                   "(its own odometry: see --carmen)")
    r.add_argument("--carmen", choices=("flaser", "odom", "laser"), default="flaser",
                   help="poses of a CARMEN log: flaser = the robot's odometry pose of each scan (default), "
                   "odom = ODOM lines, laser = the laser's pose of each scan")
    r.add_argument("relations", help="relations file: 't1 t2 x y z roll pitch yaw' per line, or its path inside "
                   "$NAVLAB_DATA (e.g. mit-csail/mit-csail.relations)")
    r.add_argument("--tolerance", type=float, default=1e-3, help="timestamp match tolerance in s (default 0.001)")
    r.add_argument("--json", action="store_true", help="print one JSON object")
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
    t.add_argument("truth", metavar="TRUTH", nargs="?", help="reference trajectory file (default: EST's true "
                   "columns, for navlab map's trajectory.txt)")
    t.add_argument("--carmen", choices=("flaser", "odom", "laser"), default="flaser",
                   help="poses of EST when it is a CARMEN log (default flaser: the robot pose of each scan)")
    t.add_argument("--carmen-truth", choices=("flaser", "odom", "laser"), default="flaser",
                   help="poses of TRUTH when it is a CARMEN log (default flaser)")
    t.add_argument("--tolerance", type=float, default=0.02, help="timestamp match tolerance in s (default 0.02)")
    t.add_argument("--far", type=float, default=0.5, help="error (m) counted as far off (default 0.5)")
    t.add_argument("--no-align", action="store_true", help="compare the poses as given (no rigid alignment)")
    t.add_argument("--json", action="store_true", help="print one JSON object")
    t.set_defaults(func=_cmd_eval_trajectory)
    add_eval_map(esub)


def _cmd_world_office(args: argparse.Namespace) -> int:
    from navlab.cli_common import optional_out, out_file
    from navlab.experiments.session import rounded
    from navlab.io.carmen import write_carmen
    from navlab.io.poses import write_poses
    from navlab.mapping.simlog import OdometryNoise, record_log
    from navlab.world.office import generate_office

    office = generate_office()
    world = office.write_world(out_file(args.out, "office.world", old_suffixes=(".world", ".sdf")))
    log = optional_out(args.log, world.parent, "office.clf")
    truth = optional_out(args.truth, world.parent, "truth.txt")
    summary: dict = {"world": str(world), "width_m": office.width, "depth_m": office.depth, "rooms": office.rooms,
                     "start": list(office.start)}  # fmt: skip
    if log:
        rec = record_log(world, office.route(), seed=args.seed, noise=OdometryNoise(scale=args.odom_scale,
                         heading_drift=args.heading_drift))  # fmt: skip
        write_carmen(log, rec.log, comment=f"navlab office log, seed {args.seed}: odometry frame = the true "
                     f"start pose {rec.start} in {world.name}")  # fmt: skip
        summary.update(log=str(log), scans=len(rec.log.scans), log_s=rec.log.duration)
        if truth:
            from navlab.experiments.trajectory import apply_se2
            from navlab.geometry import inverse2

            # the truth in the log's odometry frame (the start pose), as the SLAM output is
            write_poses(truth, rec.timestamps, apply_se2(tuple(inverse2(rec.start)), rec.truth))
            summary["truth"] = str(truth)
    print_figures(rounded(summary), args.json)
    return 0


def add_world_office(verbs: argparse._SubParsersAction) -> None:
    """``navlab world office``: the generated office floor, and a sparse log recorded in it."""
    o = verbs.add_parser(
        "office",
        help="an office floor (30 x 20.5 m, 28 alike rooms, corridors closing two loops) and a sparse log in it",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Writes the generated office floor as a .world file. With --log, drives the robot around "
        "both loops\n(and into two rooms) in the simulator and records a sparse laser log: a scan every 1 m "
        "or 0.5 rad,\n181 beams over 180 degrees, wheel odometry with --odom-scale scale errors and heading "
        "drift.\nThe log's odometry frame is the robot's true start pose; --truth writes the true poses in it.",
        epilog="examples:\n"
        "  navlab world office --out office --log --truth --seed 1   # office/office.world, office.clf, truth.txt\n"
        "  navlab slam --log office/office.clf --out office_map --mode gmapping\n"
        "  navlab eval trajectory office_map/poses.txt office/truth.txt",
    )
    o.add_argument("--out", required=True, metavar="DIR",
                   help="folder to write office.world in (a FILE.world still works this release, deprecated)")
    o.add_argument("--log", nargs="?", const="", metavar="FILE.clf",
                   help="also record a sparse CARMEN log: in FILE.clf, or DIR/office.clf without a value")
    o.add_argument("--truth", nargs="?", const="", metavar="FILE.txt",
                   help="with --log: the true poses ('t x y theta', log frame) in FILE.txt, or DIR/truth.txt")
    o.add_argument("--seed", type=int, default=0, help="random seed of the lidar and odometry noise (default 0)")
    o.add_argument("--odom-scale", type=float, default=0.05,
                   help="std. dev. of the odometry's scale errors and per-step noise (default 0.05: 5 %%)")
    o.add_argument("--heading-drift", type=float, default=0.02,
                   help="std. dev. of the odometry's heading drift rate, rad/m (default 0.02)")
    o.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    o.set_defaults(func=_cmd_world_office)
