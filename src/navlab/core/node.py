"""rclpy-like nodes: publishers, subscriptions, timers, clock, logger, parameters, tf, services.

Every node class takes ``(executor, *, name=..., parameters=None, namespace="")``; objects a node
needs besides its parameters (the simulation, for a Gazebo plugin) follow as keyword-only arguments.
"""

from __future__ import annotations

import dataclasses
import difflib
import logging
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from navlab.core.errors import ParameterError
from navlab.core.executor import Executor
from navlab.core.params import TYPO_CUTOFF, ParameterWarning
from navlab.core.tf import Pose2
from navlab.core.topics import Publisher, Subscription, Timer, seconds_to_ns
from navlab.msgs import TFMessage, time_from_ns

__all__ = [
    "Clock",
    "Node",
    "Publisher",
    "Subscription",
    "Timer",
    "dataclass_parameters",
    "flatten_params",
    "resolve_name",
]


def resolve_name(name: str, namespace: str) -> str:
    """ROS name resolution: absolute names stay; relative ones go under ``namespace``."""
    if name.startswith("/"):
        return name
    ns = namespace.strip("/")
    return f"/{ns}/{name}" if ns else f"/{name}"


class Clock:
    """Simulated-time clock of an executor."""

    def __init__(self, executor: Executor) -> None:
        self._executor = executor

    def now_ns(self) -> int:
        """Current simulated time in nanoseconds."""
        return self._executor.now_ns

    def now(self) -> Any:
        """Current simulated time as ``builtin_interfaces/Time``."""
        return time_from_ns(self._executor.now_ns)

    def seconds(self) -> float:
        """Current simulated time in seconds."""
        return self._executor.now_ns / 1e9


class _SimTimeAdapter(logging.LoggerAdapter[logging.Logger]):
    """Prefixes each message with the simulated time (s) and the node's name."""

    def __init__(self, logger: logging.Logger, executor: Executor, node: str) -> None:
        super().__init__(logger, {"executor": executor, "node": node})
        self._executor = executor
        self._node = node

    def process(self, msg: Any, kwargs: Any) -> tuple[Any, Any]:
        return f"[{self._executor.now_ns / 1e9:.3f}] [{self._node}] {msg}", kwargs

    def warn(self, msg: Any, *args: Any, **kwargs: Any) -> None:
        """rclpy spelling of :meth:`warning`."""
        self.warning(msg, *args, **kwargs)


