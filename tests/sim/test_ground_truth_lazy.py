"""The ground-truth plugin (p3d) builds /ground_truth/odom only for someone: a subscriber, a recorder or topic
echo; its pose is the same whenever it is read."""

from __future__ import annotations

from typing import Any

from navlab import msgs
from navlab.core import Node
from navlab.core.launch import start


def test_ground_truth_publishes_for_subscribers_and_listeners_only() -> None:
    s = start("sim")
    ex = s.executor
    topic = ex.topic("/ground_truth/odom", msgs.Odometry)
    s.run(0.5)
    assert topic.count == 0  # nobody reads it: no message built
    seen: list[Any] = []
    node = Node(ex, name="truth_reader")
    node.create_subscription(msgs.Odometry, "/ground_truth/odom", seen.append, 10)
    s.run(0.5)
    assert len(seen) == 25 and seen[-1].header.frame_id == "world"  # 50 Hz once subscribed
    x, y, _ = s.node("gazebo").sim.base_pose2d()
    assert (seen[-1].pose.pose.position.x, seen[-1].pose.pose.position.y) == (x, y)
    node.destroy_node()
    s.run(0.5)
    assert topic.count == 25  # unsubscribed: quiet again
    heard: list[str] = []
    ex.add_listener(lambda name, _msg, _t: heard.append(name))  # a recorder's or topic echo's way in
    s.run(0.5)
    assert heard.count("/ground_truth/odom") == 25 and len(seen) == 25
