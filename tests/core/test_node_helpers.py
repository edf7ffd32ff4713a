"""Core node helpers: one constructor signature, tf pose helpers, parameters from a dataclass, public executor API."""

from __future__ import annotations

import ast
import importlib
import inspect
import math
from dataclasses import dataclass

import pytest

from navlab import msgs
from navlab.core import Context, CoreError, Executor, Node, ParameterError, TfError, dataclass_parameters
from navlab.nodes import NODES


def _node_classes() -> list[type]:
    from navlab.sim import plugins as sim_plugins
    from navlab.sim.imu import ImuSensorPlugin

    classes = [getattr(importlib.import_module(m), c) for m, c in (t.split(":") for t in NODES.values())]
    classes += [
        sim_plugins.DiffDrivePlugin,
        sim_plugins.LidarPlugin,
        ImuSensorPlugin,
        sim_plugins.JointStatePlugin,
        sim_plugins.RobotStatePublisher,
        sim_plugins.GroundTruthPlugin,
    ]
    return classes  # the base Node has rclpy's constructor (issue 23; tests/core/test_rclpy_api.py)


@pytest.mark.parametrize("cls", _node_classes(), ids=lambda c: c.__name__)
def test_every_node_class_takes_executor_then_name_parameters_namespace(cls: type) -> None:
    params = list(inspect.signature(cls.__init__).parameters.values())[1:]
    assert params[0].name == "executor" and params[0].kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
    assert [p.name for p in params[1:4]] == ["name", "parameters", "namespace"]
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params[1:])
    assert params[2].default is None and params[3].default == ""


def test_pose_at_a_stamp_interpolates_and_falls_back_on_the_latest() -> None:
    ex = Executor()
    node = Node("n", context=Context(ex))
    node.send_transform(msgs.transform_stamped(1_000_000_000, "odom", "base_link", 1.0, 0.0, 0.0))
    node.send_transform(msgs.transform_stamped(2_000_000_000, "odom", "base_link", 2.0, 0.0, 0.2))
    x, y, yaw = node.pose_at("odom", "base_link", 1_500_000_000)
    assert (x, y) == pytest.approx((1.5, 0.0)) and yaw == pytest.approx(0.1)
    # a scan stamped after the newest odometry gets the newest pose; so does one before the oldest
    assert node.pose_at("odom", "base_link", 3_000_000_000) == pytest.approx((2.0, 0.0, 0.2))
    assert node.pose_at("odom", "base_link", 0) == pytest.approx((2.0, 0.0, 0.2))
    with pytest.raises(TfError, match="laser"):
        node.pose_at("odom", "laser", 1_500_000_000)


def test_sensor_pose_is_looked_up_once() -> None:
    ex = Executor()
    node = Node("n", context=Context(ex))
    with pytest.raises(TfError):
        node.sensor_pose("base_link", "laser")
    node.send_static_transform(msgs.transform_stamped(0, "base_link", "laser", 0.1, 0.0, math.pi / 2))
    assert node.sensor_pose("base_link", "laser") == pytest.approx((0.1, 0.0, math.pi / 2))
    node.send_static_transform(msgs.transform_stamped(0, "base_link", "laser", 0.5, 0.0, 0.0))
    assert node.sensor_pose("base_link", "laser")[0] == pytest.approx(0.1)  # a mounted sensor does not move


@dataclass
class _FilterParams:
    min_particles: int = 100
    kld_err: float = 0.01
    laser_model_type: str = "likelihood_field"


def test_parameters_declared_from_a_dataclass_with_aliases() -> None:
    assert dataclass_parameters(_FilterParams, prefix="pf") == {
        "pf.min_particles": 100,
        "pf.kld_err": 0.01,
        "pf.laser_model_type": "likelihood_field",
    }
    ex = Executor()
    node = Node("amcl", context=Context(ex), parameter_overrides={"pf_err": 0.05, "min_particles": 7})
    values = node.declare_parameters(dataclass_parameters(_FilterParams), aliases={"kld_err": ("pf_err",)})
    assert _FilterParams(**{k: p.value for k, p in values.items()}) == _FilterParams(min_particles=7, kld_err=0.05)
    with pytest.raises(ParameterError, match="min_particles"):
        Node("bad", context=Context(ex), parameter_overrides={"min_particles": "many"}).declare_parameters(
            dataclass_parameters(_FilterParams)
        )
    with pytest.raises(ParameterError, match="not a dataclass"):
        dataclass_parameters(dict)


def test_executor_public_node_api() -> None:
    ex = Executor()
    with ex.node_context(remappings={"scan": "/mybot/laser/scan"}):
        assert ex.construction_remappings() == {"scan": "/mybot/laser/scan"}
        node = Node("amcl", context=Context(ex))
    assert ex.construction_remappings() == {}
    assert node.resolve_topic_name("scan") == "/mybot/laser/scan" and ex.nodes["/amcl"] is node
    with pytest.raises(CoreError, match="already exists"):
        Node("amcl", context=Context(ex))
    assert not ex.has_listeners

    def listener(topic: str, msg: object, t: int) -> None:
        pass

    ex.add_listener(listener)
    assert ex.has_listeners
    ex.remove_listener(listener)
    assert not ex.has_listeners


def test_executor_and_node_modules_do_not_import_each_other() -> None:
    def imports(module: str) -> set[str]:
        tree = ast.parse(inspect.getsource(importlib.import_module(module)))
        return {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module} | {
            a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names
        }

    assert "navlab.core.node" not in imports("navlab.core.executor")
    assert "navlab.core.node" not in imports("navlab.core.topics")
    assert "navlab.core.executor" not in imports("navlab.core.topics")
