"""The viewer's pace keeper: simulated time at a chosen multiple of wall-clock time, with pause and step.

:class:`Pacer` is thread-safe: the server's thread pauses, resumes and changes the speed while the
executor's thread calls :meth:`Pacer.tick` every pacing period.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable


class Pacer:
    """Keeps simulated time at ``speed`` × wall-clock time (0: as fast as possible) and pauses; thread-safe.

    While paused, :meth:`step` lets the executor go on to its next event (at most one pacing period of
    simulated time): that is how an input queued in its inbox is applied during a pause.
    """

    def __init__(self, speed: float = 1.0) -> None:
        self._lock = threading.Lock()
        self._resume = threading.Event()
        self._resume.set()
        self._step = threading.Event()
        self.closed = False
        self.speed = float(speed)
        self._anchor: tuple[int, float] | None = None

    @property
    def paused(self) -> bool:
        """Whether simulated time is held."""
        return not self._resume.is_set()

    def set_speed(self, speed: float) -> None:
        """Change the pace (re-anchored: no catching up)."""
        with self._lock:
            self.speed = float(speed)
            self._anchor = None

    def pause(self) -> None:
        """Hold simulated time at the next pacing tick."""
        self._step.clear()
        self._resume.clear()

    def resume(self) -> None:
        """Let simulated time run again."""
        with self._lock:
            self._anchor = None
        self._resume.set()
        self._step.set()

    def step(self) -> None:
        """While paused: let the executor reach its next event (an input waits in its inbox)."""
        self._step.set()

    def close(self) -> None:
        """Release a paused executor for good."""
        self.closed = True
        self._resume.set()
        self._step.set()

    def tick(self, now_ns: int, idle: Callable[[], None] | None = None) -> None:
        """Called every few simulated ms in the executor's thread: wait while paused (calling ``idle`` every
        50 ms, returning early on :meth:`step`) or while ahead of the pace."""
        while self.paused and not self.closed:
            if self._step.wait(0.05):
                self._step.clear()
                if self.paused:
                    return  # one step for an input, then held again at the next tick
                break
            if idle is not None:
                idle()
        with self._lock:
            speed = self.speed
            if speed <= 0 or self.closed:
                self._anchor = None
                return
            wall = time.perf_counter()
            if self._anchor is None:
                self._anchor = (now_ns, wall)
                return
            sim0, wall0 = self._anchor
        target = wall0 + (now_ns - sim0) / 1e9 / speed
        delay = target - wall
        if delay < -0.25:  # fell behind (a heavy step): re-anchor rather than rush to catch up
            with self._lock:
                self._anchor = (now_ns, wall)
        elif delay > 0:
            time.sleep(min(delay, 0.25))
