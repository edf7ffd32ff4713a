"""Executor: ordering, timers in simulated time, determinism, pacing, inbox."""

import hashlib
import itertools
import threading
import time

import pytest

from navlab import msgs
from navlab.core import Context, CoreError, Executor, Node


def test_timers_fire_at_simulated_rate():
    ex = Executor()
    node = Node("n", context=Context(ex))
    stamps: list[int] = []
    node.create_timer(0.025, lambda: stamps.append(ex.now_ns))  # 40 Hz
    ex.run(2.0)
    assert len(stamps) == 80
    assert stamps[0] == 25_000_000 and stamps[-1] == 2_000_000_000
    assert all(b - a == 25_000_000 for a, b in itertools.pairwise(stamps))


def test_order_is_time_then_priority_then_sequence():
    ex = Executor()
    node = Node("n", context=Context(ex))
    order: list[str] = []
    node.create_timer(0.1, lambda: order.append("b0"), priority=0)
    node.create_timer(0.1, lambda: order.append("a-1"), priority=-1)
    node.create_timer(0.1, lambda: order.append("c0"), priority=0)
    node.create_timer(0.05, lambda: order.append("fast"))
    ex.run(0.1)
    # At t=0.1 all four are due: priority first, then the order they were (re)scheduled in.
    assert order == ["fast", "a-1", "b0", "c0", "fast"]


def test_messages_delivered_in_publish_order_before_time_advances():
    ex = Executor()
    a, b = Node("a", context=Context(ex)), Node("b", context=Context(ex))
    pub = a.create_publisher(msgs.Float64, "x")
    seen: list[tuple[float, int]] = []
    b.create_subscription(msgs.Float64, "x", lambda m: seen.append((m.data, ex.now_ns)))

    def burst() -> None:
        for i in range(3):
            pub.publish(msgs.Float64(data=float(i)))

    a.create_timer(0.5, burst)
    ex.run(1.0)
    assert seen == [(0.0, 5e8), (1.0, 5e8), (2.0, 5e8), (0.0, 1e9), (1.0, 1e9), (2.0, 1e9)]


def _stream_hash(seed: int) -> str:
    ex = Executor(seed=seed)
    h = hashlib.sha256()

    class Noisy(Node):
        def __init__(self, ex: Executor, i: int) -> None:
            super().__init__(f"noisy{i}", context=Context(ex))
            self.pub = self.create_publisher(msgs.Float64, "noise")
            self.create_timer(0.01 * (i + 1), lambda: self.pub.publish(msgs.Float64(data=self.rng.normal())))

    for i in range(3):
        Noisy(ex, i)
    sink = Node("sink", context=Context(ex))
    sink.create_subscription(msgs.Float64, "noise", lambda m: h.update(f"{ex.now_ns}:{m.data!r}".encode()))
    ex.run(5.0)
    return h.hexdigest()


def test_same_seed_same_stream_different_seed_different_stream():
    assert _stream_hash(7) == _stream_hash(7)
    assert _stream_hash(7) != _stream_hash(8)


def test_latched_topic_reaches_late_subscriber():
    ex = Executor()
    pub = Node("map_server", context=Context(ex)).create_publisher(msgs.String, "map", latched=True)
    pub.publish(msgs.String(data="the map"))
    got: list[str] = []
    Node("late", context=Context(ex)).create_subscription(msgs.String, "/map", lambda m: got.append(m.data))
    ex.run(0.1)
    assert got == ["the map"]


def test_topic_type_conflict_is_refused():
    ex = Executor()
    Node("a", context=Context(ex)).create_publisher(msgs.Float64, "x")
    with pytest.raises(CoreError, match="std_msgs/msg/Float64"):
        Node("b", context=Context(ex)).create_subscription(msgs.String, "x", print)


def test_unknown_message_type_is_refused_with_suggestion():
    with pytest.raises(msgs.MessageTypeError, match="geometry_msgs/msg/Twist"):
        msgs.get_type("geometry_msgs/Twst")


def test_steppers_advance_to_each_event_time():
    ex = Executor()
    calls: list[int] = []

    class Physics:
        def advance_to(self, t_ns: int) -> None:
            calls.append(t_ns)

    ex.add_stepper(Physics())
    Node("n", context=Context(ex)).create_timer(0.25, lambda: None)
    ex.run(1.0)
    assert calls == [250_000_000, 500_000_000, 750_000_000, 1_000_000_000]


