"""Launch verbs: ``navlab launch`` / ``navlab roslaunch`` (ROS 2 YAML or ROS 1 XML launch files) and
``navlab run FILE.py`` (an rclpy-style node file in a launch's simulation)."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
from pathlib import Path
from typing import Any

from navlab.cli.options import add_resource_path_arguments, add_run_options, apply_resource_paths, positive_seconds
from navlab.cli.runs import stop_signals


def _show_args(file: str) -> int:
    from navlab.core import declared_args

    rows = declared_args(file)
    if not rows:
        print(f"{file}: no arguments")
    for a in rows:
        text = str(a.get("description", ""))
        default = f" (default: {a['default']!r})" if "default" in a else " (required)"
        if "(default:" in text:  # the description says it in words (e.g. the robot's own frame), not '$(robot ...)'
            default = ""
        print(f"  '{a.get('name')}':\n      {text}{default}")
    return 0


def _split_files(first: str, items: list[str]) -> tuple[list[str], list[str]]:
    """``FILE [FILE ...] name:=value ...``: the launch files and the arguments (as roslaunch takes them)."""
    files = [first] + [i for i in items if ":=" not in i]
    return files, [i for i in items if ":=" in i]


def find_in_package(pkg: str, name: str) -> Path:
    """roslaunch's ``roslaunch PKG FILE``: the file called ``name`` anywhere inside package ``pkg``."""
    from navlab.core import LaunchError
    from navlab.description import DescriptionError, find_package

    try:
        root = find_package(pkg)
    except DescriptionError as exc:
        raise LaunchError(str(exc)) from None
    found = sorted(p for p in root.rglob(name) if p.is_file() and not any(s.startswith(".") for s in p.parts))
    if not found:
        raise LaunchError(f"[{name}] is neither a launch file in package [{pkg}] ({root}) nor a launch file name")
    if len(found) > 1:
        raise LaunchError(f"[{name}] is ambiguous in package [{pkg}]: {', '.join(map(str, found))}")
    return found[0]


def _cmd_roslaunch(args: argparse.Namespace) -> int:
    apply_resource_paths(args)
    if not Path(args.file).is_file() and args.args and ":=" not in args.args[0]:
        args.file, args.args = str(find_in_package(args.file, args.args[0])), args.args[1:]
    return _cmd_launch(args)


@stop_signals()  # Ctrl-C and SIGTERM end it cleanly, also as a background job (SIGINT inherited ignored)
def _cmd_launch(args: argparse.Namespace) -> int:
    from navlab.core import parse_launch_args, run_for, start  # (not at import: --help loads no numpy)

    if args.show_args:
        return _show_args(args.file)
    apply_resource_paths(args)  # --package-path / --model-path for robot:= and world:=
    # Like roslaunch, a launch without --duration runs in real time until Ctrl-C.
    from navlab.cli.runs import follows_clock, pop_ros_arg, ros_bridge

    files, items = _split_files(args.file, args.args)
    launch_args = parse_launch_args(items)
    ros = pop_ros_arg(launch_args) or args.ros  # outside nodes cannot follow 100x: real time unless --rate
    rate = args.rate if args.rate is not None else (1.0 if args.duration is None or ros else 0.0)
    follow_clock = ros and follows_clock(launch_args)  # hardware in the loop: the robot's /clock paces the run
    rate = 0.0 if follow_clock else rate
    session = start(files, seed=args.seed, rate=rate, launch_args=launch_args, ros=ros)
    ex = session.executor
    duration = math.inf if args.duration is None else args.duration
    # `navlab topic/node/graph` in another shell look into this launch while it runs; SIGTERM ends it
    # cleanly like Ctrl-C (the recording is closed, the socket removed), also as a background job
    from navlab.cli.runs import viewing
    from navlab.core import IntrospectionServer

    with (
        IntrospectionServer(ex, name=args.file),
        contextlib.suppress(KeyboardInterrupt),
        viewing(args, ex),
        ros_bridge(ros, ex, session.nodes, follow_clock=follow_clock),
    ):
        try:
            run_for(ex, duration, record=args.record, quiet=args.quiet, desc=Path(args.file).stem)
        finally:
            session.shutdown()
    topics = {name: t.count for name, t in sorted(ex.topics.items())}
    summary: dict[str, Any] = {"sim_s": round(ex.now_ns / 1e9, 3), "nodes": sorted(ex.nodes), "topics": topics}
    if args.record:
        summary["record"] = str(args.record)
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"ran {summary['sim_s']:.2f} simulated s; {len(ex.nodes)} nodes")
        for name, count in topics.items():
            print(f"  {name}: {count} messages")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    """``navlab run FILE.py``: an rclpy-style node file, unchanged, in a launch's simulation."""
    import runpy
    import sys

    from navlab import init, install_ros_imports, shutdown
    from navlab.core import Context, parse_launch_args, start

    apply_resource_paths(args)
    install_ros_imports()
    files, items = _split_files(args.launch, args.args) if args.launch else ([], args.args)
    if files:
        session = start(files, seed=args.seed, launch_args=parse_launch_args(items))
        ctx = Context(session.executor, session, args.duration, prepared=True)
    else:
        ctx = Context(duration=args.duration, prepared=True)
    init(context=ctx)
    argv = sys.argv
    sys.argv = [args.file]
    try:
        runpy.run_path(args.file, run_name="__main__")
    finally:
        sys.argv = argv
        shutdown(context=ctx)
    ex = ctx.executor
    summary = {
        "sim_s": round(ex.now_ns / 1e9, 3),
        "nodes": sorted(ex.nodes),
        "topics": {name: t.count for name, t in sorted(ex.topics.items())},
    }
    if args.json:
        print(json.dumps(summary))
    return 0


