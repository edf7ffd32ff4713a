"""ROS-style tools: ``navlab launch``, ``navlab topic list|echo|hz``, ``navlab node list``, ``navlab graph``.

The introspection verbs look at a ``navlab launch`` running in another shell (the default; ``--pid``
picks one of several), at a launch that they start themselves (``--launch FILE name:=value``, run
for ``--duration`` simulated seconds), or at a recording (``--bag DIR``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from navlab.cli_common import add_resource_path_arguments, apply_resource_paths, out_file, positive_seconds
from navlab.core.errors import CoreError
from navlab.core.graph import Graph
from navlab.core.launch import Session, start
from navlab.core.runner import parse_launch_args, run_for
from navlab.io.files import write_text_atomic
from navlab.ros1.cli import add_ros_argument
from navlab.viz.cli import add_view_arguments


def _add_source(p: argparse.ArgumentParser) -> None:
    src = p.add_mutually_exclusive_group()
    src.add_argument(
        "--launch", nargs="+", metavar=("FILE", "name:=value"),
        help="start this launch (file or shipped name, then its arguments) here and watch it",
    )
    src.add_argument("--bag", metavar="DIR", help="read a rosbag2 recording instead")
    src.add_argument("--pid", type=int, help="which running `navlab launch` to watch when several run")
    p.add_argument("--duration", type=positive_seconds, default=None,
                   help="simulated seconds to watch (default 5; echo: until Ctrl-C or the end of the launch)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")


def _watch_seconds(args: argparse.Namespace) -> None:
    """``--duration``'s default: 5 simulated s to collect a list, rate or graph; echo runs until stopped."""
    if args.duration is None:
        args.duration = math.inf if getattr(args, "action", "") == "echo" else 5.0


def _start(args: argparse.Namespace) -> Session:
    file, *items = args.launch
    return start(file, seed=args.seed, launch_args=parse_launch_args(items))


def _running(args: argparse.Namespace) -> Path | None:
    """The socket of a launch running in another process, when neither --launch nor --bag is given."""
    from navlab.core.introspect import find_running

    return None if args.launch or args.bag else find_running(args.pid)


def _live_messages(path: Path, topic: str, duration: float) -> Iterator[tuple[int, Any]]:
    """Messages of a running launch until ``duration`` simulated seconds passed."""
    from navlab.core.introspect import subscribe

    t0 = None
    for t_ns, msg in subscribe(path, topic):
        t0 = t_ns if t0 is None else t0
        yield t_ns, msg
        if t_ns - t0 >= duration * 1e9:
            return


def _messages(args: argparse.Namespace, topic: str) -> Iterator[tuple[int, Any]] | list[tuple[int, Any]]:
    """(t_ns, msg) on ``topic`` from the bag, a running launch, or a launch started here."""
    if args.bag:
        from navlab.io.rosbag import read_bag

        return [(t, m) for _, t, m in read_bag(args.bag, topics=[topic])]
    live = _running(args)
    if live is not None:
        return _live_messages(live, topic, args.duration)
    session = _start(args)
    got: list[tuple[int, Any]] = []

    def listen(name: str, msg: Any, t_ns: int) -> None:
        if name == topic:
            got.append((t_ns, msg))

    session.executor.add_listener(listen)
    run_for(session.executor, args.duration, quiet=True)
    if topic not in session.executor.topics:
        raise CoreError(f"no topic {topic!r} in this launch (topics: {', '.join(sorted(session.executor.topics))})")
    return got


def _show_args(file: str) -> int:
    from navlab.core.launch import declared_args

    rows = declared_args(file)
    if not rows:
        print(f"{file}: no arguments")
    for a in rows:
        default = f" (default: {a['default']!r})" if "default" in a else " (required)"
        print(f"  '{a.get('name')}':\n      {a.get('description', '')}{default}")
    return 0


def _split_files(first: str, items: list[str]) -> tuple[list[str], list[str]]:
    """``FILE [FILE ...] name:=value ...``: the launch files and the arguments (as roslaunch takes them)."""
    files = [first] + [i for i in items if ":=" not in i]
    return files, [i for i in items if ":=" in i]


