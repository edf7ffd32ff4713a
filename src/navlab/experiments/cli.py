"""``navlab map``, ``navlab teleop`` and ``navlab eval map``: the paper's mapping step in simulation."""

from __future__ import annotations

import argparse
import contextlib
import json
from pathlib import Path
from typing import Any

from navlab.core.runner import positive_seconds
from navlab.mapping.errors import MappingError


def _print_scores(scores: dict[str, Any], as_json: bool) -> None:
    if as_json:
        print(json.dumps(scores))
    else:
        for key, value in scores.items():
            print(f"  {key}: {value}")


def _cmd_map(args: argparse.Namespace) -> int:
    if args.action == "save":
        return _cmd_map_save(args)
    from navlab.mapping.run import run_mapping

    driver = "teleop" if args.teleop else "route" if args.route else "explore"
    result = run_mapping(
        world=args.world, robot=args.robot, out=args.out, driver=driver, route=args.route,
        duration=args.duration, mode=args.mode, seed=args.seed, rate=args.rate, record=args.record,
        quiet=args.quiet,
    )  # fmt: skip
    if not args.json:
        print(f"saved {result.map_yaml} (+ map.pgm, map.png) after {result.sim_seconds:.1f} simulated s")
    _print_scores(result.scores, args.json)
    return 0


def _cmd_map_save(args: argparse.Namespace) -> int:
    """map_saver: save the current ``/map`` of a running ``navlab launch``, or of one started here."""
    from navlab import msgs
    from navlab.core.launch import start
    from navlab.core.runner import parse_launch_args, run_for
    from navlab.grid import GridMap
    from navlab.mapping.mapfile import save_map

    path = Path(args.out) / "map.yaml"
    if not args.launch:  # the launch running in another shell: /map is latched, so its current map comes first
        from navlab.core.introspect import find_running, subscribe

        for _t, msg in subscribe(find_running(args.pid), "/map"):
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


def _cmd_teleop(args: argparse.Namespace) -> int:
    """Drive the robot from the keyboard (teleop_twist_keyboard) or a joystick, in real time: the robot
    of a `navlab launch` running in another shell, or (with --world, or when none runs) a simulator
    started here."""
    import sys

    from navlab.core import CoreError, Executor
    from navlab.core.introspect import RemotePublisher, find_running
    from navlab.mapping.teleop import HELP, TeleopKeyboard, terminal_keys
    from navlab.sim.gazebo import launch_sim

    ex = Executor(seed=args.seed, rate=args.rate)
    gazebo = remote = None
    if args.world is None:
        with contextlib.suppress(CoreError):
            remote = RemotePublisher(find_running(args.pid))
    if remote is not None:  # forward our cmd_vel into the running launch
        ex.add_listener(lambda topic, msg, _t: remote.publish(topic, msg) if topic == "/cmd_vel" else None)
        print("driving the robot of the running navlab launch")
    else:
        gazebo = launch_sim(ex, world=args.world or "room", robot=args.robot)
    if args.joy:
        from navlab import msgs
        from navlab.core import Node
        from navlab.mapping.teleop import JoyMapping, joystick_thread

        pub = Node(ex, name="teleop_twist_joy").create_publisher(msgs.Twist, "cmd_vel", 1)
        joystick_thread(ex, pub, JoyMapping(scale_linear=args.speed, scale_angular=args.turn))
        print("joystick: hold button 0 and move the left stick; Ctrl-C to quit")
    else:
        if not sys.stdin.isatty():
            raise MappingError("navlab teleop reads keys from a terminal; run it in an interactive shell")
        teleop = TeleopKeyboard(ex, parameters={"speed": args.speed, "turn": args.turn})
        print(HELP)
        terminal_keys(teleop, ex)
    with contextlib.suppress(KeyboardInterrupt):
        ex.spin()
    if remote is not None:
        remote.close()
    if gazebo is not None:
        x, y, yaw = gazebo.sim.base_pose2d()
        print(f"\nstopped at x={x:.2f} y={y:.2f} yaw={yaw:.2f} after {ex.now_ns / 1e9:.1f} simulated s")
    return 0


