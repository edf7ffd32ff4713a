"""ROS-style tools: ``navlab topic list|echo|hz``, ``navlab node list``, ``navlab graph``, ``navlab bag reindex``
and ``navlab roscore``.

The introspection verbs look at a ``navlab launch`` running in another shell (the default; ``--pid``
picks one of several), at a launch that they start themselves (``--launch FILE name:=value``, run
for ``--duration`` simulated seconds), or at a recording (``--bag DIR``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navlab.cli.options import add_run_options, out_file, positive_seconds
from navlab.cli.runs import stop_signals
from navlab.io import write_text_atomic

if TYPE_CHECKING:  # navlab.core loads numpy and rosbags: imported where a verb runs, so --help stays quick
    from navlab.core import Graph, Session


def _add_source(p: argparse.ArgumentParser) -> None:
    src = p.add_mutually_exclusive_group()
    src.add_argument(
        "--launch",
        nargs="+",
        metavar=("FILE", "name:=value"),
        help="start this launch (file or shipped name, then its arguments) here and watch it",
    )
    src.add_argument("--bag", metavar="DIR", help="read a rosbag2 recording instead")
    src.add_argument("--pid", type=int, help="which running `navlab launch` to watch when several run")
    p.add_argument(
        "--duration",
        type=positive_seconds,
        default=None,
        help="simulated seconds to watch (default 5; echo: until Ctrl-C or the end of the launch)",
    )
    add_run_options(p, seed=0)


def _watch_seconds(args: argparse.Namespace) -> None:
    """``--duration``'s default: 5 simulated s to collect a list, rate or graph; echo runs until stopped."""
    if args.duration is None:
        args.duration = math.inf if getattr(args, "action", "") == "echo" else 5.0


def _start(args: argparse.Namespace) -> Session:
    from navlab.core import parse_launch_args, start

    file, *items = args.launch
    return start(file, seed=args.seed, launch_args=parse_launch_args(items))


def _running(args: argparse.Namespace) -> Path | None:
    """The socket of a launch running in another process, when neither --launch nor --bag is given."""
    from navlab.core import find_running

    return None if args.launch or args.bag else find_running(args.pid)


def _live_messages(path: Path, topic: str, duration: float) -> Iterator[tuple[int, Any]]:
    """Messages of a running launch until ``duration`` simulated seconds passed."""
    from navlab.core import subscribe

    t0 = None
    for t_ns, msg in subscribe(path, topic):
        t0 = t_ns if t0 is None else t0
        yield t_ns, msg
        if t_ns - t0 >= duration * 1e9:
            return


def _messages(args: argparse.Namespace, topic: str) -> Iterator[tuple[int, Any]] | list[tuple[int, Any]]:
    """(t_ns, msg) on ``topic`` from the bag, a running launch, or a launch started here."""
    from navlab.core import CoreError, run_for

    if args.bag:
        from navlab.io import read_bag

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


@stop_signals()  # `topic echo` runs until Ctrl-C (or SIGTERM), also as a background job
def _cmd_topic(args: argparse.Namespace) -> int:
    import numpy as np

    from navlab.core import CoreError, run_for

    _watch_seconds(args)
    if args.action == "list":
        if args.bag:
            from navlab.io import bag_topics

            rows = {k: v for k, v in bag_topics(args.bag).items()}
        elif (live := _running(args)) is not None:
            from navlab.core import request

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
        from navlab.core import EchoPrinter, echo_bag, echo_launch, echo_live

        out = EchoPrinter(args.count)
        if args.bag:
            return echo_bag(args.bag, args.topic, out, args.duration)
        if (live := _running(args)) is not None:
            return echo_live(live, args.topic, out, args.duration)
        return echo_launch(args.launch, args.topic, out, args.duration, args.seed, run_for)
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
    from navlab.core import Graph, run_for

    _watch_seconds(args)
    if args.bag:
        from navlab.io import bag_graph, bag_topics

        data = bag_graph(args.bag)
        if data is not None:
            return Graph.from_json(data)
        return Graph(topics={t: ([], []) for t in bag_topics(args.bag)})
    live = _running(args)
    if live is not None:
        from navlab.core import request

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
    from navlab.io import reindex_bag

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


@stop_signals()  # Ctrl-C and SIGTERM stop it, also as a background job (SIGINT inherited ignored)
def _cmd_roscore(args: argparse.Namespace) -> int:
    from navlab.ros1 import Master, host_port, master_uri

    port = args.port if args.port is not None else host_port(master_uri())[1]
    master = Master(port=port)
    print(f"navlab roscore: ROS master at {master.uri} (Ctrl-C to stop)", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        master.stopped.wait()
    master.close()
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``bag``, ``topic``, ``node``, ``graph`` and ``roscore``."""
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
    add_run_options(p, json=True)
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
    p.add_argument(
        "-n",
        "--count",
        type=int,
        default=0,
        help="echo: stop after this many messages (exit 1 if the source ends before)",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="list: show message counts")
    add_run_options(p, json=True)
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
    p.add_argument(
        "--out", default="graph", metavar="DIR", help="output folder: DIR/graph.dot and DIR/graph.svg (default ./graph)"
    )
    p.set_defaults(func=_cmd_graph)

    p = sub.add_parser(
        "roscore",
        help="run a ROS 1 master + parameter server (for real ROS tools and navlab's --ros runs)",
        description="A ROS 1 master and parameter server, as `roscore` starts them, on $ROS_MASTER_URI's port "
        "(default 11311). It listens on loopback unless ROS_IP or ROS_HOSTNAME name another address.",
    )
    p.add_argument("-p", "--port", type=int, default=None, help="port (default: from $ROS_MASTER_URI, else 11311)")
    p.set_defaults(func=_cmd_roscore)
