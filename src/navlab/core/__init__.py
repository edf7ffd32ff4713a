"""The simulated-time runtime: executor, nodes, topics, tf, parameters (see docs/core-api.md)."""

from navlab.core.errors import CoreError, LaunchError, ParameterError, TfError
from navlab.core.executor import Executor
from navlab.core.node import Clock, Node, dataclass_parameters, resolve_name
from navlab.core.params import ParamSpec, load_params, merge_params, read_params
from navlab.core.tf import Pose2, TfBuffer
from navlab.core.topics import NS_PER_S, Publisher, Subscription, Timer, Topic, seconds_to_ns

__all__ = [
    "NS_PER_S",
    "Clock",
    "CoreError",
    "Executor",
    "LaunchError",
    "Node",
    "ParamSpec",
    "ParameterError",
    "Pose2",
    "Publisher",
    "Subscription",
    "TfBuffer",
    "TfError",
    "Timer",
    "Topic",
    "dataclass_parameters",
    "load_params",
    "merge_params",
    "read_params",
    "resolve_name",
    "seconds_to_ns",
]