def find_in_package(pkg: str, name: str) -> Path:
    """roslaunch's ``roslaunch PKG FILE``: the file called ``name`` anywhere inside package ``pkg``."""
    from navlab.core.errors import LaunchError
    from navlab.description.errors import DescriptionError
    from navlab.description.packages import find_package

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


def _cmd_launch(args: argparse.Namespace) -> int:
    if args.show_args:
        return _show_args(args.file)
    apply_resource_paths(args)  # --package-path / --model-path for robot:= and world:=
    # Like roslaunch, a launch without --duration runs in real time until Ctrl-C.
    from navlab.ros1.cli import follows_clock, pop_ros_arg, ros_bridge

    files, items = _split_files(args.file, args.args)
    launch_args = parse_launch_args(items)
    ros = pop_ros_arg(launch_args) or args.ros  # outside nodes cannot follow 100x: real time unless --rate
    rate = args.rate if args.rate is not None else (1.0 if args.duration is None or ros else 0.0)
    follow_clock = ros and follows_clock(launch_args)  # hardware in the loop: the robot's /clock paces the run
    rate = 0.0 if follow_clock else rate
    session = start(files, seed=args.seed, pace=rate, launch_args=launch_args, ros=ros)
    ex = session.executor
    duration = math.inf if args.duration is None else args.duration
    from navlab.core.introspect import IntrospectionServer

    # `navlab topic/node/graph` in another shell look into this launch while it runs; SIGTERM ends it
    # cleanly like Ctrl-C (the recording is closed, the socket removed)
    signal.signal(signal.SIGTERM, lambda *_: ex.post(ex.stop))
    from navlab.viz.cli import viewing

    with IntrospectionServer(ex, name=args.file), contextlib.suppress(KeyboardInterrupt), viewing(args, ex), \
            ros_bridge(ros, ex, session.nodes, follow_clock=follow_clock):
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

    from navlab.core import rclpy_api
    from navlab.core.ros_imports import install

    apply_resource_paths(args)
    install()
    files, items = (_split_files(args.launch, args.args) if args.launch else ([], args.args))
    if files:
        session = start(files, seed=args.seed, launch_args=parse_launch_args(items))
        ctx = rclpy_api.Context(session.executor, session, args.duration, prepared=True)
    else:
        ctx = rclpy_api.Context(duration=args.duration, prepared=True)
    rclpy_api.init(context=ctx)
    argv = sys.argv
    sys.argv = [args.file]
    try:
        runpy.run_path(args.file, run_name="__main__")
    finally:
        sys.argv = argv
        rclpy_api.shutdown(context=ctx)
    ex = ctx.executor
    summary = {"sim_s": round(ex.now_ns / 1e9, 3), "nodes": sorted(ex.nodes),
               "topics": {name: t.count for name, t in sorted(ex.topics.items())}}
    if args.json:
        print(json.dumps(summary))
    return 0


