"""``/joint_states`` goes straight to robot_state_publisher while it is the topic's only reader; the wheels' tf
is the same either way, and a subscriber (or a recorder) gets every JointState message at 30 Hz; ``/odom``'s
messages hold the pose of the odom tf."""

from __future__ import annotations

from typing import Any

from sim_helpers import make_mybot, make_room

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.sim import launch_sim
from navlab.sim.plugins import joint_motion


def _drive(subscribe: bool, listen: bool = False) -> tuple[dict[tuple[int, str], Any], list[Any], int]:
    """Drive 1 s in an arc; (every non-static tf the buffer got, keyed (stamp, child), the JointState messages a
    subscriber got, the topic's message count)."""
    ex = Executor(seed=3)
    launch_sim(ex, world=make_room(), robot=make_mybot())
    got: dict[tuple[int, str], Any] = {}
    set_transform = ex.tf.set_transform

    def spy(parent: str, child: str, t_ns: int, tf: Any, *, static: bool = False) -> None:
        if not static:
            got[(t_ns, child)] = tf
        set_transform(parent, child, t_ns, tf, static=static)

    ex.tf.set_transform = spy  # type: ignore[method-assign]
    node = Node("driver", context=Context(ex))
    cmd = node.create_publisher(msgs.Twist, "cmd_vel", 10)
    node.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.4, 0.8)))
    seen: list[Any] = []
    if subscribe:
        node.create_subscription(msgs.JointState, "joint_states", seen.append, 10)
        node.create_subscription(msgs.Odometry, "odom", seen.append, 10)
    if listen:
        ex.add_listener(lambda name, msg, _t: seen.append(msg) if name in ("/joint_states", "/odom") else None)
    ex.run(1.0)
    return got, seen, ex.topic("/joint_states", msgs.JointState).count


def test_wheel_tf_is_the_same_with_and_without_a_joint_states_subscriber() -> None:
    alone, none_seen, count = _drive(subscribe=False)
    read, seen_all, read_count = _drive(subscribe=True)
    heard, listened, _ = _drive(subscribe=False, listen=True)
    seen = [m for m in seen_all if isinstance(m, msgs.JointState)]
    odom = [m for m in seen_all if isinstance(m, msgs.Odometry)]
    assert not none_seen and count == read_count == len(seen) == len(listened) // 2 == 30  # 30 Hz either way
    assert len(odom) == 30 and [msgs.stamp_ns(m) for m in odom] == [msgs.stamp_ns(m) for m in seen]
    p, o = odom[-1].pose.pose.position, odom[-1].pose.pose.orientation
    assert alone[(msgs.stamp_ns(odom[-1]), "chassis")] == (p.x, p.y, p.z, o.x, o.y, o.z, o.w)  # odom = its tf
    wheels = {k: v for k, v in alone.items() if k[1].endswith("wheel")}
    assert len(wheels) == 60 and alone == read == heard  # every tf bit for bit, wheels and odom
    robot = make_mybot()
    joint = next(j for j in robot.joints if j.name == "left_wheel_hinge")
    last = seen[-1]
    assert list(last.name) == ["left_wheel_hinge", "right_wheel_hinge"] and len(last.velocity) == 2
    xyz, q = joint_motion(joint, float(last.position[0]))
    assert wheels[(msgs.stamp_ns(last), joint.child)] == (*xyz, *q)  # the message's angle gives the tf
    assert float(last.position[0]) > 1.0  # the wheels turned
