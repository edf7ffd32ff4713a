"""The simulated-time runtime: executor, nodes, topics, tf, parameters (see docs/core-api.md)."""

from navlab.core.errors import CoreError, LaunchError, ParameterError, TfError
from navlab.core.executor import NS_PER_S, Executor, Topic, seconds_to_ns
from navlab.core.node import Clock, Node, Publisher, Subscription, Timer, resolve_name
from navlab.core.params import load_params, merge_params
from navlab.core.tf import TfBuffer

__all__ = [
    "NS_PER_S",
    "Clock",
    "CoreError",
    "Executor",
    "LaunchError",
    "Node",
    "ParameterError",
    "Publisher",
    "Subscription",
    "TfBuffer",
    "TfError",
    "Timer",
    "Topic",
    "load_params",
    "merge_params",
    "resolve_name",
    "seconds_to_ns",
]