@pytest.mark.parametrize("rate", [2.0, 5.0])
def test_pacing_keeps_asked_rate(rate: float):
    ex = Executor(rate=rate)
    Node("n", context=Context(ex)).create_timer(0.01, lambda: None)
    t0 = time.perf_counter()
    ex.run(1.0)
    wall = time.perf_counter() - t0
    assert abs(wall - 1.0 / rate) <= 0.05 * (1.0 / rate)


def test_inbox_runs_inputs_from_other_threads():
    ex = Executor(rate=10.0)
    node = Node("n", context=Context(ex))
    pub = node.create_publisher(msgs.String, "cmd")
    got: list[str] = []
    node.create_subscription(msgs.String, "cmd", lambda m: got.append(m.data))
    node.create_timer(0.1, lambda: None)
    t = threading.Thread(target=lambda: (time.sleep(0.05), ex.post(lambda: pub.publish(msgs.String(data="hi")))))
    t.start()
    ex.run(1.0)
    t.join()
    assert got == ["hi"]


def test_run_until_stops_when_condition_holds():
    ex = Executor()
    node = Node("n", context=Context(ex))
    count = [0]
    node.create_timer(0.1, lambda: count.__setitem__(0, count[0] + 1))
    assert ex.run_until(lambda: count[0] >= 5, timeout=10.0)
    assert ex.now_ns == 500_000_000
    assert not ex.run_until(lambda: count[0] >= 1000, timeout=1.0)


def test_stop_from_another_thread_ends_chunked_runs():
    from navlab.core.runner import run_for

    ex = Executor(rate=10.0)
    Node("n", context=Context(ex)).create_timer(0.05, lambda: None)
    threading.Timer(0.05, lambda: ex.post(ex.stop)).start()
    run_for(ex, 100.0, quiet=True, chunk=0.2)  # 10 s of wall time if the stop were lost
    assert ex.stopped and ex.now_ns < 2_000_000_000


def test_idle_timer_firings_run_nothing_and_step_no_physics() -> None:
    ex = Executor()
    steps: list[int] = []

    class Stepper:
        def advance_to(self, t_ns: int) -> None:
            steps.append(t_ns)

    ex.add_stepper(Stepper())
    node = Node("sensor", context=Context(ex))
    readers: list[int] = []
    fired: list[int] = []
    node.create_timer(0.01, lambda: fired.append(ex.now_ns), idle=lambda: not readers)
    node.create_timer(0.05, lambda: None)
    ex.run(0.1)
    assert fired == [] and steps == [50_000_000, 100_000_000]  # only the busy timer's times
    readers.append(1)
    ex.run(0.03)
    assert fired == [110_000_000, 120_000_000, 130_000_000]  # on the same 10 ms grid once read


def test_a_timer_idle_until_the_graph_changes_leaves_the_queue_and_wakes_on_its_grid() -> None:
    """A lazy sensor (idle while nobody subscribes or listens) is not asked again while parked, and fires on the
    same ticks as a sensor asked at every tick: from the first tick after a subscription or a listener appears."""
    runs = []
    for parks in (False, True):
        ex = Executor()
        sensor, other = Node("sensor", context=Context(ex)), Node("other", context=Context(ex))
        pub = sensor.create_publisher(msgs.String, "reading", 10)
        fired: list[int] = []
        asked = [0]

        def idle(pub=pub, ex=ex, asked=asked) -> bool:
            asked[0] += 1
            return not (pub.get_subscription_count() or ex.has_listeners)

        sensor.create_timer(
            0.01, lambda fired=fired, ex=ex: fired.append(ex.now_ns), idle=idle, idle_until_graph_changes=parks
        )
        sub = []
        # a subscription made inside a callback at 45 ms, between two ticks of the 10 ms grid
        other.create_timer(
            0.045,
            lambda sub=sub, other=other: (
                None if sub else sub.append(other.create_subscription(msgs.String, "reading", lambda _m: None, 10))
            ),
        )
        ex.run(0.069)
        busy = fired[:]
        other.destroy_node()  # nobody subscribes: quiet again
        asked[0] = 0
        ex.run(0.05)
        quiet = (fired[len(busy) :], asked[0])
        ex.add_listener(lambda *_: None)  # a recorder: wakes it
        ex.run(0.02)
        runs.append((busy, quiet, fired[len(busy) :]))
    (busy0, quiet0, after0), (busy1, quiet1, after1) = runs
    assert busy1 == busy0 == [50_000_000, 60_000_000]  # the first tick after the subscription at 45 ms
    assert quiet0 == ([], 5) and quiet1 == ([], 1)  # asked at each of the 5 ticks, or once and then parked
    assert after1 == after0 == [120_000_000, 130_000_000]  # woken at 119 ms: the next ticks of its grid
