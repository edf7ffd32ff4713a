"""Mapping verbs: ``navlab map`` (SLAM in simulation, and ``map save``), ``navlab slam`` (offline SLAM on a
laser log) and ``navlab teleop`` (drive the robot by keyboard or joystick, as for mapping)."""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from pathlib import Path
from typing import Any

from navlab.cli.options import (
    add_pose_arguments,
    add_run_options,
    add_set_argument,
    add_world_robot,
    apply_resource_paths,
    parse_sets,
    positive_seconds,
    print_figures,
    start_pose,
)
from navlab.cli.runs import ros_hook, stop_signals, view_hook
from navlab.errors import interrupt_note


def _cmd_map(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    if args.action == "save":
        return _cmd_map_save(args)
    if args.teleop:
        _need_terminal("map --teleop")  # before the simulator starts
    from navlab.experiments import run_mapping

    driver = "teleop" if args.teleop else "route" if args.route else "explore"
    # Ctrl-C (or SIGTERM, also as a background job) ends the drive and saves the map so far; a second one quits
    with stop_signals() as stop, view_hook(args) as view, ros_hook(args, view) as then:
        try:
            result = run_mapping(
                world=args.world,
                robot=args.robot,
                pose=start_pose(args),
                out=args.out,
                driver=driver,
                route=args.route,
                duration=args.duration,
                mode=args.mode,
                seed=args.seed,
                rate=args.rate or 0.0,
                record=args.record,
                quiet=args.quiet,
                slam_params=parse_sets(args.set),
                on_start=stop.on_start(then, "stopping the drive; saving the map (Ctrl-C again: quit without saving)"),
            )
        except KeyboardInterrupt as exc:
            if not stop.requested:  # while the simulator was starting
                exc.add_note(f"nothing saved to {args.out}")
            raise
    if not args.json:
        stopped = "stopped by Ctrl-C: " if stop.requested else ""
        print(f"{stopped}saved {result.map_yaml} (+ map.pgm, map.png) after {result.sim_s:.1f} simulated s")
    print_figures(result.scores, args.json)
    return 0


def _need_terminal(verb: str) -> None:
    """Keyboard teleop reads keys from a terminal: one clear line when stdin is none (a pipe, a file)."""
    if not sys.stdin.isatty():
        from navlab.drivers import DriverError

        raise DriverError(
            f"navlab {verb} reads keys from a terminal (stdin is not one); run it in an interactive shell"
        )


@stop_signals()  # waiting for a /map, or running a launch: Ctrl-C and SIGTERM end it, also as a background job
def _cmd_map_save(args: argparse.Namespace) -> int:
    """map_saver: save the current ``/map`` of a running ``navlab launch``, or of one started here."""
    from navlab import msgs
    from navlab.core import parse_launch_args, run_for, start
    from navlab.grid import GridMap
    from navlab.mapping import MappingError, save_map

    path = Path(args.out) / "map.yaml"
    if not args.launch:  # the launch running in another shell: /map is latched, so its current map comes first
        from navlab.core import CoreError, find_running, subscribe

        try:
            running = find_running(args.pid)
        except CoreError as exc:
            if args.pid is not None or not str(exc).startswith("no running"):
                raise
            raise MappingError(  # map_saver's own hint: where a /map can come from
                "no running navlab launch to save a /map from: start one in another shell (navlab launch mapping), "
                "run one here (navlab map save --launch mapping --duration 60), or map in one command "
                "(navlab map --teleop: Ctrl-C saves)"
            ) from None
        for _t, msg in subscribe(running, "/map"):
            save_map(GridMap.from_msg(msg), path)
            print(f"saved {path}")
            return 0
    file, *items = args.launch
    session = start(file, seed=args.seed, launch_args=parse_launch_args(items))
    latest: list[Any] = []
    session.executor.add_listener(lambda topic, msg, _t: latest.append(msg) if topic == "/map" else None)
    run_for(session.executor, args.duration, quiet=args.quiet, desc="map save")
    maps = [m for m in latest if isinstance(m, msgs.OccupancyGrid)]
    if not maps:
        raise MappingError(f"the launch {file!r} published no /map in {args.duration} s (is a SLAM node running?)")
    save_map(GridMap.from_msg(maps[-1]), path)
    print(f"saved {path}")
    return 0


def _params_file(path: str | None) -> dict:
    if not path:
        return {}
    from navlab.core import read_yaml
    from navlab.mapping import MappingError

    doc = read_yaml(path) or {}  # a regular UTF-8 file of bounded size and nesting (no FIFO, no alias bomb)
    if not isinstance(doc, dict):
        raise MappingError(f"{path}: expected a mapping of parameter names to values")
    # accept ROS layouts: {node: {ros__parameters: {...}}} or {node: {...}}
    if len(doc) == 1 and isinstance(next(iter(doc.values())), dict):
        inner = next(iter(doc.values()))
        doc = inner.get("ros__parameters", inner)
    return doc


@stop_signals()  # SIGTERM as Ctrl-C, also as a background job: the note says what is written
def _cmd_slam(args: argparse.Namespace) -> int:
    from navlab.io import data_file, read_carmen, skipped_summary

    log = read_carmen(data_file(args.log))  # a bad log is reported before the SLAM's and the plots' imports

    from navlab.experiments import Track, plot_run, rounded
    from navlab.mapping import run_offline, write_outputs

    note = skipped_summary(log)
    if note:
        print(f"navlab slam: warning: {note}", file=sys.stderr)
    t0 = time.perf_counter()
    with interrupt_note(f"SLAM had not finished: nothing written to {args.out}"):
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
    # map.yaml + map.pgm, poses.txt, map.png in this order, each whole (temp name + rename) or not at all
    with interrupt_note(f"while writing {args.out}: its map.yaml, poses.txt and map.png are each whole or old"):
        paths = write_outputs(result, args.out)
        paths["figure"] = Path(args.out) / "map.png"
        plot_run(
            result.grid,
            [Track(result.poses, "SLAM trajectory", "r-", width=0.7)],
            paths["figure"],
            title=f"{log.path.name if log.path else ''} ({args.mode})",
            crop=False,
        )
    log_s = float(result.timestamps[-1] - result.timestamps[0])
    summary = rounded(
        {
            "scans": len(result.timestamps),
            "skipped_lines": len(log.skipped),
            "log_s": log_s,
            "wall_s": wall,
            "rtf": log_s / wall if wall > 0 else None,
            **result.stats,
            **{k: str(v) for k, v in paths.items()},
        }
    )
    if args.json or not args.quiet:
        print_figures(summary, args.json)
    return 0


# Ctrl-C and SIGTERM end it at once, also as a background job (SIGINT inherited ignored): while it starts with
# "navlab: interrupted", while it drives with the pose it stopped at
@stop_signals()
def _cmd_teleop(args: argparse.Namespace) -> int:
    """Drive the robot from the keyboard (teleop_twist_keyboard) or a joystick, in real time: the robot
    of a `navlab launch` running in another shell, or (with --world, or when none runs) a simulator
    started here."""
    if not args.joy:
        _need_terminal("teleop")  # before the simulator starts
    with contextlib.ExitStack() as stack:  # the terminal's settings come back, the remote publisher closes
        ex, gazebo, remote = _teleop_executor(args)
        if remote is not None:
            stack.callback(remote.close)
        if args.joy:
            from navlab import msgs
            from navlab.core import Node
            from navlab.drivers import JoyMapping, joystick_thread

            pub = Node(ex, name="teleop_twist_joy").create_publisher(msgs.Twist, "cmd_vel", 1)
            joystick_thread(ex, pub, JoyMapping(scale_linear=args.speed, scale_angular=args.turn))
            print("joystick: hold button 0 and move the left stick; Ctrl-C to quit")
        else:
            from navlab.drivers import HELP, TeleopKeyboard, terminal_keys

            teleop = TeleopKeyboard(ex, parameters={"speed": args.speed, "turn": args.turn})
            print(HELP)
            stack.enter_context(terminal_keys(teleop, ex))
            teleop.show_status(gazebo.sim.base_pose2d if gazebo is not None else None)
        with contextlib.suppress(KeyboardInterrupt):
            ex.spin()
    if gazebo is not None:
        x, y, yaw = gazebo.sim.base_pose2d()
        print(f"\nstopped at x={x:.2f} y={y:.2f} yaw={yaw:.2f} after {ex.now_ns / 1e9:.1f} simulated s")
    return 0


def _teleop_executor(args: argparse.Namespace) -> tuple[Any, Any, Any]:
    """The executor teleop publishes into: (executor, gazebo node or None, RemotePublisher or None)."""
    from navlab.core import CoreError, Executor, RemotePublisher, find_running
    from navlab.experiments import start_run

    remote = None
    if args.world is None:
        with contextlib.suppress(CoreError):
            remote = RemotePublisher(find_running(args.pid))
    if remote is not None:  # forward our cmd_vel into the running launch
        ex = Executor(seed=args.seed, rate=args.rate)
        ex.add_listener(lambda topic, msg, _t: remote.publish(topic, msg) if topic == "/cmd_vel" else None)
        print("driving the robot of the running navlab launch")
        return ex, None, remote
    run = start_run(  # the sim launch, here, in real time
        "sim", world=args.world or "room", robot=args.robot, pose=start_pose(args), seed=args.seed, rate=args.rate
    )
    return run.executor, run.gazebo, None


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``map``, ``slam`` and ``teleop``."""
    from navlab.resources import shipped

    p = sub.add_parser(
        "map",
        help="build a map with SLAM in simulation (exploration, teleop or a route) and save it",
        description="The paper's mapping launch: simulator + slam_gmapping + a driver. Saves DIR/map.yaml, "
        "DIR/map.pgm, DIR/map.png (map with SLAM and true trajectories) and DIR/trajectory.txt, and prints the "
        "map's score against the world. It ends when exploration is done, the route ends or --duration passes; "
        "Ctrl-C (or SIGTERM) ends it sooner and saves the map so far, as gmapping + map_saver would (a second "
        "Ctrl-C quits without saving). `navlab map save --out DIR` saves the current /map of a running "
        "`navlab launch` (map_saver); with --launch FILE it starts the launch itself.",
    )
    p.add_argument("action", nargs="?", choices=["save"], help="save: run a launch and save its /map")
    add_world_robot(p, "room")
    drive = p.add_mutually_exclusive_group()
    drive.add_argument("--explore", action="store_true", help="frontier exploration (the default)")
    drive.add_argument(
        "--teleop",
        action="store_true",
        help="drive with the keyboard (teleop_twist_keyboard's keys) in real time; Ctrl-C saves the map",
    )
    drive.add_argument(
        "--route",
        metavar="FILE",
        help=f"a route YAML (segments and/or waypoints) or a shipped route's name ({', '.join(shipped('route'))})",
    )
    p.add_argument("--out", default="map", metavar="DIR", help="output folder (default ./map)")
    p.add_argument(
        "--mode", default="gmapping", help="SLAM mode: gmapping, the paper's RBPF (default), or graph (pose graph)"
    )
    add_set_argument(p, "slam_gmapping", "particles=50")
    p.add_argument("--duration", type=positive_seconds, default=600.0, help="at most this many simulated s (600)")
    p.add_argument(
        "--launch",
        nargs="+",
        metavar=("FILE", "name:=value"),
        help="save: start this launch here and save its /map after --duration (default: save the "
        "/map of the `navlab launch` running in another shell)",
    )
    p.add_argument("--pid", type=int, help="save: which running navlab launch, when several run")
    add_run_options(p, seed=0, rate=None, record=True, quiet=True, json=True, view=True, ros=True)
    p.set_defaults(func=_cmd_map)

    p = sub.add_parser(
        "slam",
        help="run SLAM offline on a laser log and save the map and trajectory",
        description="Run SLAM on a CARMEN log (FLASER, ODOM, ROBOTLASER1 lines) and write DIR/map.yaml + "
        "DIR/map.pgm (map_server format), DIR/poses.txt (one 'timestamp x y theta' line per scan, robot "
        "pose in the map frame) and DIR/map.png (map and trajectory), and print a summary (not with --quiet).",
    )
    p.add_argument(
        "--log",
        required=True,
        metavar="FILE.clf",
        help="CARMEN log file, or its path inside $NAVLAB_DATA (e.g. mit-csail/mit-csail.clf)",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument(
        "--mode",
        default="gmapping",
        help="slam_gmapping's mode, a SLAM plugin: gmapping: the paper's Rao-Blackwellized particle filter "
        "(default, as in navlab map); graph: scan-to-map matching + loop closure + pose-graph optimisation",
    )
    p.add_argument(
        "--params", metavar="YAML", help="SLAM parameters: slam_gmapping's names (graph mode's own under 'graph:')"
    )
    add_set_argument(p, "slam_gmapping", "particles=50")
    p.add_argument("--resolution", type=float, default=0.05, help="map resolution in m/cell (default 0.05)")
    p.add_argument("--max-scans", type=int, default=None, help="only the first N scans")
    add_run_options(p, seed=0, quiet=True, json=True)
    p.set_defaults(func=_cmd_slam)

    p = sub.add_parser(
        "teleop",
        help="drive the robot from the keyboard (teleop_twist_keyboard) or a joystick",
        description="Publishes cmd_vel from keys (u i o / j k l / m , . to move, q/z w/x e/c to change speeds, "
        "k to stop, Ctrl-C to quit) into the `navlab launch` running in another shell, as "
        "teleop_twist_keyboard does next to a ROS launch (e.g. `navlab launch mapping explore:=false`). "
        "With --world, or when no launch runs, it starts the simulator here in real time.",
    )
    p.add_argument(
        "--world", default=None, help="start this world here (file or shipped name) instead of driving a running launch"
    )
    p.add_argument("--pid", type=int, help="which running navlab launch to drive, when several run")
    p.add_argument(
        "--robot", default="mybot", help=f"robot file or shipped name: {', '.join(shipped('robot'))} (default mybot)"
    )
    add_pose_arguments(p)
    p.add_argument("--speed", type=float, default=0.5, help="linear speed, m/s (default 0.5)")
    p.add_argument("--turn", type=float, default=1.0, help="angular speed, rad/s (default 1.0)")
    p.add_argument(
        "--joy",
        action="store_true",
        help="drive with the first joystick (pygame; teleop_twist_joy's axes and deadman button 0)",
    )
    add_run_options(p, seed=0, rate=1.0)
    p.set_defaults(func=_cmd_teleop)
