"""Following the graph's ``/clock`` (ROS's ``use_sim_time``): a run without its own simulator (hardware in
the loop) lets its simulated time advance only as far as the clock published elsewhere has.

:class:`ClockFollower` is a stepper of the executor (run it with ``rate=0``): before each event at ``t`` it
waits until a ``/clock`` message at ``t`` or later arrived, so timers, tf and stamps share the robot's time.
"""

from __future__ import annotations

import threading

from navlab.core import Executor, Timer
from navlab.ros1.net import LOG

MAX_JUMP_NS = 3600 * 1_000_000_000
HEARTBEAT_NS = 10_000_000


def _nothing() -> None:
    pass


class ClockFollower:
    """An executor stepper that blocks until the outside ``/clock`` reaches each event's time."""

    def __init__(self, executor: Executor) -> None:
        self.latest_ns = -1
        self._cond = threading.Condition()
        self._closed = False
        self._warned = False
        executor.add_stepper(self)
        # a heartbeat event every 10 ms: time moves in clock-sized steps even when no node has a timer
        # (map_server + amcl only wait for messages); otherwise the executor would wait for its run's end time
        self._heartbeat = Timer(executor, HEARTBEAT_NS, _nothing, 0, executor.now_ns)

    def tick(self, t_ns: int) -> None:
        """A ``/clock`` message arrived (any thread); a jump of more than an hour is refused (wall-clock time
        such as ``rosbag play --clock`` of a bag recorded without /clock would fire every timer in between)."""
        with self._cond:
            if self.latest_ns >= 0 and t_ns - self.latest_ns > MAX_JUMP_NS:
                if not self._warned:
                    self._warned = True
                    LOG.error(
                        "ros1: /clock jumped %.0f s ahead: ignored (follow a simulator's /clock or play a "
                        "bag that recorded /clock, without --clock)",
                        (t_ns - self.latest_ns) / 1e9,
                    )
                return
            if t_ns > self.latest_ns:
                self.latest_ns = t_ns
                self._cond.notify_all()

    def advance_to(self, t_ns: int) -> None:
        with self._cond:
            while self.latest_ns < t_ns and not self._closed:
                self._cond.wait(0.5)

    def close(self) -> None:
        """Stop waiting (the run is ending)."""
        self._heartbeat.cancel()
        with self._cond:
            self._closed = True
            self._cond.notify_all()
