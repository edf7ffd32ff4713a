"""The Gazebo-like plugin nodes on an executor: cmd_vel → motion, odometry, scans, tf, spawning."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import make_mybot, make_room

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.geometry import wrap_angle
from navlab.sim import launch_sim
from navlab.world import WorldModel


class Probe(Node):
    """Publishes a constant cmd_vel at 10 Hz (until ``stop_at`` s) and keeps what the plugins publish."""

    def __init__(self, ex: Executor, v: float, w: float, stop_at: float = math.inf) -> None:
        super().__init__("probe", context=Context(ex))
        self.v, self.w, self.stop_at = v, w, stop_at
        self.cmd = self.create_publisher(msgs.Twist, "cmd_vel", 10)
        self.scans: list = []
        self.odom: list = []
        self.truth: list = []
        self.joints: list = []
        self.create_subscription(msgs.LaserScan, "/mybot/laser/scan", self.scans.append)
        self.create_subscription(msgs.Odometry, "odom", self.odom.append)
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self.truth.append)
        self.create_subscription(msgs.JointState, "joint_states", self.joints.append)
        self.create_timer(0.1, self.tick)

    def tick(self) -> None:
        if self.get_clock().seconds() < self.stop_at:
            self.cmd.publish(msgs.twist(self.v, self.w))


def _start(world: WorldModel | None = None, *, seed: int = 0, **kw: object) -> tuple[Executor, object]:
    ex = Executor(seed=seed)
    gazebo = launch_sim(ex, world=world or make_room(), robot=make_mybot(), **kw)  # type: ignore[arg-type]
    return ex, gazebo


def test_cmd_vel_drives_two_metres_and_topics_flow() -> None:
    ex, _ = _start()
    probe = Probe(ex, 0.5, 0.0)
    ex.run(4.0)
    x, y, _ = msgs.pose2d(probe.truth[-1].pose.pose)
    assert probe.truth[-1].header.frame_id == "world"
    assert x == pytest.approx(2.0, abs=0.1) and abs(y) < 0.02
    assert len(probe.scans) == pytest.approx(160, abs=1)  # 40 Hz
    scan = probe.scans[-1]
    assert scan.header.frame_id == "laser" and len(scan.ranges) == 720
    assert scan.range_min == pytest.approx(0.2) and scan.range_max == pytest.approx(25.0)
    assert scan.angle_increment == pytest.approx(2 * math.pi / 719)
    assert len(probe.odom) == pytest.approx(120, abs=1)  # 30 Hz diff drive
    assert probe.odom[-1].header.frame_id == "odom" and probe.odom[-1].child_frame_id == "chassis"
    assert probe.odom[-1].pose.covariance[0] > 0
    assert set(probe.joints[-1].name) == {"left_wheel_hinge", "right_wheel_hinge"}
    # tf: odom -> chassis from the plugin, chassis -> laser static from the fixed joint
    lx, ly, _ = ex.tf.lookup_pose2d("odom", "laser")
    assert lx == pytest.approx(x, abs=0.05) and abs(ly) < 0.02
    # robot_state_publisher: chassis -> left_wheel turns about y by the joint angle in joint_states
    js = probe.joints[-1]
    angle = float(js.position[list(js.name).index("left_wheel_hinge")])
    wheel = ex.tf.lookup_transform("chassis", "left_wheel", msgs.stamp_ns(js))
    q = wheel.transform.rotation
    assert wheel.transform.translation.y == pytest.approx(0.2)
    assert abs(q.x) < 1e-9 and abs(q.z) < 1e-9
    assert wrap_angle(2 * math.atan2(q.y, q.w) - angle) == pytest.approx(0.0, abs=1e-6)
    assert angle > 20  # 2 m of 0.08 m wheels: 25 rad


def test_turns_in_place() -> None:
    ex, _ = _start()
    probe = Probe(ex, 0.0, 1.0)
    ex.run(3.0)
    _, _, yaw = msgs.pose2d(probe.truth[-1].pose.pose)
    assert yaw == pytest.approx(3.0 - 0.133, abs=0.15)  # first cmd_vel at 0.1 s, applied at the 0.133 s update


def test_encoder_odometry_within_one_percent_over_ten_metres() -> None:
    ex, _ = _start(WorldModel("flat"))
    probe = Probe(ex, 0.5, 0.05)  # a gentle 10 m arc at the paper's navigation speed
    ex.run(20.0)
    truth = probe.truth[-1].pose.pose.position
    odom = probe.odom[-1].pose.pose.position
    path = sum(
        math.dist((a.pose.pose.position.x, a.pose.pose.position.y), (b.pose.pose.position.x, b.pose.pose.position.y))
        for a, b in zip(probe.truth, probe.truth[1:], strict=False)
    )
    assert path == pytest.approx(10.0, rel=0.05)
    assert math.dist((odom.x, odom.y), (truth.x, truth.y)) < 0.01 * path


def test_cmd_timeout_stops_the_robot() -> None:
    ex, gazebo = _start(cmd_timeout=0.5)  # navlab's watchdog, off unless set
    Probe(ex, 0.5, 0.0, stop_at=1.0)
    ex.run(3.0)
    x_then = gazebo.sim.base_pose2d()[0]  # type: ignore[attr-defined]
    ex.run(1.0)
    assert gazebo.sim.base_pose2d()[0] == pytest.approx(x_then, abs=1e-3)  # type: ignore[attr-defined]
    assert 0.5 < x_then < 0.9  # moved for ~1 s plus the 0.5 s timeout at most


def test_spawn_and_delete_services_change_the_next_scan() -> None:
    ex, _ = _start(seed=1)
    probe = Probe(ex, 0.0, 0.0)
    ex.run(0.1)
    assert probe.scans[-1].ranges[360] == pytest.approx(5.0, abs=0.05)
    reply = ex.call_service("/spawn_entity", "box:name=crate,x=2,size=0.5")
    assert reply["success"], reply
    n = len(probe.scans)
    ex.run(0.03)
    assert len(probe.scans) == n + 1
    assert probe.scans[-1].ranges[360] == pytest.approx(1.75, abs=0.05)
    assert ex.call_service("/delete_entity", "crate")["success"]
    assert not ex.call_service("/delete_entity", "crate")["success"]
    ex.run(0.03)
    assert probe.scans[-1].ranges[360] == pytest.approx(5.0, abs=0.05)


def test_same_seed_same_run() -> None:
    def run(seed: int) -> list[np.ndarray]:
        ex, _ = _start(seed=seed)
        probe = Probe(ex, 0.3, 0.3)
        ex.run(0.5)
        return [s.ranges for s in probe.scans]

    a, b, c = run(4), run(4), run(5)
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not np.array_equal(a[-1], c[-1])
