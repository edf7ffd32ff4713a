"""Topics, subscriptions, publishers and timers: the pieces the executor and nodes share.

This module sits under both :mod:`navlab.core.executor` and :mod:`navlab.core.node` and imports
neither: a publisher and a timer reach their executor through the small protocols below.
Time is an integer count of simulated nanoseconds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from navlab.core.errors import CoreError

NS_PER_S = 1_000_000_000


def seconds_to_ns(seconds: float) -> int:
    """Simulated seconds to integer nanoseconds (rounded)."""
    return round(seconds * NS_PER_S)


@dataclass
class Subscription:
    """A callback attached to a topic (``node`` is the subscribing node's full name)."""

    topic: str
    msgtype: type
    callback: Callable[[Any], None]
    node: str


@dataclass
class Topic:
    """A named topic: its type, who publishes and subscribes, and each latched publisher's last message."""

    name: str
    msgtype: type
    publishers: list[str] = field(default_factory=list)
    subscriptions: list[Subscription] = field(default_factory=list)
    latched: dict[int, Any] = field(default_factory=dict)  # id(publisher) -> last message
    count: int = 0


class MessageBus(Protocol):
    """What a publisher needs of its executor."""

    def publish(self, topic: Topic, msg: Any, *, latch_key: int | None = None) -> None: ...


class TimerQueue(Protocol):
    """What a timer needs of its executor."""

    def schedule(self, timer: Timer, t_ns: int) -> None: ...


class Publisher:
    """Publishes messages of one type on one topic."""

    def __init__(self, bus: MessageBus, topic: Topic, *, latched: bool) -> None:
        self._bus = bus
        self.topic = topic
        self.latched = latched

    @property
    def topic_name(self) -> str:
        """The resolved topic name."""
        return self.topic.name

    def publish(self, msg: Any) -> None:
        """Send ``msg`` to every subscriber."""
        self._bus.publish(self.topic, msg, latch_key=id(self) if self.latched else None)

    def get_subscription_count(self) -> int:
        """How many subscriptions the topic has."""
        return len(self.topic.subscriptions)


class Timer:
    """Calls ``callback`` every ``period_ns`` of simulated time, at ``start + k·period``.

    ``idle`` (optional) tells, at a firing time, that the callback would do nothing now (a sensor nobody
    reads): the executor then skips that firing without running it or integrating physics up to it.
    ``idle_until_graph_changes``: ``idle`` depends only on the graph (who subscribes, whether a recorder
    listens), as ROS's lazy publishers ask ``get_num_connections``: an idle timer then leaves the queue and
    the executor wakes it, at its next tick, when a subscription or a listener is added.
    """

    def __init__(
        self,
        queue: TimerQueue,
        period_ns: int,
        callback: Callable[[], None],
        priority: int,
        start_ns: int,
        idle: Callable[[], bool] | None = None,
        *,
        idle_until_graph_changes: bool = False,
    ) -> None:
        if period_ns <= 0:
            raise CoreError(f"timer period must be > 0 s, got {period_ns / 1e9}")
        self._queue = queue
        self.period_ns = period_ns
        self.callback = callback
        self.idle = idle
        self.parks = idle is not None and idle_until_graph_changes
        self.parked = False  # out of the queue (the executor parked it) until the graph changes
        self.priority = priority
        self.cancelled = False
        self._start = start_ns
        self._k = 1
        queue.schedule(self, start_ns + period_ns)

    def fire(self) -> None:
        """Run the callback and schedule the next firing (called by the executor)."""
        self._k += 1
        self._queue.schedule(self, self._start + self._k * self.period_ns)
        self.callback()

    def skip(self) -> None:
        """Schedule the next firing without running the callback (an idle firing)."""
        self._k += 1
        self._queue.schedule(self, self._start + self._k * self.period_ns)

    def wake(self, now_ns: int) -> None:
        """Put a parked timer (see ``idle_until_graph_changes``) back in the queue at its first tick after
        ``now_ns``: the ticks it was parked over were idle."""
        self.parked = False
        self._k = max(self._k + 1, (now_ns - self._start) // self.period_ns + 1)
        self._queue.schedule(self, self._start + self._k * self.period_ns)

    def cancel(self) -> None:
        """Stop the timer."""
        self.cancelled = True
