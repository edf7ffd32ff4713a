"""``navlab view``: rviz in a browser page, live on a launch or replaying a recording.

Other verbs add the viewer with two calls: ``add_run_options(parser, view=True)`` (:mod:`navlab.cli.options`) when
building their parser, and ``with viewing(args, run.executor): ...`` (:mod:`navlab.cli.runs`) around their run.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path
from typing import Any

from navlab.cli.options import (
    DeprecatedAlias,
    add_pose_arguments,
    add_resource_path_arguments,
    add_ros_argument,
    add_run_options,
    add_server_arguments,
    apply_resource_paths,
    pace,
    positive_seconds,
    start_pose,
)
from navlab.cli.runs import ros_bridge, start_viewer, stop_signals


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``view`` verb."""
    p = sub.add_parser(
        "view",
        help="rviz in a browser page: watch a launch live (goals, initial pose, teleop, obstacles) or replay a bag",
        description="Start a launch (default: navigation in room_obstacles on the world's true map) and serve a "
        "page that shows it live in simulated time: map, costmaps, scan, particles, plans, goal, traces, tf; "
        "with rviz's tools (2D Pose Estimate, 2D Nav Goal), teleop keys, obstacles placed by click, pause and "
        "speed, and the node graph. With --bag DIR, replay a recording with a timeline instead.",
    )
    p.add_argument("args", nargs="*", metavar="NAME:=VALUE", help="launch arguments (ROS syntax)")
    p.add_argument("--launch", default="navigation", help="shipped launch or launch file (default navigation)")
    p.add_argument("--world", default="room_obstacles", help="shipped world or .world file (default room_obstacles)")
    p.add_argument("--robot", default="mybot", help="shipped robot or .xacro/.urdf file (default mybot)")
    add_pose_arguments(p)
    p.add_argument("--map", default=None, help="map YAML for launches that take one (default: the world's true map)")
    p.add_argument("--bag", default=None, metavar="DIR", help="replay this rosbag2 recording instead of a launch")
    p.add_argument(
        "--duration",
        type=positive_seconds,
        default=None,
        help="stop after this many simulated s (default: until Ctrl-C)",
    )
    add_run_options(p, seed=0, record=True, rate=1.0)
    p.add_argument("--speed", dest="rate", type=pace, action=DeprecatedAlias, new="--rate", help=argparse.SUPPRESS)
    add_server_arguments(p)
    add_resource_path_arguments(p)
    add_ros_argument(p)
    p.set_defaults(func=_cmd_view)


@stop_signals()  # Ctrl-C and SIGTERM end it (the recording closed), also as a background job
def _cmd_view(args: argparse.Namespace) -> int:
    if args.bag:
        if args.ros:
            from navlab.viz import VizError

            raise VizError("--ros serves a live launch, not a --bag replay (play the recording with `rosbag play`)")
        return _replay(args)
    apply_resource_paths(args)
    from navlab.core import declared_args, parse_launch_args
    from navlab.experiments import start_run
    from navlab.mapping import save_true_map

    launch_args: dict[str, Any] = parse_launch_args(args.args)
    world, robot = launch_args.pop("world", args.world), launch_args.pop("robot", args.robot)  # name:=value wins
    x, y, yaw = (float(launch_args.pop(k, v)) for k, v in zip(["x", "y", "yaw"], start_pose(args), strict=True))
    pose = (x, y, yaw)
    declared = {str(a.get("name")) for a in declared_args(args.launch)}
    with tempfile.TemporaryDirectory(prefix="navlab-view-") as tmp:
        if "map" in declared and "map" not in launch_args:
            launch_args["map"] = args.map or str(save_true_map(world, pose[:2], Path(tmp) / "true_map.yaml"))
        run = start_run(args.launch, world=world, robot=robot, pose=pose, seed=args.seed, **launch_args)
    viewer = start_viewer(args, run.executor, host=args.host, port=args.port, rate=args.rate)
    try:
        with ros_bridge(args.ros, run.executor, run.session.nodes):
            run.run(args.duration or math.inf, record=args.record, quiet=True, desc="view")
    finally:
        viewer.close()
    return 0


def _replay(args: argparse.Namespace) -> int:
    import time

    from navlab.viz import Hub, ViewerServer, host_warning, open_in_browser, play_bag

    warning = host_warning(args.host)
    if warning:
        print(warning, file=sys.stderr)
    hub = Hub()
    player = play_bag(args.bag, hub, rate=args.rate or 1.0)
    server = ViewerServer(hub, host=args.host, port=args.port)
    server.start()
    print(f"viewer: {server.url} (replaying {args.bag})", file=sys.stderr, flush=True)
    if not args.no_browser:
        open_in_browser(server.url)
    try:
        end = time.monotonic() + args.duration if args.duration else math.inf
        while time.monotonic() < end:
            time.sleep(0.2)
    finally:
        player.close()
        server.close()
    return 0