def flatten_params(params: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested parameter dicts to dotted names (``global_costmap.update_frequency``)."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten_params(value, name + "."))
        else:
            out[name] = value
    return out


def dataclass_parameters(cls: type, *, prefix: str = "") -> dict[str, Any]:
    """Parameter names and defaults from a parameters dataclass's fields (``prefix.name`` if a prefix is given).

    The dataclass is where a component writes its ROS names and defaults once; nodes declare from it.
    """
    if not dataclasses.is_dataclass(cls):
        raise ParameterError(f"{cls!r} is not a dataclass of parameters")
    out: dict[str, Any] = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            raise ParameterError(f"{cls.__name__}.{f.name}: a parameter needs a default")
        out[f"{prefix}.{f.name}" if prefix else f.name] = default
    return out


def _coerce(name: str, value: Any, default: Any) -> Any:
    """Check ``value`` against the type of ``default`` (ints are accepted for floats)."""
    if default is None:
        return value
    if value is None:
        raise ParameterError(f"parameter {name!r}: expected {type(default).__name__}, got null")
    kind = type(default)
    if isinstance(value, float) and value != value:  # NaN: never a usable parameter value
        raise ParameterError(f"parameter {name!r}: expected a number, got nan")
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if kind is bool and not isinstance(value, bool):
        raise ParameterError(f"parameter {name!r}: expected true/false, got {value!r}")
    if kind is int and isinstance(value, bool):
        raise ParameterError(f"parameter {name!r}: expected an integer, got {value!r}")
    if kind in (list, tuple) and isinstance(value, list | tuple):
        return kind(value)
    if not isinstance(value, kind):
        raise ParameterError(f"parameter {name!r}: expected {kind.__name__}, got {value!r}")
    return value


class Node:
    """Base class of every navlab node, shaped like ``rclpy.node.Node``."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str,
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        self.name = name
        self.namespace = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self.fully_qualified_name = f"{self.namespace}/{name}"
        self.executor = executor
        self.remappings: dict[str, str] = executor.construction_remappings()
        self._overrides = flatten_params(parameters or {})
        self._declared: dict[str, Any] = {}
        self._params_checked = False
        self.publishers: list[Publisher] = []
        self.subscriptions: list[Subscription] = []
        self.timers: list[Timer] = []
        self.rng = executor.make_rng(self.fully_qualified_name)
        self._clock = Clock(executor)
        self._logger = _SimTimeAdapter(
            logging.getLogger(f"navlab{self.fully_qualified_name.replace('/', '.')}"),
            executor,
            self.fully_qualified_name,
        )
        self._sensor_poses: dict[tuple[str, str], Pose2] = {}
        executor.register_node(self)

    # --- names -----------------------------------------------------------------------------------

    def resolve_topic_name(self, topic: str) -> str:
        """Apply this node's remappings, then resolve against its namespace."""
        for key in (topic, resolve_name(topic, self.namespace)):
            if key in self.remappings:
                return resolve_name(self.remappings[key], self.namespace)
        return resolve_name(topic, self.namespace)

    # --- communication ---------------------------------------------------------------------------

    def create_publisher(self, msgtype: type, topic: str, qos: int = 10, *, latched: bool = False) -> Publisher:
        """Publisher of ``msgtype`` on ``topic`` (``latched``: ROS transient_local)."""
        t = self.executor.topic(self.resolve_topic_name(topic), msgtype)
        t.publishers.append(self.fully_qualified_name)
        pub = Publisher(self.executor, t, latched=latched)
        self.publishers.append(pub)
        return pub

    def create_subscription(
        self, msgtype: type, topic: str, callback: Callable[[Any], None], qos: int = 10
    ) -> Subscription:
        """Call ``callback(msg)`` for each message on ``topic``."""
        sub = Subscription(self.resolve_topic_name(topic), msgtype, callback, self.fully_qualified_name)
        self.executor.subscribe(sub, msgtype)
        self.subscriptions.append(sub)
        return sub

    def create_timer(self, period: float, callback: Callable[[], None], *, priority: int = 0,
                     idle: Callable[[], bool] | None = None) -> Timer:  # fmt: skip
        """Call ``callback()`` every ``period`` simulated seconds (lower ``priority`` runs first on ties).

        ``idle()`` (navlab extension), if given, returns True when the callback would do nothing at this
        firing (e.g. a sensor nobody reads); the firing is then skipped, physics included.
        """
        if isinstance(period, bool) or not isinstance(period, int | float) or not 0 < period < 1e9:
            raise ParameterError(f"node {self.fully_qualified_name}: timer period {period!r} s: expected a "
                                 "finite number > 0 (is a rate parameter 0, negative or not a number?)")
        timer = Timer(self.executor, seconds_to_ns(period), callback, priority, self.executor.now_ns, idle)
        self.timers.append(timer)
        return timer

    def create_service(self, name: str, callback: Callable[[Any], Any]) -> str:
        """Offer ``callback(request) -> response`` as a service; returns the resolved name."""
        full = resolve_name(name, self.namespace)
        self.executor.add_service(full, callback)
        return full

    def send_transform(self, transforms: Any | Sequence[Any]) -> None:
        """Broadcast ``TransformStamped`` (one or a list) on ``/tf``."""
        self._tf_publisher("/tf").publish(TFMessage(transforms=_as_list(transforms)))

    def send_static_transform(self, transforms: Any | Sequence[Any]) -> None:
        """Broadcast ``TransformStamped`` (one or a list) on ``/tf_static``."""
        self._tf_publisher("/tf_static").publish(TFMessage(transforms=_as_list(transforms)))

    def _tf_publisher(self, topic: str) -> Publisher:
        for pub in self.publishers:
            if pub.topic_name == topic:
                return pub
        return self.create_publisher(TFMessage, topic, latched=topic == "/tf_static")

    # --- tf ---------------------------------------------------------------------------------------

    def listen_tf(self) -> None:
        """Declare that this node reads tf, as a ROS node does by creating a ``tf2_ros.TransformListener``: the
        graph (``navlab graph``, rqt_graph) then shows it subscribing ``/tf`` and ``/tf_static``. The transforms
        themselves are in the executor's one buffer (``executor.tf``)."""
        self.executor.tf_listeners.add(self.fully_qualified_name)

    def pose_at(self, target: str, source: str, t_ns: int | None) -> Pose2:
        """(x, y, yaw) of ``source`` in ``target`` at ``t_ns`` (a message's stamp), else the latest.

        Falls back on the latest transform when tf has none at ``t_ns`` yet (a scan stamped just after
        the last odometry). Raises ``TfError`` when the frames are not connected at all.
        """
        self.listen_tf()
        return self.executor.tf.lookup_pose2d_or_latest(target, source, t_ns)

    def sensor_pose(self, base_frame: str, sensor_frame: str) -> Pose2:
        """(x, y, yaw) of a sensor frame mounted on the robot, in ``base_frame``: looked up once, then cached.

        Raises ``TfError`` until the transform is known (robot_state_publisher's static tf).
        """
        key = (base_frame, sensor_frame)
        pose = self._sensor_poses.get(key)
        if pose is None:
            self.listen_tf()
            pose = self._sensor_poses[key] = self.executor.tf.lookup_pose2d(base_frame, sensor_frame)
        return pose

    # --- clock, logger ---------------------------------------------------------------------------

    def get_clock(self) -> Clock:
        """The simulated clock."""
        return self._clock

    def get_logger(self) -> _SimTimeAdapter:
        """A logger whose lines carry simulated time and the node name."""
        return self._logger

    def get_name(self) -> str:
        """The node's name (without namespace)."""
        return self.name

    # --- parameters ------------------------------------------------------------------------------

    def declare_parameter(self, name: str, default: Any = None, *, aliases: Sequence[str] = ()) -> Any:
        """Declare a parameter and return its value: the override given at construction, or ``default``.

        ``aliases`` are other accepted spellings (e.g. Nav2's name for a ROS 1 parameter).
        """
        key = name.replace("/", ".")
        value = default
        for cand in (key, *(a.replace("/", ".") for a in aliases)):
            if cand in self._overrides:
                value = _coerce(cand, self._overrides[cand], default)
                self._declared[cand] = value
                break
        self._declared[key] = value
        return value

    def declare_parameters(
        self, defaults: Mapping[str, Any], *, aliases: Mapping[str, Sequence[str]] | None = None
    ) -> dict[str, Any]:
        """Declare every ``name: default`` (e.g. from :func:`dataclass_parameters`); returns name -> value.

        ``aliases`` maps a name to its other accepted spellings (Nav2's, for a ROS 1 name).
        """
        aka = aliases or {}
        return {k: self.declare_parameter(k, d, aliases=aka.get(k, ())) for k, d in defaults.items()}

    def get_parameter(self, name: str) -> Any:
        """Value of a declared parameter."""
        key = name.replace("/", ".")
        try:
            return self._declared[key]
        except KeyError:
            raise ParameterError(f"node {self.fully_qualified_name}: parameter {name!r} was not declared") from None

    def set_parameter(self, name: str, value: Any) -> None:
        """Change a declared parameter's value (the node reads it on its next use)."""
        key = name.replace("/", ".")
        self._declared[key] = _coerce(key, value, self.get_parameter(key))

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Any]:
        """Overrides under ``prefix.`` (undeclared ones too), with the prefix removed."""
        p = prefix.replace("/", ".") + "."
        return {k[len(p) :]: v for k, v in self._overrides.items() if k.startswith(p)}

    def accept_parameters(self, prefix: str) -> None:
        """Mark every override under ``prefix.`` as known (for sub-objects that read them themselves)."""
        p = prefix.replace("/", ".") + "."
        for k in self._overrides:
            if k.startswith(p):
                self._declared.setdefault(k, self._overrides[k])

    def check_parameters(self) -> None:
        """Refuse overrides that no declaration asked for, suggesting the closest names."""
        if self._params_checked:
            return
        self._params_checked = True
        lines = []
        for key in (k for k in self._overrides if k not in self._declared):  # policy: params.check_unknown_key
            close = difflib.get_close_matches(key, list(self._declared), n=1, cutoff=TYPO_CUTOFF)
            if close:
                lines.append(f"{key!r} (did you mean {close[0]!r}?)")
            else:
                warnings.warn(ParameterWarning(f"node {self.fully_qualified_name}: unknown parameter {key!r} "
                                               "ignored (ROS ignores what it does not read)", key), stacklevel=2)
        if lines:
            raise ParameterError(f"node {self.fully_qualified_name}: unknown parameter " + ", ".join(lines))

    def destroy_node(self) -> None:
        """Cancel timers and detach subscriptions."""
        for timer in self.timers:
            timer.cancel()
        for sub in self.subscriptions:
            topic = self.executor.topics.get(sub.topic)
            if topic is not None and sub in topic.subscriptions:
                topic.subscriptions.remove(sub)
        self.executor.nodes.pop(self.fully_qualified_name, None)


def _as_list(x: Any | Sequence[Any]) -> list[Any]:
    return list(x) if isinstance(x, list | tuple) else [x]
