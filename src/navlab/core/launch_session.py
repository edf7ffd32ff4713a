"""A started launch and the nodes in it: :class:`Session`, the runtime description :class:`NodeSpec` that every
launch format (YAML, ROS 1 XML) translates into, and :func:`start_node`, which constructs one node from it."""

from __future__ import annotations

import importlib
import logging
import warnings
from dataclasses import dataclass, field
from typing import Any

from navlab.core.errors import LaunchError
from navlab.core.executor import Executor
from navlab.core.node import Node
from navlab.core.params import ParameterWarning, merge_params
from navlab.errors import NavlabError


def load_node_class(exec_name: str) -> type[Node]:
    """The node class for a launch ``exec`` (registered name or ``module:Class``)."""
    from navlab.nodes import NODES

    target = NODES.get(exec_name, exec_name)
    if ":" not in target:
        raise LaunchError(f"unknown node executable {exec_name!r} (navlab provides: {', '.join(sorted(NODES))})")
    module, cls = target.split(":", 1)
    try:
        found = getattr(importlib.import_module(module), cls)
    except (ImportError, AttributeError, ValueError) as exc:
        raise LaunchError(f"node executable {exec_name!r}: cannot load {target} ({exc})") from None
    if not (isinstance(found, type) and issubclass(found, Node)):
        raise LaunchError(f"node executable {exec_name!r}: {target} is not a navlab Node class")
    return found


@dataclass
class Session:
    """A started launch: its executor, its nodes by name, and the arguments it was given."""

    executor: Executor
    nodes: dict[str, Node] = field(default_factory=dict)
    args: dict[str, str] = field(default_factory=dict)
    overrides: dict[str, dict[str, Any]] = field(default_factory=dict)
    origins: dict[str, str] = field(default_factory=dict)  # node name -> "launch file: entry (parameter files)"
    params: dict[str, Any] = field(default_factory=dict)  # ROS 1 launch: the parameter server (absolute names)
    notes: list[str] = field(default_factory=list)  # what a ROS 1 launch asked for that navlab covers or skips
    processes: Any = None  # ROS 1 launch with ros:=true: the ProcessGroup of the nodes navlab does not run

    def shutdown(self) -> None:
        """End the processes this launch started (a ROS 1 launch with the bridge on); safe to call twice."""
        if self.processes is not None:
            self.processes.stop()
            self.processes = None

    def run(self, duration: float) -> None:
        """Advance simulated time by ``duration`` seconds."""
        self.executor.run(duration)

    def node(self, name: str) -> Node:
        """A node of this launch by name (with or without leading slash)."""
        for key in (name, "/" + name.lstrip("/")):
            if key in self.nodes:
                return self.nodes[key]
        raise LaunchError(f"no node {name!r} in this launch (nodes: {', '.join(self.nodes)})")


@dataclass
class NodeSpec:
    """One node to start, as every launch format describes it: the runtime description that YAML and
    ROS 1 XML launch files both translate into (one wiring path)."""

    exec: str  # a name in navlab.nodes.NODES or module:Class
    name: str = ""  # "" = the class's default name
    namespace: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    remaps: dict[str, str] = field(default_factory=dict)
    origin: str = ""  # "launch file: entry 'name' (parameter files)", prefixed to its errors
    files: dict[str, set[str]] = field(default_factory=dict)  # parameter file name -> the key names in it


def start_node(session: Session, spec: NodeSpec) -> Node:
    """Construct the node ``spec`` describes in ``session`` (command-line overrides applied last)."""
    try:
        cls = load_node_class(spec.exec)
    except LaunchError as exc:
        raise LaunchError(f"{spec.origin}: {exc}") from None
    params = spec.params
    origin = spec.origin
    if (spec.name or spec.exec) in session.overrides:  # like `ros2 launch ... --ros-args -p`: applied last
        params = merge_params(params, session.overrides[spec.name or spec.exec])
        origin += " + --set overrides"
    kwargs: dict[str, Any] = {"parameters": params}
    if spec.name:
        kwargs["name"] = spec.name
    if spec.namespace.strip("/"):
        kwargs["namespace"] = spec.namespace
    try:
        with session.executor.node_context(remappings=spec.remaps), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ParameterWarning)
            node = cls(session.executor, **kwargs)
    except NavlabError as exc:  # the problem first, then the launch file and parameter files it came from
        raise located(exc, origin) from None
    warn_unknown_keys(caught, spec.files, spec.origin)
    session.nodes[node.fully_qualified_name] = node
    session.origins[node.fully_qualified_name] = spec.origin
    return node


def warn_unknown_keys(caught: list[warnings.WarningMessage], files: dict[str, set[str]], origin: str) -> None:
    """Log each ignored parameter key (``ParameterWarning``) naming the parameter file that holds it; other
    warnings go on as they came."""
    for w in caught:
        if not isinstance(w.message, ParameterWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            continue
        leaf = w.message.key.rsplit(".", 1)[-1]
        held = [name for name, keys in files.items() if leaf in keys]
        where = ", ".join(held) if held else origin
        logging.getLogger("navlab.launch").warning("%s: %s", where, w.message)


def located(exc: NavlabError, where: str) -> NavlabError:
    """``exc`` (same class where it can be rebuilt from a message) with `` (in WHERE)`` after its message."""
    try:
        return type(exc)(f"{exc} (in {where})")
    except Exception:  # an error class with another constructor
        return LaunchError(f"{exc} (in {where})")
