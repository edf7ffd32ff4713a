"""The simulated-time runtime: executor, nodes, topics, tf, parameters (see docs/core-api.md).

The runtime's classes load with the package; the rest (launch, runner, introspection, recording, rclpy's
module API, ...) in ``_EXPORTS`` load their module on first use, so ``navlab --help`` stays light."""

from typing import TYPE_CHECKING

from navlab.core.errors import CoreError, LaunchError, ParameterError, TfError
from navlab.core.executor import Executor
from navlab.core.node import Clock, Node, dataclass_parameters, resolve_name
from navlab.core.params import ParamSpec, load_params, merge_params, read_params
from navlab.core.safe_eval import MATH_NAMES, ExpressionError, safe_eval
from navlab.core.tf import Pose2, TfBuffer
from navlab.core.topics import NS_PER_S, Publisher, Subscription, Timer, Topic, seconds_to_ns
from navlab.lazy import lazy_exports

__all__ = [
    "MATH_NAMES",
    "NS_PER_S",
    "Clock",
    "Context",
    "CoreError",
    "EchoPrinter",
    "Executor",
    "ExpressionError",
    "Graph",
    "IntrospectionServer",
    "LaunchError",
    "Node",
    "ParamSpec",
    "ParameterError",
    "Pose2",
    "Publisher",
    "Recorder",
    "RemotePublisher",
    "Session",
    "Subscription",
    "TfBuffer",
    "TfError",
    "Timer",
    "Topic",
    "canonical_params",
    "ceilings",
    "check_ceiling",
    "check_unknown_key",
    "dataclass_parameters",
    "declared_args",
    "echo_bag",
    "echo_launch",
    "echo_live",
    "find_running",
    "flatten_params",
    "load_params",
    "merge_params",
    "param_error",
    "parse_launch_args",
    "parse_yaml",
    "read_params",
    "read_yaml",
    "request",
    "resolve_name",
    "run_for",
    "safe_eval",
    "seconds_to_ns",
    "start",
    "subscribe",
    "typed_value",
    "with_layout",
]

if TYPE_CHECKING:
    from navlab.core.echo import Printer as EchoPrinter
    from navlab.core.echo import echo_bag, echo_launch, echo_live
    from navlab.core.graph import Graph, with_layout
    from navlab.core.introspect import IntrospectionServer, RemotePublisher, find_running, request, subscribe
    from navlab.core.launch import Session, declared_args, start
    from navlab.core.limits import ceilings, check_ceiling
    from navlab.core.params import (
        canonical_params,
        check_unknown_key,
        flatten_params,
        param_error,
        parse_yaml,
        read_yaml,
        typed_value,
    )
    from navlab.core.rclpy_api import Context
    from navlab.core.record import Recorder
    from navlab.core.runner import parse_launch_args, run_for

_EXPORTS = {
    "Context": "navlab.core.rclpy_api",
    "EchoPrinter": "navlab.core.echo:Printer",
    "Graph": "navlab.core.graph",
    "IntrospectionServer": "navlab.core.introspect",
    "Recorder": "navlab.core.record",
    "RemotePublisher": "navlab.core.introspect",
    "Session": "navlab.core.launch",
    "canonical_params": "navlab.core.params",
    "ceilings": "navlab.core.limits",
    "check_ceiling": "navlab.core.limits",
    "check_unknown_key": "navlab.core.params",
    "declared_args": "navlab.core.launch",
    "echo_bag": "navlab.core.echo",
    "echo_launch": "navlab.core.echo",
    "echo_live": "navlab.core.echo",
    "find_running": "navlab.core.introspect",
    "flatten_params": "navlab.core.params",
    "param_error": "navlab.core.params",
    "parse_launch_args": "navlab.core.runner",
    "parse_yaml": "navlab.core.params",
    "read_yaml": "navlab.core.params",
    "request": "navlab.core.introspect",
    "run_for": "navlab.core.runner",
    "start": "navlab.core.launch",
    "subscribe": "navlab.core.introspect",
    "with_layout": "navlab.core.graph",
    "typed_value": "navlab.core.params",
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
