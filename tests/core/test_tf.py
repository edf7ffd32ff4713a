"""tf buffer: chains, static transforms, interpolation, errors — against hand-computed values."""

import math

import pytest

from navlab import msgs
from navlab.core import Context, Executor, Node, TfBuffer, TfError


def _buf() -> TfBuffer:
    buf = TfBuffer()
    buf.set_transform("chassis", "laser", 0, (0.1, 0.0, 0.06, 0.0, 0.0, 0.0, 1.0), static=True)
    q = msgs.quaternion_from_yaw(math.pi / 2)
    buf.set_transform("odom", "chassis", 0, (1.0, 2.0, 0.0, 0.0, 0.0, q.z, q.w))
    q2 = msgs.quaternion_from_yaw(math.pi)
    buf.set_transform("odom", "chassis", 1_000_000_000, (3.0, 2.0, 0.0, 0.0, 0.0, q2.z, q2.w))
    buf.set_transform("map", "odom", 0, (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), static=True)
    return buf


def test_chain_lookup_map_to_laser():
    # At t=0 chassis is at (1, 2) facing +y; the laser 0.1 m ahead is at (1, 2.1) in odom, (1.5, 2.1) in map.
    x, y, yaw = _buf().lookup_pose2d("map", "laser", 0)
    assert (x, y, yaw) == pytest.approx((1.5, 2.1, math.pi / 2))


def test_interpolation_halfway():
    x, y, yaw = _buf().lookup_pose2d("odom", "chassis", 500_000_000)
    assert (x, y, yaw) == pytest.approx((2.0, 2.0, 3 * math.pi / 4))


def test_inverse_lookup():
    x, y, yaw = _buf().lookup_pose2d("laser", "odom", 0)
    # odom origin seen from the laser at (1, 2.1) facing +y: it lies 2.1 m behind-right.
    assert (x, y, yaw) == pytest.approx((-2.1, 1.0, -math.pi / 2))


def test_latest_common_time():
    assert _buf().lookup_pose2d("map", "chassis")[:2] == pytest.approx((3.5, 2.0))


def test_unknown_frame_and_extrapolation():
    buf = _buf()
    with pytest.raises(TfError, match="base_link"):
        buf.lookup("map", "base_link", 0)
    with pytest.raises(TfError, match="future"):
        buf.lookup("odom", "chassis", 2_000_000_000)
    buf.tolerance_ns = 1_500_000_000
    assert buf.lookup_pose2d("odom", "chassis", 2_000_000_000)[0] == pytest.approx(3.0)


def test_disconnected_frames():
    buf = _buf()
    buf.set_transform("world", "camera", 0, (0, 0, 0, 0, 0, 0, 1), static=True)
    with pytest.raises(TfError, match="not connected"):
        buf.lookup("map", "camera", 0)


def test_executor_feeds_tf_from_topics():
    ex = Executor()
    node = Node("pub", context=Context(ex))
    node.send_static_transform(msgs.transform_stamped(0, "chassis", "laser", 0.0, 0.0, 0.0, 0.06))
    node.create_timer(
        0.1,
        lambda: node.send_transform(msgs.transform_stamped(ex.now_ns, "odom", "chassis", ex.now_ns / 1e9, 0.0, 0.0)),
    )
    ex.run(1.0)
    assert ex.tf.lookup_pose2d("odom", "laser", 550_000_000)[0] == pytest.approx(0.55)


def test_edges_above_the_common_ancestor_do_not_limit_lookups():
    buf = TfBuffer()
    buf.set_transform("map", "odom", 5_000_000_000, (0, 0, 0, 0, 0, 0, 1))  # localization started late
    buf.set_transform("odom", "chassis", 0, (0.0, 0, 0, 0, 0, 0, 1))
    buf.set_transform("odom", "chassis", 1_000_000_000, (1.0, 0, 0, 0, 0, 0, 1))
    assert buf.lookup_pose2d("odom", "chassis", 500_000_000)[0] == pytest.approx(0.5)
    assert buf.lookup_pose2d("odom", "chassis")[0] == pytest.approx(1.0)
    with pytest.raises(TfError, match="past"):
        buf.lookup("map", "chassis", 500_000_000)


def test_pose_at_a_stamp_falls_back_on_the_latest_only_outside_the_history():
    buf = _buf()
    assert buf.lookup_pose2d_or_latest("map", "laser", 500_000_000) == buf.lookup_pose2d("map", "laser", 500_000_000)
    latest = buf.lookup_pose2d("map", "laser")
    assert buf.lookup_pose2d_or_latest("map", "laser", 1_200_000_000) == latest  # after the newest odometry
    buf.tolerance_ns = 300_000_000
    assert buf.lookup_pose2d_or_latest("map", "laser", 1_200_000_000) == latest  # within tolerance: the newest
    with pytest.raises(TfError, match="base_link"):
        buf.lookup_pose2d_or_latest("map", "base_link", 0)


