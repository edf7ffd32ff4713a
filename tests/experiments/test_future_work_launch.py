"""Issue 15's launch arguments: wheel_controller:=true and ekf:=true on the shipped launches, the EKF the only
publisher of tf odom -> base, and the scenario keys wired through the same arguments."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from navlab import msgs
from navlab.cli import main
from navlab.core import Context, Node
from navlab.core.launch import start
from navlab.errors import NavlabError
from navlab.experiments.navigate_run import sim_launch_args
from navlab.mapping import save_map
from navlab.navigation import NavigationError
from navlab.world import load_world, true_map


class _Watch(Node):
    """Drives in a curve and keeps every tf odom -> chassis and every /odometry/filtered and /odom message."""

    def __init__(self, executor: Any) -> None:
        super().__init__("test_watch", context=Context(executor))
        self.odom_tf: list[tuple[int, float, float]] = []  # (stamp ns, x, y)
        self.filtered: dict[int, tuple[float, float]] = {}
        self.odom = 0
        self.create_subscription(msgs.TFMessage, "/tf", self._on_tf, 100)
        self.create_subscription(msgs.Odometry, "/odometry/filtered", self._on_filtered, 100)
        self.create_subscription(msgs.Odometry, "/odom", lambda _m: setattr(self, "odom", self.odom + 1), 100)
        cmd = self.create_publisher(msgs.Twist, "/cmd_vel", 1)
        twist = msgs.Twist(linear=msgs.Vector3(x=0.4, y=0.0, z=0.0), angular=msgs.Vector3(x=0.0, y=0.0, z=0.6))
        self.create_timer(0.1, lambda: cmd.publish(twist))

    def _on_tf(self, msg: Any) -> None:
        for t in msg.transforms:
            if t.header.frame_id == "odom" and t.child_frame_id == "chassis":
                stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
                self.odom_tf.append((stamp, t.transform.translation.x, t.transform.translation.y))

    def _on_filtered(self, msg: Any) -> None:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self.filtered[stamp] = (msg.pose.pose.position.x, msg.pose.pose.position.y)


@pytest.mark.parametrize("wheel_controller", ["true", "false"])
def test_ekf_launch_arg_makes_the_ekf_the_only_odom_tf_publisher(wheel_controller: str) -> None:
    s = start("sim", launch_args={"wheel_controller": wheel_controller, "ekf": "true"})
    watch = _Watch(s.executor)
    s.run(2.0)
    assert "/ekf_se" in s.nodes
    assert watch.odom > 50, "the wheel odometry still goes out on /odom (the EKF's input)"
    assert len(watch.filtered) >= 55  # 30 Hz
    assert len(watch.odom_tf) == len(watch.filtered)  # one tf per estimate: nothing else sends odom -> chassis
    for stamp, x, y in watch.odom_tf:  # each is the EKF's estimate at its stamp
        assert watch.filtered[stamp] == pytest.approx((x, y), abs=1e-12)
    assert max(x for _t, x, _y in watch.odom_tf) > 0.3  # it drove: the estimates are not all at the origin


def test_without_ekf_the_drive_owns_odom_tf() -> None:
    s = start("sim", launch_args={"wheel_controller": "true"})
    watch = _Watch(s.executor)
    s.run(1.0)
    assert "/ekf_se" not in s.nodes and not watch.filtered
    assert len(watch.odom_tf) == watch.odom > 40  # the controller's odometry and tf, 50 Hz


def test_navigation_launch_with_controller_and_ekf(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    map_yaml = tmp_path / "map.yaml"
    save_map(true_map(load_world("room_obstacles"), (0.0, 0.0)), map_yaml)
    code = main(
        [
            "launch",
            "navigation",
            f"map:={map_yaml}",
            "ekf:=true",
            "wheel_controller:=true",
            "--duration",
            "1",
            "--json",
            "--quiet",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert {"/ekf_se", "/mobile_base_controller", "/amcl", "/move_base"} <= set(out["nodes"])
    assert out["topics"]["/odometry/filtered"] >= 25 and out["topics"]["/imu"] >= 90


def test_controller_params_must_exist() -> None:
    with pytest.raises(NavlabError, match=r"no_such\.yaml: cannot read"):
        start("sim", launch_args={"wheel_controller": "true", "controller_params": "/nonexistent/no_such.yaml"})


def test_scenario_keys_map_to_the_launch_args(tmp_path: Path) -> None:
    assert sim_launch_args("gazebo_ros_diff_drive", None) == {}
    assert sim_launch_args("diff_drive_controller", "default") == {"wheel_controller": "true", "ekf": "true"}
    mine = tmp_path / "ctrl.yaml"
    mine.write_text("mobile_base_controller: {wheel_radius: 0.08}\n")
    args = sim_launch_args(str(mine), str(mine))
    assert args == {
        "wheel_controller": "true",
        "controller_params": str(mine.resolve()),
        "ekf": "true",
        "ekf_params": str(mine.resolve()),
    }
    with pytest.raises(NavigationError, match="expected gazebo_ros_diff_drive or diff_drive_controller"):
        sim_launch_args("pid_please", None)