def cmd_eval_map(args: argparse.Namespace) -> int:
    """Score a saved map against a world's true occupancy (start pose known, no alignment)."""
    from navlab.mapping.evaluation import free_coverage, score_map, trajectory_error
    from navlab.mapping.mapfile import load_map
    from navlab.mapping.run import read_trajectory, true_occupancy
    from navlab.sim.gazebo import load_world_named

    grid = load_map(args.map)
    world = load_world_named(args.world)
    truth = true_occupancy(world, grid)
    start = tuple(args.start)
    scores = score_map(grid, truth, world_T_map=start)
    scores["coverage"] = round(free_coverage(grid, truth, world_T_map=start), 4)
    traj = Path(args.trajectory) if args.trajectory else Path(args.map).with_name("trajectory.txt")
    if args.trajectory or traj.is_file():
        est, true = read_trajectory(traj)
        scores.update(trajectory_error(est, true))
    _print_scores(scores, args.json)
    return 0


def add_eval_map(esub: argparse._SubParsersAction) -> None:
    """``navlab eval map MAP.yaml --world W``; called by the mapping CLI's ``eval`` verb."""
    m = esub.add_parser(
        "map",
        help="score a map against a simulated world's true occupancy",
        description="Occupied-cell precision and recall (a match within one cell), mean wall error and "
        "free-space coverage of a map_server map against the world's true occupancy at lidar height, and the "
        "SLAM trajectory's error against ground truth when a trajectory file is there. "
        "The map frame is the robot's start pose in the world (--start), so no alignment is searched.",
    )
    m.add_argument("map", help="map_server YAML file")
    m.add_argument("--world", required=True, help="world file or shipped name (room, room_obstacles)")
    m.add_argument("--start", nargs=3, type=float, default=(0.0, 0.0, 0.0), metavar=("X", "Y", "YAW"),
                   help="robot start pose in the world = the map frame (default 0 0 0)")  # fmt: skip
    m.add_argument("--trajectory", metavar="FILE",
                   help="SLAM vs true trajectory to score too (default: trajectory.txt beside the map, "
                   "as navlab map writes it)")  # fmt: skip
    m.add_argument("--json", action="store_true", help="print JSON")
    m.set_defaults(func=cmd_eval_map)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``map`` and ``teleop``."""
    p = sub.add_parser(
        "map",
        help="build a map with SLAM in simulation (exploration, teleop or a route) and save it",
        description="The paper's mapping launch: simulator + slam_gmapping + a driver. Saves DIR/map.yaml, "
        "DIR/map.pgm and DIR/map.png (map with SLAM and true trajectories) and prints the map's score "
        "against the world. `navlab map save --out DIR` saves the current /map of a running `navlab launch` "
        "(map_saver); with --launch FILE it starts the launch itself.",
    )
    p.add_argument("action", nargs="?", choices=["save"], help="save: run a launch and save its /map")
    p.add_argument("--world", default="room", help="world file or shipped name (default room)")
    p.add_argument("--robot", default="mybot", help="robot .xacro/.urdf or shipped name (default mybot)")
    drive = p.add_mutually_exclusive_group()
    drive.add_argument("--explore", action="store_true", help="frontier exploration (the default)")
    drive.add_argument("--teleop", action="store_true", help="drive with the keyboard, in real time")
    drive.add_argument("--route", metavar="FILE", help="a route YAML: segments and/or waypoints")
    p.add_argument("--out", default="map", help="output folder (default ./map)")
    p.add_argument("--mode", choices=["gmapping", "graph"], default="gmapping",
                   help="SLAM algorithm: the paper's RBPF (default) or pose-graph")  # fmt: skip
    p.add_argument("--duration", type=positive_seconds, default=600.0, help="at most this many simulated s (600)")
    p.add_argument("--rate", type=float, default=0.0, help="pacing: 0 = as fast as possible, 1 = real time")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--record", metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR")
    p.add_argument("--launch", nargs="+", metavar="FILE [name:=value]",
                   help="save: start this launch here and save its /map after --duration (default: save the "
                   "/map of the `navlab launch` running in another shell)")  # fmt: skip
    p.add_argument("--pid", type=int, help="save: which running navlab launch, when several run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the scores as JSON")
    p.set_defaults(func=_cmd_map)

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
    p.add_argument("--speed", type=float, default=0.5, help="linear speed, m/s (default 0.5)")
    p.add_argument("--turn", type=float, default=1.0, help="angular speed, rad/s (default 1.0)")
    p.add_argument("--rate", type=float, default=1.0, help="pacing (default 1 = real time)")
    p.add_argument("--joy", action="store_true",
                   help="drive with the first joystick (pygame; teleop_twist_joy's axes and deadman button 0)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.set_defaults(func=_cmd_teleop)
