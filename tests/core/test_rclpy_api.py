"""Issue 23 item 4: an rclpy-shaped API. A node file written against rclpy runs unchanged (navlab run), rclpy's
constructor and parameter objects work, the old constructor warns, and every name docs/core-api.md lists
exists with the documented signature."""

from __future__ import annotations

import inspect
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import navlab
from navlab.core import Executor, Node
from navlab.core.node import Parameter

DOC = Path(__file__).parents[2] / "docs" / "core-api.md"

DRIVER = Path(__file__).parents[2] / "examples" / "07_rclpy_node" / "driver.py"  # written for rclpy only


def test_an_rclpy_node_file_runs_unchanged(tmp_path: Path) -> None:
    file = tmp_path / "driver.py"
    file.write_text(DRIVER.read_text())
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "navlab.cli",
            "run",
            str(file),
            "--launch",
            "sim",
            "world:=room",
            "--duration",
            "2",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["sim_s"] == 2.0 and out["topics"]["/cmd_vel"] == 20  # 10 Hz for 2 simulated seconds


def test_rclpy_constructor_parameters_and_spin() -> None:
    ctx = navlab.init(seed=0)
    try:
        node = Node("driver", namespace="robot1", parameter_overrides=[Parameter("speed", value=0.5)])
        assert node.get_fully_qualified_name() == "/robot1/driver" and node.get_namespace() == "/robot1"
        speed = node.declare_parameter("speed", 0.1)
        assert isinstance(speed, Parameter) and speed.value == 0.5
        assert node.get_parameter("speed").get_parameter_value().double_value == 0.5
        assert node.set_parameters([Parameter("speed", value=0.7)])[0].successful
        assert node.get_parameters(["speed"])[0].value == 0.7
        ticks: list[int] = []
        node.create_timer(0.25, lambda: ticks.append(1))
        navlab.spin_once(node, timeout_sec=1.0)
        assert len(ticks) == 4 and ctx.executor.now_ns == 1_000_000_000
        now = node.get_clock().now()  # rclpy's Time
        assert now.nanoseconds == 1_000_000_000 and now.to_msg().sec == 1 and now.seconds_nanoseconds() == (1, 0)
        assert navlab.ok()
    finally:
        navlab.shutdown()
    assert not navlab.ok()


def test_a_node_before_init_is_a_clear_error() -> None:
    navlab.shutdown()
    with pytest.raises(navlab.core.errors.CoreError, match=r"navlab.init\(\)"):
        Node("early")


def test_the_old_constructor_still_works_with_a_deprecation_warning() -> None:
    with pytest.warns(DeprecationWarning, match="Node\\(executor, name=...\\) is deprecated"):
        node = Node(Executor(), name="old", parameters={"gain": 2.0})
    assert node.declare_parameter("gain", 1.0) == 2.0 and node.get_parameter("gain") == 2.0  # plain values


def test_the_previous_keyword_names_still_work_with_a_deprecation_warning() -> None:
    from navlab.msgs import Twist, twist

    navlab.init(seed=0)
    try:
        node = Node("old_kw")
        with pytest.warns(DeprecationWarning, match=r"create_publisher\(msgtype=..., qos=...\) is deprecated"):
            pub = node.create_publisher(msgtype=Twist, topic="cmd_vel", qos=10)
        got: list[Any] = []
        with pytest.warns(DeprecationWarning, match=r"create_subscription\(qos=...\)"):
            node.create_subscription(Twist, "cmd_vel", got.append, qos=10)
        ticks: list[int] = []
        with pytest.warns(DeprecationWarning, match=r"create_timer\(period=...\)"):
            node.create_timer(period=0.5, callback=lambda: ticks.append(1))
        with pytest.warns(DeprecationWarning, match=r"declare_parameter\(default=...\)"):
            assert node.declare_parameter("gain", default=3.0).value == 3.0
        pub.publish(twist(0.1))
        navlab.spin_once(node, timeout_sec=1.0)
        assert len(got) == 1 and len(ticks) == 2
        with pytest.raises(TypeError, match="both 'qos' and 'qos_profile'"):
            node.create_publisher(Twist, "cmd_vel", qos=10, qos_profile=10)
    finally:
        navlab.shutdown()


def test_message_classes_default_their_fields_as_rclpy_does() -> None:
    navlab.install_ros_imports()
    from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.time import Time

    assert SingleThreadedExecutor().add_node(object()) and Time(seconds=1.5).nanoseconds == 1_500_000_000
    msg = Twist()
    msg.linear.x = 0.2
    assert (msg.linear.x, msg.angular.z, msg.__msgtype__) == (0.2, 0.0, "geometry_msgs/msg/Twist")
    pose = PoseWithCovarianceStamped()
    assert pose.pose.covariance.shape == (36,) and pose.header.frame_id == ""


def _documented() -> list[tuple[str, str]]:
    block = re.search(r"```api\n(.*?)```", DOC.read_text(), re.S)
    assert block, "docs/core-api.md has no ```api block"
    return [(line.split("(", 1)[0], "(" + line.split("(", 1)[1]) for line in block.group(1).splitlines() if line]


@pytest.mark.parametrize(("name", "signature"), _documented())
def test_every_documented_name_exists_with_its_signature(name: str, signature: str) -> None:
    obj = navlab
    for part in name.split(".")[1:]:
        obj = getattr(obj, part)
    sig = inspect.signature(obj)
    params = [p.replace(annotation=inspect.Parameter.empty) for p in sig.parameters.values() if p.name != "self"]
    assert str(sig.replace(parameters=params, return_annotation=inspect.Signature.empty)) == signature
