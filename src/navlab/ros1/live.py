"""A launch kept running in real time in a background thread and offered on a ROS 1 master — how tests,
benchmarks and notebooks put a run on the graph while their own thread talks to it."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from navlab.core import start
from navlab.ros1.bridge import RosBridge, session_params
from navlab.ros1.services import call_in_executor

T = TypeVar("T")


class LiveRun:
    """``launch`` started with ``args``, spun in a thread (real time, or following the graph's ``/clock``)
    and offered on the master at ``master``; ready once every node has published (2 simulated seconds)."""

    def __init__(self, launch: str, *, master: str | None = None, follow_clock: bool = False, **args: Any) -> None:
        self.session = start(launch, rate=0.0 if follow_clock else 1.0, **args)
        self.ex = self.session.executor
        self.bridge = RosBridge(
            self.ex, master=master, params=session_params(self.session.nodes), follow_clock=follow_clock
        )
        self.thread = threading.Thread(target=self.ex.spin, name="navlab-live", daemon=True)
        self.thread.start()
        while self.ex.now_ns < 2_000_000_000 and self.thread.is_alive():  # tf publishers appear on first use
            time.sleep(0.05)
        self.call(self.bridge.sync)
        self.bridge.flush()

    def call(self, fn: Callable[[], T], timeout: float = 30.0) -> T:
        """``fn()`` run in the executor's thread."""
        return call_in_executor(self.ex, fn, timeout)

    def close(self) -> None:
        self.ex.post(self.ex.stop)
        if self.bridge.follower is not None:  # the graph's clock may have stopped: do not wait for it
            self.bridge.follower.close()
        self.thread.join(10)
        self.bridge.close()