def _cmd_topic(args: argparse.Namespace) -> int:
    _watch_seconds(args)
    if args.action == "list":
        if args.bag:
            from navlab.io.rosbag import bag_topics

            rows = {k: v for k, v in bag_topics(args.bag).items()}
        elif (live := _running(args)) is not None:
            from navlab.core.introspect import request

            rows = {k: tuple(v) for k, v in request(live, "graph")["types"].items()}
        else:
            from navlab.msgs import type_name

            session = _start(args)
            run_for(session.executor, args.duration, quiet=True)
            rows = {k: (type_name(t.msgtype), t.count) for k, t in session.executor.topics.items()}
        for name in sorted(rows):
            msgtype, count = rows[name]
            print(f"{name} [{msgtype}]" + (f" {count} msgs" if args.verbose else ""))
        return 0
    if not args.topic:
        raise CoreError(f"navlab topic {args.action} needs a TOPIC name")
    if args.action == "echo":
        from navlab.core import echo

        out = echo.Printer(args.count)
        if args.bag:
            return echo.echo_bag(args.bag, args.topic, out, args.duration)
        if (live := _running(args)) is not None:
            return echo.echo_live(live, args.topic, out, args.duration)
        return echo.echo_launch(args.launch, args.topic, out, args.duration, args.seed, run_for)
    msgs = _messages(args, args.topic)
    # hz
    times = np.array([t for t, _ in msgs], dtype=np.int64)  # simulated time stamps
    if len(times) < 2:
        raise CoreError(f"topic {args.topic!r}: fewer than 2 messages, no rate to compute")
    periods = np.diff(times) / 1e9
    res = {
        "topic": args.topic,
        "messages": len(times),
        "average_rate_hz": float(1.0 / periods.mean()),
        "min_period_s": float(periods.min()),
        "max_period_s": float(periods.max()),
        "std_dev_s": float(periods.std()),
    }
    if args.json:
        print(json.dumps(res))
    else:
        print(
            f"average rate: {res['average_rate_hz']:.3f}\n\tmin: {res['min_period_s']:.3f}s "
            f"max: {res['max_period_s']:.3f}s std dev: {res['std_dev_s']:.5f}s window: {res['messages']}"
        )
    return 0


def _graph_of(args: argparse.Namespace) -> Graph:
    _watch_seconds(args)
    if args.bag:
        from navlab.io.rosbag import bag_graph, bag_topics

        data = bag_graph(args.bag)
        if data is not None:
            return Graph.from_json(data)
        return Graph(topics={t: ([], []) for t in bag_topics(args.bag)})
    live = _running(args)
    if live is not None:
        from navlab.core.introspect import request

        return Graph.from_json(request(live, "graph"))
    session = _start(args)
    run_for(session.executor, args.duration, quiet=True)
    return Graph.from_executor(session.executor)


def _cmd_node(args: argparse.Namespace) -> int:
    graph = _graph_of(args)
    for n in graph.nodes:
        print(n)
    return 0


def _cmd_graph(args: argparse.Namespace) -> int:
    graph = _graph_of(args)
    svg = out_file(args.out, "graph.svg", old_suffixes=(".dot", ".svg"))
    dot = svg.with_suffix(".dot")
    write_text_atomic(dot, graph.to_dot())
    graph.write_svg(svg)
    print(f"wrote {dot} and {svg}")
    return 0


def _cmd_bag(args: argparse.Namespace) -> int:
    from navlab.io.rosbag import reindex_bag

    res = reindex_bag(args.dir, args.out)
    if args.json:
        print(json.dumps(res))
    else:
        print(f"reindexed {res['path']}: {res['messages']} messages on {len(res['topics'])} topics")
        for kept in res["kept"]:
            print(f"  kept the damaged file as {kept}")
        for name, count in sorted(res["topics"].items()):
            print(f"  {name}: {count}")
    return 0


