"""The IMU plugin builds /imu messages only for someone: a subscriber, a recorder or topic echo."""

from __future__ import annotations

from typing import Any

from navlab import msgs
from navlab.core import Node
from navlab.core.launch import start


def test_imu_publishes_for_subscribers_and_listeners_only() -> None:
    s = start("sim")
    ex = s.executor
    topic = ex.topic("/imu", msgs.Imu)
    s.run(0.5)
    assert topic.count == 0  # nobody reads it: no message built
    seen: list[Any] = []
    node = Node(ex, name="imu_reader")
    node.create_subscription(msgs.Imu, "/imu", seen.append, 10)
    s.run(0.5)
    assert len(seen) == 50 and seen[-1].header.frame_id == "chassis"  # 100 Hz once subscribed
    node.destroy_node()
    s.run(0.5)
    assert topic.count == 50  # unsubscribed: quiet again
    heard: list[str] = []
    ex.add_listener(lambda name, _msg, _t: heard.append(name))  # a recorder's or topic echo's way in
    s.run(0.5)
    assert heard.count("/imu") == 50 and len(seen) == 50
