"""Following the graph's ``/clock`` (ROS's ``use_sim_time``): a run without its own simulator (hardware in
the loop) lets its simulated time advance only as far as the clock published elsewhere has.

:class:`ClockFollower` is a stepper of the executor (run it with ``rate=0``): before each event at ``t`` it
waits until a ``/clock`` message at ``t`` or later arrived, so timers, tf and stamps share the robot's time.
"""

from __future__ import annotations

import threading

from navlab.core.executor import Executor


class ClockFollower:
    """An executor stepper that blocks until the outside ``/clock`` reaches each event's time."""

    def __init__(self, executor: Executor) -> None:
        self.latest_ns = -1
        self._cond = threading.Condition()
        self._closed = False
        executor.add_stepper(self)

    def tick(self, t_ns: int) -> None:
        """A ``/clock`` message arrived (any thread)."""
        with self._cond:
            if t_ns > self.latest_ns:
                self.latest_ns = t_ns
                self._cond.notify_all()

    def advance_to(self, t_ns: int) -> None:
        with self._cond:
            while self.latest_ns < t_ns and not self._closed:
                self._cond.wait(0.5)

    def close(self) -> None:
        """Stop waiting (the run is ending)."""
        with self._cond:
            self._closed = True
            self._cond.notify_all()
