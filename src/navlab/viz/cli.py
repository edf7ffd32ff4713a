"""``navlab view``: rviz in a browser page, live on a launch or replaying a recording; and ``--view`` for other verbs.

Other verbs add the viewer with two calls: ``add_view_arguments(parser)`` when building their parser, and
``with viewing(args, run.executor): ...`` around their run.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from navlab.cli_common import (
    add_pose_arguments,
    add_resource_path_arguments,
    apply_resource_paths,
    positive_seconds,
    start_pose,
)
from navlab.ros1.cli import add_ros_argument, ros_bridge

DEFAULT_PORT = 8765


def add_server_arguments(p: argparse.ArgumentParser, *, prefix: str = "") -> None:
    """``--host``, ``--port`` (with ``prefix``: ``--view-host``, ``--view-port``), ``--no-browser``, ``--foxglove``."""
    p.add_argument(
        f"--{prefix}host",
        default="127.0.0.1",
        help="address to listen on (default 127.0.0.1: this machine only; anything else warns)",
    )
    p.add_argument(
        f"--{prefix}port",
        type=int,
        default=DEFAULT_PORT,
        help=f"port of the page and its WebSocket (default {DEFAULT_PORT}; 0 = any free port)",
    )
    p.add_argument("--no-browser", action="store_true", help="print the URL only, do not open a browser")
    p.add_argument("--foxglove", nargs="?", type=int, const=8766, default=None, metavar="PORT",
                   help="also serve the topics to Foxglove (its WebSocket protocol, ROS 2 schemas) on PORT "
                   "(default 8766); Foxglove's 3D panel can publish goals and initial poses")  # fmt: skip


def add_view_arguments(p: argparse.ArgumentParser) -> None:
    """``--view`` and its server options, for verbs that run a simulation."""
    p.add_argument("--view", action="store_true",
                   help="watch and command the run in a browser page (navlab view's viewer, paced at real time; "
                   "the page can pause and change the speed)")  # fmt: skip
    add_server_arguments(p, prefix="view-")


def start_viewer(args: argparse.Namespace, executor: Any, *, host: str, port: int, speed: float | None = None) -> Any:
    """Attach the viewer, print its URL (and a warning off loopback), open a browser where there is a desktop."""
    from navlab.viz.viewer import attach, host_warning, open_in_browser

    warning = host_warning(host)
    if warning:
        print(warning, file=sys.stderr)
    viewer = attach(executor, host=host, port=port, speed=speed, foxglove_port=getattr(args, "foxglove", None))
    print(f"viewer: {viewer.url}", file=sys.stderr, flush=True)
    if viewer.foxglove is not None:
        print(f"foxglove: ws://{host}:{viewer.foxglove.port} (open it in Foxglove: Open connection)", file=sys.stderr)
    if not getattr(args, "no_browser", False):
        open_in_browser(viewer.url)
    return viewer


@contextlib.contextmanager
def viewing(args: argparse.Namespace, executor: Any) -> Iterator[Any]:
    """With ``--view``: the viewer on ``executor`` while the block runs (None without ``--view``)."""
    if not getattr(args, "view", False):
        yield None
        return
    viewer = start_viewer(args, executor, host=args.view_host, port=args.view_port)
    try:
        yield viewer
    finally:
        viewer.close()


@contextlib.contextmanager
def view_hook(args: argparse.Namespace) -> Iterator[Any]:
    """With ``--view``: an ``on_start(run)`` for ``start_run`` (and the run functions that take one) that
    serves the viewer on each run it starts (the previous run's viewer closes); None without ``--view``."""
    if not getattr(args, "view", False):
        yield None
        return
    viewers: list[Any] = []

    def on_start(run: Any) -> None:
        while viewers:
            viewers.pop().close()  # the previous run has finished: its page reconnects to this one
        viewers.append(start_viewer(args, run.executor, host=args.view_host, port=args.view_port))

    try:
        yield on_start
    finally:
        for viewer in viewers:
            viewer.close()


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
        "--speed",
        type=float,
        default=1.0,
        help="simulated s per wall-clock s (default 1 = real time; 0 = as fast as possible)",
    )
    p.add_argument(
        "--duration",
        type=positive_seconds,
        default=None,
        help="stop after this many simulated s (default: until Ctrl-C)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--record", default=None, metavar="DIR", help="record every topic to a rosbag2 in DIR")
    add_server_arguments(p)
    add_resource_path_arguments(p)
    add_ros_argument(p, pace_option="--speed")
    p.set_defaults(func=_cmd_view)


def _cmd_view(args: argparse.Namespace) -> int:
    if args.bag:
        if args.ros:
            from navlab.viz.errors import VizError

            raise VizError("--ros serves a live launch, not a --bag replay (play the recording with `rosbag play`)")
        return _replay(args)
    apply_resource_paths(args)
    from navlab.core.launch import declared_args
    from navlab.core.runner import parse_launch_args
    from navlab.experiments.session import start_run

    launch_args: dict[str, Any] = parse_launch_args(args.args)
    world, robot = launch_args.pop("world", args.world), launch_args.pop("robot", args.robot)  # name:=value wins
    x, y, yaw = (float(launch_args.pop(k, v)) for k, v in zip(["x", "y", "yaw"], start_pose(args), strict=True))
    pose = (x, y, yaw)
    declared = {str(a.get("name")) for a in declared_args(args.launch)}
    with tempfile.TemporaryDirectory(prefix="navlab-view-") as tmp:
        if "map" in declared and "map" not in launch_args:
            launch_args["map"] = args.map or _true_map(world, pose, Path(tmp))
        run = start_run(args.launch, world=world, robot=robot, pose=pose, seed=args.seed, **launch_args)
    viewer = start_viewer(args, run.executor, host=args.host, port=args.port, speed=args.speed)
    try:
        with ros_bridge(args.ros, run.executor, run.session.nodes):
            run.run(args.duration or math.inf, record=args.record, quiet=True, desc="view")
    finally:
        viewer.close()
    return 0


def _true_map(world: str, pose: tuple[float, float, float], folder: Path) -> str:
    from navlab.experiments.truth import true_map
    from navlab.mapping.mapfile import save_map
    from navlab.sim.gazebo import load_world_named

    path = folder / "true_map.yaml"
    save_map(true_map(load_world_named(world), pose[:2]), path)
    return str(path)


def _replay(args: argparse.Namespace) -> int:
    import time

    from navlab.viz.hub import Hub
    from navlab.viz.replay import play_bag
    from navlab.viz.server import ViewerServer
    from navlab.viz.viewer import host_warning, open_in_browser

    warning = host_warning(args.host)
    if warning:
        print(warning, file=sys.stderr)
    hub = Hub()
    player = play_bag(args.bag, hub, speed=args.speed or 1.0)
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