def _shipped_launches() -> list[str]:
    from navlab.core.launch import resources_dir

    return sorted(f.name.removesuffix(".launch.yaml") for f in (resources_dir() / "launch").glob("*.launch.yaml"))


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``launch``, ``topic``, ``node`` and ``graph``."""
    for verb in ("launch", "roslaunch"):
        p = sub.add_parser(
            verb,
            help="run launch files: navlab YAML (ROS 2 shape) or ROS 1 XML .launch" if verb == "launch"
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
        p.add_argument("file", help="launch file or shipped launch name" if verb == "launch"
                       else "ROS package (then the launch file's name), or a launch file")
        p.add_argument("args", nargs="*", metavar="FILE|name:=value",
                       help="more launch files, then launch arguments")
        p.add_argument("--duration", type=positive_seconds, default=None,
                       help="simulated seconds to run (default: until Ctrl-C)")
        p.add_argument("--rate", type=float, default=None,
                       help="pacing: 0 = as fast as possible, 1 = real time (default: 0 with --duration, else 1)")
        p.add_argument("--record", metavar="DIR", help="write every topic to a rosbag2 (MCAP) in DIR")
        p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
        p.add_argument("--quiet", action="store_true", help="no progress bar")
        p.add_argument("--json", action="store_true", help="print the summary as JSON")
        add_view_arguments(p)
        add_ros_argument(p)
        add_resource_path_arguments(p)
        p.add_argument("-s", "--show-args", action="store_true",
                       help="list the launch's arguments (name, description, default) and exit")
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
    p.add_argument("--duration", type=positive_seconds, default=None,
                   help="simulated seconds rclpy.spin() runs (default: until the file calls rclpy.shutdown())")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--json", action="store_true", help="print the topics' message counts as JSON")
    add_resource_path_arguments(p)
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser(
        "bag",
        help="recordings: reindex a recording that was killed (ros2 bag reindex)",
        description="`navlab bag reindex DIR` rebuilds a rosbag2 (MCAP) recording whose process was killed before "
        "it closed the bag (no metadata.yaml; navlab leaves it in .DIR.partial/DIR): every message written before "
        "the kill is kept and the bag is moved to DIR with its metadata. Only the bag's own files are renamed into "
        "DIR (its MCAP file and metadata.yaml); the damaged MCAP files stay beside them as FILE.damaged and nothing "
        "else in DIR is touched. With --out, the rebuilt bag goes to a new directory and DIR is left as it is.",
    )
    p.add_argument("action", choices=["reindex"], help="what to do")
    p.add_argument("dir", metavar="DIR", help="the recording's directory (or the name it was recorded under)")
    p.add_argument("--out", metavar="OUT", help="write the rebuilt recording to this new directory instead")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_bag)

    p = sub.add_parser(
        "topic",
        help="list, echo or measure the rate of topics (rostopic)",
        description="rostopic list|echo|hz on a `navlab launch` running in another shell (the default), on a "
        "launch that this command starts (--launch), or on a rosbag2 recording (--bag). list and hz watch "
        "--duration simulated seconds (default 5). echo prints each message as YAML followed by ---, as rostopic "
        "does, until Ctrl-C, the end of the launch or recording, -n N messages, or --duration (a --launch started "
        "here then runs as fast as possible; without --duration it runs in real time, as roslaunch). "
        "e.g. `navlab topic hz /mybot/laser/scan` next to `navlab launch mapping`.",
    )
    p.add_argument("action", choices=["list", "echo", "hz"], help="what to do")
    p.add_argument("topic", nargs="?", help="topic name (echo, hz)")
    _add_source(p)
    p.add_argument("-n", "--count", type=int, default=0,
                   help="echo: stop after this many messages (exit 1 if the source ends before)")
    p.add_argument("-v", "--verbose", action="store_true", help="list: show message counts")
    p.add_argument("--json", action="store_true", help="hz: print JSON")
    p.set_defaults(func=_cmd_topic)

    p = sub.add_parser(
        "node",
        help="list the nodes of a launch or recording (rosnode list)",
        description="rosnode list on a running `navlab launch` (the default), on a launch that this command "
        "starts and runs for --duration simulated seconds (--launch), or on a navlab rosbag2 recording "
        "(--bag; the graph is stored in its metadata).",
    )
    p.add_argument("action", choices=["list"], help="what to do")
    _add_source(p)
    p.set_defaults(func=_cmd_node)

    p = sub.add_parser(
        "graph",
        help="write the node/topic graph as DOT and SVG (rqt_graph)",
        description="rqt_graph as files: the nodes and topics of a running `navlab launch` (the default), of "
        "a launch started here (--launch, run for --duration simulated seconds) or of a recording (--bag), "
        "written as DIR/graph.dot and DIR/graph.svg: nodes as ellipses, topics as boxes, publisher -> topic -> "
        "subscriber, laid out left to right by Graphviz's dot (Debian package graphviz).",
    )
    _add_source(p)
    p.add_argument("--out", default="graph", metavar="DIR",
                   help="output folder: DIR/graph.dot and DIR/graph.svg (default ./graph)")
    p.set_defaults(func=_cmd_graph)

