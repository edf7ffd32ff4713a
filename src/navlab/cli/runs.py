"""What run verbs wrap around a run: ``--view`` (the viewer on each run), ``--ros`` / ``ros:=true`` (the run
offered on ROS 1, paced by ``--rate``) and Ctrl-C / SIGTERM (runs until interrupted)."""

from __future__ import annotations

import argparse
import contextlib
import logging
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

TRUE = ("true", "1", "yes", "on")


def pop_ros_arg(launch_args: dict[str, str]) -> bool:
    """Take ``ros:=true|false`` out of the launch arguments (it switches the bridge, no launch file reads it)."""
    return str(launch_args.pop("ros", "false")).strip().lower() in TRUE


def follows_clock(launch_args: dict[str, str]) -> bool:
    """Whether a run takes its time from the graph's ``/clock``: ``sim:=false`` (hardware in the loop)."""
    return str(launch_args.get("sim", "true")).strip().lower() not in TRUE


class StopRequest:
    """What the first Ctrl-C (or SIGTERM) does inside :func:`stop_signals`: raise KeyboardInterrupt where the
    main thread is, or, once :meth:`graceful` named a run's executor, end that run at the next event boundary
    (its state whole, so the verb can still save its result); a second signal then raises KeyboardInterrupt."""

    def __init__(self) -> None:
        self.requested = False  # a signal asked the graceful run to stop
        self._executor: Any = None
        self._message = ""

    def graceful(self, executor: Any, message: str) -> None:
        """From now on the first signal stops ``executor`` (after printing ``message`` on stderr)."""
        self._executor, self._message = executor, message

    def on_start(self, then: Callable[[Any], None] | None, message: str) -> Callable[[Any], None]:
        """An ``on_start(run)`` for ``start_run`` that calls ``then(run)`` and makes the run's executor graceful."""

        def on_start(run: Any) -> None:
            if then is not None:
                then(run)
            self.graceful(run.executor, message)

        return on_start

    def __call__(self, _signum: int, _frame: Any) -> None:
        ex = self._executor
        if ex is None or self.requested:
            raise KeyboardInterrupt
        self.requested = True
        message = self._message

        def stop() -> None:  # in the executor's thread, between events: no print inside another write
            print(f"\n{message}", file=sys.stderr, flush=True)
            ex.stop()

        ex.post(stop)  # the executor's inbox is a SimpleQueue: its put may interrupt its own get


@contextlib.contextmanager
def stop_signals() -> Iterator[StopRequest]:
    """Ctrl-C (SIGINT) and SIGTERM raise KeyboardInterrupt in the block, whatever this process inherited
    (or, after ``graceful(executor, ...)`` on the yielded :class:`StopRequest`, the first one stops that run).

    A background job of a script starts with SIGINT ignored, and Python then installs no handler of its own:
    roslaunch and rospy install theirs for that reason, and so does every verb that runs until Ctrl-C. The main
    thread is interrupted where it is (an executor's loop, a startup, a blocking wait); the verb suppresses the
    KeyboardInterrupt around its loop and its ``finally`` blocks clean up. The previous handlers come back after."""
    request = StopRequest()
    if threading.current_thread() is not threading.main_thread():  # only the main thread may set handlers
        yield request
        return
    before = {sig: signal.signal(sig, request) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield request
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)


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
    from navlab.ros1 import RosBridge, session_params

    logging.getLogger("navlab.ros1").setLevel(logging.INFO)
    return RosBridge(executor, params=session_params(nodes), follow_clock=follow_clock)


def start_viewer(args: argparse.Namespace, executor: Any, *, host: str, port: int, rate: float | None = None) -> Any:
    """Attach the viewer, print its URL (and a warning off loopback), open a browser where there is a desktop."""
    from navlab.viz import attach, host_warning, open_in_browser

    warning = host_warning(host)
    if warning:
        print(warning, file=sys.stderr)
    viewer = attach(executor, host=host, port=port, rate=rate, foxglove_port=getattr(args, "foxglove", None))
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