def _shipped_launches() -> list[str]:
    from navlab.resources import root  # (navlab.core would load numpy for --help)

    return sorted(f.name.removesuffix(".launch.yaml") for f in (root() / "launch").glob("*.launch.yaml"))


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``launch``, ``roslaunch`` and ``run``."""
    for verb in ("launch", "roslaunch"):
        p = sub.add_parser(
            verb,
            help="run launch files: navlab YAML (ROS 2 shape) or ROS 1 XML .launch"
            if verb == "launch"
            else "roslaunch PKG FILE.launch [name:=value]: a ROS 1 launch file found in a package",
            description="Run launch files (paths or shipped names; several at once as `roslaunch a.launch b.launch` "
            "takes them) with name:=value arguments, in simulated time, and print how many messages each topic "
            "carried. ROS 1 XML .launch files run with roslaunch's semantics; `navlab roslaunch PKG FILE.launch` "
            "finds FILE inside package PKG (ROS_PACKAGE_PATH and --package-path). Nodes navlab does not implement "
            "are listed, and started as processes with ros:=true (the ROS bridge). Shipped launches: "
            f"{', '.join(_shipped_launches())} (e.g. `navlab launch mapping --duration 120`, "
            "`navlab launch localization map:=map/map.yaml`); `navlab launch NAME --show-args` lists a launch's "
            "arguments.",
        )
        p.add_argument(
            "file",
            help="launch file or shipped launch name"
            if verb == "launch"
            else "ROS package (then the launch file's name), or a launch file",
        )
        p.add_argument("args", nargs="*", metavar="FILE|name:=value", help="more launch files, then launch arguments")
        p.add_argument(
            "--duration", type=positive_seconds, default=None, help="simulated seconds to run (default: until Ctrl-C)"
        )
        add_run_options(
            p,
            seed=0,
            rate=None,
            rate_default="0 with --duration, else 1",
            record=True,
            quiet=True,
            json=True,
            view=True,
            ros=True,
        )
        add_resource_path_arguments(p)
        p.add_argument(
            "-s",
            "--show-args",
            action="store_true",
            help="list the launch's arguments (name, description, default) and exit",
        )
        p.set_defaults(func=_cmd_launch if verb == "launch" else _cmd_roslaunch)

    p = sub.add_parser(
        "run",
        help="run an rclpy-style node file unchanged in a launch's simulation",
        description="Run a Python file written against rclpy (import rclpy; from rclpy.node import Node; from "
        "geometry_msgs.msg import Twist; rclpy.init(); rclpy.spin(node)) unchanged, on navlab: `import rclpy` and "
        "the message packages come from navlab unless a real ROS 2 installation provides them. With --launch, "
        "the file's rclpy.init() joins that launch (e.g. `navlab run driver.py --launch sim world:=room "
        "--duration 10`); rclpy.spin() runs --duration simulated seconds.",
    )
    p.add_argument("file", help="the Python file")
    p.add_argument("--launch", metavar="FILE", help="a launch (file or shipped name) to start for the node")
    p.add_argument("args", nargs="*", metavar="name:=value", help="launch arguments")
    p.add_argument(
        "--duration",
        type=positive_seconds,
        default=None,
        help="simulated seconds rclpy.spin() runs (default: until the file calls rclpy.shutdown())",
    )
    add_run_options(p, seed=0, json=True)
    add_resource_path_arguments(p)
    p.set_defaults(func=_cmd_run)
