"""``navlab roscore`` (navlab's own ROS 1 master) and the ``ros:=true`` / ``--ros`` switch of runs."""

from __future__ import annotations

import argparse
import contextlib
import logging
import signal
from collections.abc import Iterator
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


def add_ros_argument(p: argparse.ArgumentParser) -> None:
    """``--ros``: offer the run on a ROS 1 master (``$ROS_MASTER_URI``, or navlab's own)."""
    p.add_argument("--ros", action="store_true",
                   help="join the ROS 1 graph at $ROS_MASTER_URI (or start navlab's own master): real rostopic, "
                        "rviz, rosbag and rospy nodes see and drive the run; runs in real time unless --rate")


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
    from navlab.ros1.bridge import RosBridge, session_params

    logging.getLogger("navlab.ros1").setLevel(logging.INFO)
    bridge = RosBridge(executor, params=session_params(nodes), follow_clock=follow_clock)
    try:
        yield bridge
    finally:
        bridge.close()
