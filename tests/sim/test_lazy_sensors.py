"""The IMU and ground-truth (p3d) plugins build their messages only for someone: a subscriber, a recorder or
topic echo; the ground truth's pose is the same whenever it is read."""

from __future__ import annotations

from typing import Any

import pytest

from navlab import msgs
from navlab.core import Context, Node
from navlab.core.launch import start


@pytest.mark.parametrize(
    ("name", "msgtype", "per_half_s", "frame"),
    [("/imu", msgs.Imu, 50, "chassis"), ("/ground_truth/odom", msgs.Odometry, 25, "world")],  # 100 Hz, 50 Hz
)
def test_sensor_publishes_for_subscribers_and_listeners_only(
    name: str, msgtype: Any, per_half_s: int, frame: str
) -> None:
    s = start("sim")
    ex = s.executor
    topic = ex.topic(name, msgtype)
    s.run(0.5)
    assert topic.count == 0  # nobody reads it: no message built
    seen: list[Any] = []
    node = Node("reader", context=Context(ex))
    node.create_subscription(msgtype, name, seen.append, 10)
    s.run(0.5)
    assert len(seen) == per_half_s and seen[-1].header.frame_id == frame  # at its rate once subscribed
    if msgtype is msgs.Odometry:
        x, y, _ = s.node("gazebo").sim.base_pose2d()
        assert (seen[-1].pose.pose.position.x, seen[-1].pose.pose.position.y) == (x, y)
    node.destroy_node()
    s.run(0.5)
    assert topic.count == per_half_s  # unsubscribed: quiet again
    heard: list[str] = []
    ex.add_listener(lambda topic_name, _msg, _t: heard.append(topic_name))  # a recorder's or topic echo's way in
    s.run(0.5)
    assert heard.count(name) == per_half_s and len(seen) == per_half_s