def test_a_remembered_lookup_is_forgotten_when_a_transform_arrives():
    buf = _buf()
    assert buf.lookup_pose2d("map", "chassis")[:2] == pytest.approx((3.5, 2.0))
    assert buf.lookup_pose2d("map", "chassis", 500_000_000)[:2] == pytest.approx((2.5, 2.0))
    buf.set_transform("odom", "chassis", 2_000_000_000, (5.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    buf.set_transform("map", "odom", 0, (1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), static=True)  # amcl's correction
    assert buf.lookup_pose2d("map", "chassis")[:2] == pytest.approx((6.5, 2.0))
    assert buf.lookup_pose2d("map", "chassis", 500_000_000)[:2] == pytest.approx((3.5, 2.0))


def test_a_remembered_lookup_follows_the_edges_it_read():
    buf = _buf()
    assert buf.lookup_pose2d("odom", "chassis")[:2] == pytest.approx((3.0, 2.0))
    buf.set_transform("map", "odom", 0, (1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), static=True)  # not on odom -> chassis
    assert buf.lookup_pose2d("odom", "chassis")[:2] == pytest.approx((3.0, 2.0))
    assert buf.lookup_pose2d("map", "chassis")[:2] == pytest.approx((4.5, 2.0))
    # messages, newest last (appended as they come) and one out of order (put in its place)
    later = msgs.transform_stamped(2_000_000_000, "odom", "chassis", 5.0, 2.0, 0.0)
    buf.add_message(msgs.TFMessage([later]))
    assert buf.lookup_pose2d("odom", "chassis")[:2] == pytest.approx((5.0, 2.0))
    assert buf.lookup_pose2d("map", "chassis")[:2] == pytest.approx((6.5, 2.0))
    assert buf.lookup_pose2d("odom", "chassis", 1_500_000_000)[:2] == pytest.approx((4.0, 2.0))
    between = msgs.transform_stamped(1_500_000_000, "odom", "chassis", 7.0, 2.0, 0.0)
    buf.add_message(msgs.TFMessage([between]))
    assert buf.lookup_pose2d("odom", "chassis", 1_500_000_000)[:2] == pytest.approx((7.0, 2.0))
    assert buf.lookup_pose2d("odom", "chassis")[:2] == pytest.approx((5.0, 2.0))


def _tf_run(*, subscriber: bool, listener: bool) -> tuple[list[tuple[float, ...]], list, list, int]:
    """Two nodes send odom->base as tuples; a third, fed by a topic published just before each transform, looks tf
    up at once. Returns (lookups, /tf messages a subscriber got, messages a listener saw, /tf's count)."""
    ex = Executor()
    ctx = Context(ex)
    sender, reader = Node("odom_pub", context=ctx), Node("reader", context=ctx)
    tick = sender.create_publisher(msgs.String, "tick", 10)
    seen: list[tuple[float, ...]] = []

    def on_tick(_msg: object) -> None:
        try:
            seen.append(ex.tf.lookup_pose2d("odom", "base", None))
        except TfError:
            seen.append(())

    reader.create_subscription(msgs.String, "tick", on_tick, 10)
    got: list = []
    if subscriber:
        reader.create_subscription(msgs.TFMessage, "/tf", got.append, 10)
    heard: list = []
    if listener:
        ex.add_listener(lambda name, msg, _t: heard.append(msg) if name == "/tf" else None)
    k = [0]

    def send() -> None:
        k[0] += 1
        q = msgs.quaternion_from_yaw(0.1 * k[0])
        tick.publish(msgs.String(data=""))  # queued before the transform: its reader sees tf without it
        sender.send_transform_tuples(ex.now_ns, [("odom", "base", (0.5 * k[0], 1.0, 0.0, 0.0, 0.0, q.z, q.w))])
        seen.append(ex.tf.lookup_pose2d("odom", "base", None) if k[0] > 1 else ())  # still queued: the old one

    sender.create_timer(0.1, send)
    ex.run(0.5)
    seen.append(ex.tf.lookup_pose2d("odom", "base", ex.now_ns))
    return seen, got, heard, ex.topic("/tf", msgs.TFMessage).count


def test_transform_tuples_reach_tf_in_queue_order_and_as_messages_for_readers():
    alone, _, _, count = _tf_run(subscriber=False, listener=False)
    assert count == 5 and alone[-1] == pytest.approx((2.5, 1.0, 0.5))
    assert alone[0] == () and alone[2] == pytest.approx((0.5, 1.0, 0.1))  # delivered after the tick, as a message
    for subscriber, listener in ((True, False), (False, True)):
        seen, got, heard, count = _tf_run(subscriber=subscriber, listener=listener)
        assert seen == alone and count == 5  # the same lookups, bit for bit, message or not
        msgs_out = got or heard
        assert len(msgs_out) == 5
        last = msgs_out[-1].transforms[0]
        assert (last.header.frame_id, last.child_frame_id, msgs.ns_from_time(last.header.stamp)) == (
            "odom",
            "base",
            500_000_000,
        )
        assert (last.transform.translation.x, last.transform.rotation.z) == (2.5, msgs.quaternion_from_yaw(0.5).z)


def test_history_keeps_cache_time_as_tf2_prunes_it() -> None:
    """Entries older than ``cache_ns`` before the newest are gone (a lookup there extrapolates into the past), the
    rest interpolate, also after out-of-order stamps and many more entries than are kept (tf2's pruneList rule)."""
    cache, step = 1_000_000_000, 33_333_333
    buf = TfBuffer(cache_ns=cache)
    kept: list[int] = []  # the stamps tf2 would keep
    stamps = [k * step for k in range(900)] + [899 * step - 5 * step // 2, 880 * step + 7]  # two out of order
    for t in stamps:
        buf.set_transform("odom", "chassis", t, (t / 1e9, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
        kept = sorted([*kept, t])
        kept = [s for s in kept if kept[-1] - s <= cache]
    oldest, newest = kept[0], kept[-1]
    assert buf.lookup("odom", "chassis", oldest)[0] == oldest / 1e9
    assert buf.lookup("odom", "chassis", newest)[0] == newest / 1e9
    mid = (kept[1] + kept[2]) // 2
    assert buf.lookup("odom", "chassis", mid)[0] == pytest.approx(mid / 1e9)
    with pytest.raises(TfError, match="into the past"):
        buf.lookup("odom", "chassis", oldest - 1)
    assert buf.lookup_pose2d_or_latest("odom", "chassis", oldest - 1)[0] == newest / 1e9  # falls back to the latest
