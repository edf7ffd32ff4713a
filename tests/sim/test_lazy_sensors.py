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


def test_imu_read_after_sleeping_gives_what_an_imu_read_all_along_gives() -> None:
    """While nobody reads the IMU, physics steps skip MuJoCo's sensors; the first readings after a subscriber
    appears are the ones a run with a subscriber from the start gives (orientation: no noise), and the motion
    is the same bit for bit."""
    runs = []
    for late in (False, True):
        s = start("sim")
        ex = s.executor
        seen: list[Any] = []
        node = Node("reader", context=Context(ex))
        drive = node.create_publisher(msgs.Twist, "cmd_vel", 10)
        node.create_timer(0.1, lambda drive=drive: drive.publish(msgs.twist(0.4, 0.8)))
        if not late:
            node.create_subscription(msgs.Imu, "/imu", seen.append, 10)
        s.run(0.5)
        if late:
            node.create_subscription(msgs.Imu, "/imu", seen.append, 10)
        s.run(0.1)
        sim = s.node("gazebo").sim
        runs.append(([(msgs.stamp_ns(m), msgs.xyzw(m.orientation)) for m in seen], sim.data.qpos.tobytes()))
    (always, qpos0), (woken, qpos1) = runs
    assert len(woken) == 10 and woken == always[-10:]
    assert woken[0][1] != always[-11][1]  # the robot turns: each reading is new
    assert qpos1 == qpos0
