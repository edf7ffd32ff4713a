"""``navlab roscore`` (navlab's own ROS 1 master) and the ``ros:=true`` / ``--ros`` switch of runs."""

from __future__ import annotations

import argparse
import contextlib
import logging
import signal
from collections.abc import Callable, Iterator
from typing import Any

TRUE = ("true", "1", "yes", "on")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "roscore", help="run a ROS 1 master + parameter server (for real ROS tools and navlab's --ros runs)",
        description="A ROS 1 master and parameter server, as `roscore` starts them, on $ROS_MASTER_URI's port "
                    "(default 11311). It listens on loopback unless ROS_IP or ROS_HOSTNAME name another address.",
    )
    p.add_argument("-p", "--port", type=int, default=None, help="port (default: from $ROS_MASTER_URI, else 11311)")
    p.set_defaults(func=_cmd_roscore)


def _cmd_roscore(args: argparse.Namespace) -> int:
    from navlab.ros1.master import Master
    from navlab.ros1.net import host_port, master_uri

    port = args.port if args.port is not None else host_port(master_uri())[1]
    master = Master(port=port)
    print(f"navlab roscore: ROS master at {master.uri} (Ctrl-C to stop)", flush=True)
    signal.signal(signal.SIGTERM, lambda *_: master.close())
    with contextlib.suppress(KeyboardInterrupt):
        master.stopped.wait()
    master.close()
    return 0


def add_ros_argument(p: argparse.ArgumentParser, *, rate: bool = False, pace_option: str = "--rate") -> None:
    """``--ros``: offer the run on a ROS 1 master (``$ROS_MASTER_URI``, or navlab's own); with ``rate``, also
    ``--rate`` (for verbs that have no pace option of their own); ``pace_option``: the verb's pace option."""
    p.add_argument("--ros", action="store_true",
                   help="join the ROS 1 graph at $ROS_MASTER_URI (or start navlab's own master): real rostopic, "
                        f"rviz, rosbag and rospy nodes see and drive the run; runs in real time unless {pace_option}")
    if rate:
        p.add_argument("--rate", type=pace, default=None,
                       help="pacing: 0 = as fast as possible (default; real time with --ros), 1 = real time, "
                            "r = r x real time")


def pace(text: str) -> float:
    """argparse type of ``--rate``: a finite number >= 0 (simulated s per wall-clock s; 0 = as fast as possible)."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a number >= 0 (0 = as fast as possible), got {text!r}")
    return value


def pop_ros_arg(launch_args: dict[str, str]) -> bool:
    """Take ``ros:=true|false`` out of the launch arguments (it switches the bridge, no launch file reads it)."""
    return str(launch_args.pop("ros", "false")).strip().lower() in TRUE


def follows_clock(launch_args: dict[str, str]) -> bool:
    """Whether a run takes its time from the graph's ``/clock``: ``sim:=false`` (hardware in the loop)."""
    return str(launch_args.get("sim", "true")).strip().lower() not in TRUE


@contextlib.contextmanager
def ros_bridge(enabled: bool, executor: Any, nodes: dict[str, Any], *, follow_clock: bool = False) -> Iterator[Any]:
    """With ``enabled``: the run offered on ROS 1 while the block runs (None otherwise); ``follow_clock``:
    its time follows the graph's ``/clock``."""
    if not enabled:
        yield None
        return
    bridge = _open_bridge(executor, nodes, follow_clock=follow_clock)
    try:
        yield bridge
    finally:
        bridge.close()


@contextlib.contextmanager
def ros_hook(args: argparse.Namespace, then: Callable[[Any], None] | None = None) -> Iterator[Any]:
    """With ``--ros`` (or ``--rate``): an ``on_start(run)`` for ``start_run`` and the run functions that take one.
    It paces each run it starts — ``--rate``, else real time with ``--ros`` (outside nodes cannot follow 100x),
    else the run's own pace — then calls ``then(run)`` (``view_hook``'s viewer, which takes that pace) and, with
    ``--ros``, offers the run on ROS 1 (the previous run's bridge closes). Neither given: ``then`` itself."""
    ros, rate = bool(getattr(args, "ros", False)), getattr(args, "rate", None)
    if not ros and rate is None:
        yield then
        return
    bridges: list[Any] = []

    def on_start(run: Any) -> None:
        while bridges:
            bridges.pop().close()  # the previous run has finished
        ex = run.executor
        if rate is not None:
            ex.rate = float(rate)
        elif ros:
            ex.rate = ex.rate or 1.0
        if then is not None:
            then(run)
        if ros:
            bridges.append(_open_bridge(ex, run.session.nodes))

    try:
        yield on_start
    finally:
        for bridge in bridges:
            bridge.close()


def _open_bridge(executor: Any, nodes: dict[str, Any], *, follow_clock: bool = False) -> Any:
    from navlab.ros1.bridge import RosBridge, session_params

    logging.getLogger("navlab.ros1").setLevel(logging.INFO)
    return RosBridge(executor, params=session_params(nodes), follow_clock=follow_clock)
