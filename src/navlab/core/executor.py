"""The deterministic simulated-time executor: clock, timer queue, topics, pacing, inbox.

One process, one thread of execution. Time is an integer count of nanoseconds. Timers are ordered
by (time, priority, sequence); published messages are queued and delivered in publish order before
simulated time advances. Physics engines register as *steppers* and are advanced to each event's
time before the event runs, so they integrate between events without Python in the loop.
"""

from __future__ import annotations

import heapq
import queue
import time
import zlib
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, Protocol

import numpy as np

from navlab.core.errors import CoreError
from navlab.core.tf import TfBuffer
from navlab.core.topics import NS_PER_S, Subscription, Timer, Topic, seconds_to_ns
from navlab.geometry import Tf
from navlab.msgs import TFMessage, type_name

__all__ = ["NS_PER_S", "Executor", "ExecutorNode", "Stepper", "Topic", "seconds_to_ns"]


class Stepper(Protocol):
    """A physics engine or anything that must integrate up to an event's time before it runs."""

    def advance_to(self, t_ns: int) -> None: ...


class ExecutorNode(Protocol):
    """What the executor needs of a node (``navlab.core.node.Node`` is one)."""

    fully_qualified_name: str

    def check_parameters(self) -> None: ...


class Executor:
    """Owns the simulated clock, the event queue, the topics, tf, services and the nodes.

    ``seed`` seeds every node's random generator; ``rate`` is the pacing (0 = as fast as
    possible, r > 0 keeps simulated time at r × wall-clock time).
    """

    def __init__(self, *, seed: int = 0, rate: float = 0.0, tf_cache_s: float = 10.0) -> None:
        if rate < 0:
            raise CoreError(f"rate must be >= 0 (0 = as fast as possible), got {rate}")
        self.seed = int(seed)
        self.rate = float(rate)
        self.now_ns = 0
        self.nodes: dict[str, Any] = {}  # full name -> Node
        self.topics: dict[str, Topic] = {}
        self.services: dict[str, Callable[[Any], Any]] = {}
        self.tf = TfBuffer(cache_ns=seconds_to_ns(tf_cache_s))
        self.tf_listeners: set[str] = set()  # nodes that read tf (a tf2 TransformListener each, in ROS)
        self._tf_sub: Subscription | None = None  # the tf buffer's subscription of /tf, and its tuple twin
        self._tf_tuples: Subscription | None = None
        self._heap: list[tuple[int, int, int, Timer]] = []
        self._parked: list[Timer] = []  # idle timers out of the queue until the graph changes (Timer.parks)
        self._seq = 0
        self._deliveries: deque[tuple[Subscription, Any]] = deque()
        self._steppers: list[Stepper] = []
        self._listeners: list[Callable[[str, Any, int], None]] = []
        self._inbox: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._remappings: dict[str, str] = {}  # for nodes constructed inside node_context
        self._stop = False
        self.stopped = False  # whether the last run ended because stop() was called
        self._running = False
        self.events = 0  # timer callbacks + message deliveries handled so far

    # --- nodes and construction context --------------------------------------------------------

    def register_node(self, node: ExecutorNode) -> None:
        """Add a node under its full name (``Node.__init__`` calls this); a name may be used once."""
        if node.fully_qualified_name in self.nodes:
            raise CoreError(f"a node named {node.fully_qualified_name!r} already exists")
        self.nodes[node.fully_qualified_name] = node

    @contextmanager
    def node_context(self, *, remappings: dict[str, str] | None = None) -> Iterator[None]:
        """Nodes constructed inside this block get these topic remappings (launch files use it)."""
        old = self._remappings
        self._remappings = dict(remappings or {})
        try:
            yield
        finally:
            self._remappings = old

    def construction_remappings(self) -> dict[str, str]:
        """The topic remappings (from -> to) for a node constructed now (see :meth:`node_context`)."""
        return dict(self._remappings)

    def make_rng(self, name: str) -> np.random.Generator:
        """A generator seeded from the run's seed and ``name`` (stable across runs and platforms)."""
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence([self.seed, zlib.crc32(name.encode())])))

    # --- topics ----------------------------------------------------------------------------------

    def topic(self, name: str, msgtype: type) -> Topic:
        """The topic ``name``, created on first use; its type must agree with earlier users."""
        t = self.topics.get(name)
        if t is None:
            t = self.topics[name] = Topic(name, msgtype)
            if name in ("/tf", "/tf_static"):
                self._attach_tf(t)
        elif type_name(t.msgtype) != type_name(msgtype):  # the same type, or navlab's rclpy-style class of it
            raise CoreError(f"topic {name!r} has type {type_name(t.msgtype)}, but {type_name(msgtype)} was asked for")
        return t

    def _attach_tf(self, topic: Topic) -> None:
        static = topic.name == "/tf_static"
        buf = self.tf

        def feed(msg: Any) -> None:
            buf.add_message(msg, static=static)

        sub = Subscription(topic.name, TFMessage, feed, "/_tf_buffer")
        topic.subscriptions.append(sub)
        if not static:
            self._tf_sub = sub

            def feed_tuples(stamped: tuple[int, Sequence[tuple[str, str, Tf]]]) -> None:
                stamp_ns, transforms = stamped
                for parent, child, tf in transforms:
                    buf.set_transform(parent.lstrip("/"), child.lstrip("/"), stamp_ns, tf)

            self._tf_tuples = Subscription(topic.name, TFMessage, feed_tuples, "/_tf_buffer")

    def send_tf_tuples(self, topic: Topic, stamp_ns: int, transforms: Sequence[tuple[str, str, Tf]]) -> bool:
        """Deliver transforms ``(parent, child, (x, y, z, qx, qy, qz, qw))`` stamped ``stamp_ns`` published on
        ``/tf`` straight to the executor's tf buffer, in the queue's order, when the buffer is the topic's only
        reader (no other subscriber, no listener); False (nothing done) otherwise: the caller then publishes the
        ``TFMessage``. The buffer receives exactly what the message would give it (``TfBuffer.add_message``)."""
        subs, direct = topic.subscriptions, self._tf_tuples
        if direct is None or self._listeners or len(subs) != 1 or subs[0] is not self._tf_sub:
            return False
        topic.count += 1
        self._deliveries.append((direct, (stamp_ns, transforms)))
        if not self._running:
            self._drain()
        return True

    def publish(self, topic: Topic, msg: Any, *, latch_key: int | None = None) -> None:
        """Queue ``msg`` for every subscriber of ``topic`` (delivered before time advances).

        ``latch_key`` (a latched publisher's id) keeps the message for late subscribers, one per
        publisher, as ROS's transient_local durability does.
        """
        topic.count += 1
        if latch_key is not None:
            topic.latched[latch_key] = msg
        for sub in topic.subscriptions:
            self._deliveries.append((sub, msg))
        for listener in self._listeners:
            listener(topic.name, msg, self.now_ns)
        if not self._running:  # published from user code between runs: deliver now
            self._drain()

    def add_listener(self, fn: Callable[[str, Any, int], None]) -> None:
        """Call ``fn(topic, msg, t_ns)`` for every message published (recording, echo, hz)."""
        self._listeners.append(fn)
        self._wake_parked()

    def remove_listener(self, fn: Callable[[str, Any, int], None]) -> None:
        """Stop calling a listener added with :meth:`add_listener`."""
        self._listeners.remove(fn)

    @property
    def has_listeners(self) -> bool:
        """Whether any listener (a recorder, ``topic echo``) sees every message, subscribed or not."""
        return bool(self._listeners)

    def subscribe(self, sub: Subscription, msgtype: type) -> None:
        """Attach a subscription; each latched publisher of the topic hands it its last message at once."""
        topic = self.topic(sub.topic, msgtype)
        topic.subscriptions.append(sub)
        for msg in topic.latched.values():
            self._deliveries.append((sub, msg))
        self._wake_parked()

    def _wake_parked(self) -> None:
        """The graph changed: every parked timer goes back in the queue (it parks again if still idle)."""
        parked, self._parked = self._parked, []
        for timer in parked:
            if not timer.cancelled:
                timer.wake(self.now_ns)

    # --- timers, services, steppers, inbox -------------------------------------------------------

    def schedule(self, timer: Timer, t_ns: int) -> None:
        """Put ``timer`` in the queue to fire at ``t_ns``."""
        self._seq += 1
        heapq.heappush(self._heap, (t_ns, timer.priority, self._seq, timer))

    def add_stepper(self, stepper: Stepper) -> None:
        """Advance ``stepper`` to every event's time before the event runs."""
        self._steppers.append(stepper)

    def add_service(self, name: str, callback: Callable[[Any], Any]) -> None:
        """Register a callable service (ROS services, synchronous in simulated time)."""
        if name in self.services:
            raise CoreError(f"service {name!r} is already offered")
        self.services[name] = callback

    def call_service(self, name: str, request: Any = None) -> Any:
        """Call a service by its full name and return its response."""
        try:
            fn = self.services[name]
        except KeyError:
            known = ", ".join(sorted(self.services)) or "none"
            raise CoreError(f"no service {name!r} (offered: {known})") from None
        result = fn(request)
        self._drain()
        return result

    def post(self, fn: Callable[[], None]) -> None:
        """Thread-safe: run ``fn`` in the executor's thread before the next event."""
        self._inbox.put(fn)

    def stop(self) -> None:
        """Make the current :meth:`run` return after the event being handled (thread-safe)."""
        self._stop = True

    # --- running ---------------------------------------------------------------------------------

    def _drain_inbox(self) -> None:
        inbox = self._inbox
        while not inbox.empty():  # this thread is the only consumer: non-empty means get() returns at once
            inbox.get_nowait()()

    def _drain(self) -> None:
        deliveries = self._deliveries
        while deliveries:
            sub, msg = deliveries.popleft()
            self.events += 1
            sub.callback(msg)

    def _advance(self, t_ns: int) -> None:
        for stepper in self._steppers:
            stepper.advance_to(t_ns)
        self.now_ns = t_ns

    def _pace(self, t_ns: int, sim0: int, wall0: float) -> None:
        target = wall0 + (t_ns - sim0) / NS_PER_S / self.rate
        while True:
            self._drain_inbox()
            delay = target - time.perf_counter()
            if delay <= 0:
                return
            time.sleep(min(delay, 0.01))

    def run(self, duration: float) -> None:
        """Advance simulated time by ``duration`` seconds, handling every event on the way."""
        self.run_until(None, timeout=duration)

    def run_until(self, predicate: Callable[[], bool] | None, *, timeout: float) -> bool:
        """Run until ``predicate()`` is true (checked after each event) or ``timeout`` simulated seconds pass.

        Returns whether the predicate became true (False on timeout or :meth:`stop`).
        """
        for node in list(self.nodes.values()):
            node.check_parameters()
        self._running = True
        try:
            return self._run_until(predicate, seconds_to_ns(timeout))
        finally:
            self._running = False

    def _run_until(self, predicate: Callable[[], bool] | None, timeout_ns: int) -> bool:
        end = self.now_ns + timeout_ns
        sim0, wall0 = self.now_ns, time.perf_counter()
        self._stop = self.stopped = False
        heap, deliveries, inbox, heappop = self._heap, self._deliveries, self._inbox, heapq.heappop
        self._drain_inbox()
        self._drain()
        if predicate is not None and predicate():
            return True
        while heap and heap[0][0] <= end and not self._stop:
            t_ns, _, _, timer = heappop(heap)
            if timer.cancelled:
                continue
            if timer.idle is not None and timer.idle():  # nothing to do then: no physics step up to it either
                if timer.parks:  # out of the queue until a subscription or a listener is added
                    timer.parked = True
                    self._parked.append(timer)
                else:
                    timer.skip()
                continue
            if t_ns > self.now_ns:
                if self.rate > 0:
                    self._pace(t_ns, sim0, wall0)
                elif not inbox.empty():
                    self._drain_inbox()
                self._advance(t_ns)
            self.events += 1
            timer.fire()
            if deliveries:
                self._drain()
            if predicate is not None and predicate():
                return True
        if not self._stop and end > self.now_ns:
            if self.rate > 0:
                self._pace(end, sim0, wall0)
            self._advance(end)
            self._drain_inbox()
            self._drain()
        self.stopped = self._stop
        return predicate is not None and predicate()

    def spin(self) -> None:
        """Run until :meth:`stop` is called (use with ``rate > 0`` and another thread posting inputs)."""
        self.stopped = False
        while not self.stopped:
            self.run_until(lambda: self._stop, timeout=3600.0)
            self.stopped = self.stopped or self._stop
