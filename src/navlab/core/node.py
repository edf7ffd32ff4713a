"""rclpy-like nodes: publishers, subscriptions, timers, clock, logger, parameters, tf, services.

Every node class takes ``(executor, *, name=..., parameters=None, namespace="")``; objects a node
needs besides its parameters (the simulation, for a Gazebo plugin) follow as keyword-only arguments.
"""

from __future__ import annotations

import functools
import logging
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from navlab.core.clock import Clock, Time
from navlab.core.errors import ParameterError, TfError
from navlab.core.executor import Executor
from navlab.core.parameter import Parameter, SetParametersResult
from navlab.core.params import (
    ParameterWarning,
    dataclass_parameters,
    flatten_params,
    likely_typo,
    typed_value,
)
from navlab.core.tf import Pose2
from navlab.core.topics import Publisher, Subscription, Timer, seconds_to_ns
from navlab.deprecation import NavlabDeprecationWarning
from navlab.geometry import Tf
from navlab.msgs import TFMessage, transform_from_tuple

__all__ = [
    "Clock",
    "Node",
    "Parameter",
    "Publisher",
    "Subscription",
    "Time",
    "Timer",
    "dataclass_parameters",
    "flatten_params",
    "resolve_name",
]


def _renamed_keywords(**renames: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Accept a method's keyword names of the previous release (``old="new"``) for one more release, with a
    ``DeprecationWarning`` (the rclpy-shaped names replaced them)."""

    def wrap(method: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(method)
        def call(*args: Any, **kwargs: Any) -> Any:
            used = [old for old in renames if old in kwargs]
            for old in used:
                if renames[old] in kwargs:
                    raise TypeError(f"{method.__name__}() got both {old!r} and {renames[old]!r}")
                kwargs[renames[old]] = kwargs.pop(old)
            if used:
                warnings.warn(
                    f"{method.__name__}({'=..., '.join(used)}=...) is deprecated and goes in the next "
                    f"release: write {'=..., '.join(renames[o] for o in used)}=... (rclpy's names)",
                    NavlabDeprecationWarning,
                    stacklevel=2,
                )
            return method(*args, **kwargs)

        return call

    return wrap


def resolve_name(name: str, namespace: str) -> str:
    """ROS name resolution: absolute names stay; relative ones go under ``namespace``."""
    if name.startswith("/"):
        return name
    ns = namespace.strip("/")
    return f"/{ns}/{name}" if ns else f"/{name}"


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

    def fatal(self, msg: Any, *args: Any, **kwargs: Any) -> None:
        """rclpy's ``fatal``: logged as critical."""
        self.critical(msg, *args, **kwargs)


def _coerce(name: str, value: Any, default: Any) -> Any:
    """Check ``value`` against the type of ``default`` (``params.typed_value``'s rule; inf is a valid double)."""
    if default is None:
        return value
    return typed_value(type(default), repr(name), value, finite=False)


class Node:
    """Base class of every navlab node, shaped like ``rclpy.node.Node``.

    ``Node("driver")`` (rclpy's constructor: the name first, then rclpy's keyword options) joins the
    executor of the context ``navlab.init()`` made, or ``context=``; such a node behaves as an rclpy node
    (``declare_parameter``/``get_parameter`` return :class:`Parameter` objects). The older form
    ``Node(executor, name=..., parameters=..., namespace=...)`` keeps working for one release with a
    ``DeprecationWarning`` (navlab's own nodes use it and return plain values).
    """

    def __init__(
        self,
        node_name: str | Executor | None = None,
        *,
        context: Any = None,
        cli_args: Sequence[str] | None = None,
        namespace: str | None = None,
        use_global_arguments: bool = True,
        enable_rosout: bool = True,
        start_parameter_services: bool = True,
        parameter_overrides: Sequence[Any] | Mapping[str, Any] | None = None,
        allow_undeclared_parameters: bool = False,
        automatically_declare_parameters_from_overrides: bool = False,
        name: str | None = None,
        parameters: dict[str, Any] | None = None,
        executor: Executor | None = None,
    ) -> None:
        if isinstance(node_name, Executor) or (executor is not None and node_name is None):
            executor = node_name if isinstance(node_name, Executor) else executor
            if not sys._getframe(1).f_globals.get("__name__", "").startswith("navlab."):  # navlab's own: no warning
                warnings.warn(
                    "Node(executor, name=...) is deprecated and goes in the next release: write "
                    "Node('name', parameter_overrides=...) after navlab.init(), as rclpy does",
                    NavlabDeprecationWarning,
                    stacklevel=2,
                )
            self._rclpy_style = False
        else:
            from navlab.core.rclpy_api import context_executor

            name = node_name if node_name is not None else name
            executor = context_executor(context)
            parameters = {**(parameters or {}), **_overrides_dict(parameter_overrides)}
            self._rclpy_style = True
        if not name:
            raise ParameterError("a node needs a name: Node('driver')")
        assert executor is not None
        self._allow_undeclared = allow_undeclared_parameters
        namespace = namespace or ""
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
        self._tf_pubs: dict[str, Publisher] = {}  # /tf, /tf_static -> this node's publisher (made on first use)
        if automatically_declare_parameters_from_overrides:
            self._declared.update(self._overrides)
        executor.register_node(self)

    # --- names -----------------------------------------------------------------------------------

    def resolve_topic_name(self, topic: str) -> str:
        """Apply this node's remappings, then resolve against its namespace."""
        for key in (topic, resolve_name(topic, self.namespace)):
            if key in self.remappings:
                return resolve_name(self.remappings[key], self.namespace)
        return resolve_name(topic, self.namespace)

    # --- communication ---------------------------------------------------------------------------

    @_renamed_keywords(msgtype="msg_type", qos="qos_profile")
    def create_publisher(
        self,
        msg_type: type,
        topic: str,
        qos_profile: Any = 10,
        *,
        latched: bool = False,
        callback_group: Any = None,
        event_callbacks: Any = None,
    ) -> Publisher:
        """Publisher of ``msg_type`` on ``topic`` (``latched``, or a ``qos_profile`` whose durability is
        transient_local: ROS's latching). ``callback_group``/``event_callbacks`` are accepted as rclpy's;
        one executor thread runs every callback."""
        latched = latched or _transient_local(qos_profile)
        t = self.executor.topic(self.resolve_topic_name(topic), msg_type)
        t.publishers.append(self.fully_qualified_name)
        pub = Publisher(self.executor, t, latched=latched)
        self.publishers.append(pub)
        return pub

    @_renamed_keywords(msgtype="msg_type", qos="qos_profile")
    def create_subscription(
        self,
        msg_type: type,
        topic: str,
        callback: Callable[[Any], None],
        qos_profile: Any = 10,
        *,
        callback_group: Any = None,
        event_callbacks: Any = None,
        raw: bool = False,
    ) -> Subscription:
        """Call ``callback(msg)`` for each message on ``topic`` (rclpy's signature)."""
        sub = Subscription(self.resolve_topic_name(topic), msg_type, callback, self.fully_qualified_name)
        self.executor.subscribe(sub, msg_type)
        self.subscriptions.append(sub)
        return sub

    @_renamed_keywords(period="timer_period_sec")
    def create_timer(
        self,
        timer_period_sec: float,
        callback: Callable[[], None],
        callback_group: Any = None,
        clock: Any = None,
        *,
        priority: int = 0,
        idle: Callable[[], bool] | None = None,
        idle_until_graph_changes: bool = False,
    ) -> Timer:
        """Call ``callback()`` every ``timer_period_sec`` simulated seconds (rclpy's signature; lower
        ``priority`` runs first on ties).

        ``idle()`` (navlab extension), if given, returns True when the callback would do nothing at this
        firing (e.g. a sensor nobody reads); the firing is then skipped, physics included. With
        ``idle_until_graph_changes`` (``idle`` asks only who subscribes or listens, as a ROS lazy publisher asks
        ``get_num_connections``) an idle timer leaves the queue until a subscription or a listener is added.
        """
        period = timer_period_sec
        if isinstance(period, bool) or not isinstance(period, int | float) or not 0 < period < 1e9:
            raise ParameterError(
                f"node {self.fully_qualified_name}: timer period {period!r} s: expected a "
                "finite number > 0 (is a rate parameter 0, negative or not a number?)"
            )
        timer = Timer(
            self.executor,
            seconds_to_ns(period),
            callback,
            priority,
            self.executor.now_ns,
            idle,
            idle_until_graph_changes=idle_until_graph_changes,
        )
        self.timers.append(timer)
        return timer

    def create_service(self, name: str, callback: Callable[[Any], Any]) -> str:
        """Offer ``callback(request) -> response`` as a service; returns the resolved name."""
        full = resolve_name(name, self.namespace)
        self.executor.add_service(full, callback)
        return full

    def send_transform(self, transforms: Any | Sequence[Any]) -> None:
        """Broadcast ``TransformStamped`` (one or a list) on ``/tf``."""
        self._tf_publisher("/tf").publish(TFMessage(_as_list(transforms)))

    def send_transform_tuples(self, stamp_ns: int, transforms: Sequence[tuple[str, str, Tf]]) -> None:
        """Broadcast on ``/tf`` transforms given as ``(parent, child, (x, y, z, qx, qy, qz, qw))`` (floats) stamped
        ``stamp_ns``: what :meth:`send_transform` sends, but the ``TFMessage`` is built only when someone besides
        the executor's tf buffer reads ``/tf`` (a subscriber, a recorder, the viewer); otherwise the buffer gets
        the transforms directly, in the queue's order, as from the message (the nodes of one executor share it)."""
        pub = self._tf_publisher("/tf")
        if not self.executor.send_tf_tuples(pub.topic, stamp_ns, transforms):
            pub.publish(TFMessage([transform_from_tuple(stamp_ns, p, c, tf) for p, c, tf in transforms]))

    def send_static_transform(self, transforms: Any | Sequence[Any]) -> None:
        """Broadcast ``TransformStamped`` (one or a list) on ``/tf_static``."""
        self._tf_publisher("/tf_static").publish(TFMessage(_as_list(transforms)))

    def _tf_publisher(self, topic: str) -> Publisher:
        pub = self._tf_pubs.get(topic)
        if pub is None:
            pub = next((p for p in self.publishers if p.topic_name == topic), None)
            if pub is None:
                pub = self.create_publisher(TFMessage, topic, latched=topic == "/tf_static")
            self._tf_pubs[topic] = pub
        return pub

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

    def scan_sensor_pose(self, base_frame: str, msg: Any) -> Pose2 | None:
        """:meth:`sensor_pose` of the frame of a sensor message ``msg`` (its header's, else ``base_frame``), or
        None with a warning naming the transform while tf lacks it."""
        frame = str(msg.header.frame_id).lstrip("/") or base_frame
        try:
            return self.sensor_pose(base_frame, frame)
        except TfError as exc:
            self.get_logger().warning(f"no transform {base_frame} → {frame} for the scan: {exc}")
            return None

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

    def get_namespace(self) -> str:
        """The node's namespace (``/`` at the top)."""
        return self.namespace or "/"

    def get_fully_qualified_name(self) -> str:
        """``/namespace/name``."""
        return self.fully_qualified_name

    # --- parameters ------------------------------------------------------------------------------

    @_renamed_keywords(default="value")
    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
        *,
        aliases: Sequence[str] = (),
    ) -> Any:
        """Declare a parameter (rclpy's signature) and return it: the override given at construction, or
        ``value`` (the default); a :class:`Parameter` for an rclpy-style node, the plain value otherwise.

        ``aliases`` are other accepted spellings (e.g. Nav2's name for a ROS 1 parameter).
        """
        key = name.replace("/", ".")
        default = value
        for cand in () if ignore_override else (key, *(a.replace("/", ".") for a in aliases)):
            if cand in self._overrides:
                value = _coerce(cand, self._overrides[cand], default)
                self._declared[cand] = value
                break
        self._declared[key] = value
        return Parameter(name, value=value) if self._rclpy_style else value

    def declare_parameters(
        self, defaults: Mapping[str, Any], *, aliases: Mapping[str, Sequence[str]] | None = None
    ) -> dict[str, Any]:
        """Declare every ``name: default`` (e.g. from :func:`dataclass_parameters`); returns name -> value.

        ``aliases`` maps a name to its other accepted spellings (Nav2's, for a ROS 1 name).
        """
        aka = aliases or {}
        return {k: self.declare_parameter(k, d, aliases=aka.get(k, ())) for k, d in defaults.items()}

    def get_parameter(self, name: str) -> Any:
        """A declared parameter: a :class:`Parameter` (``.value``) for an rclpy-style node, else its value."""
        key = name.replace("/", ".")
        if key not in self._declared and self._allow_undeclared and key in self._overrides:
            self._declared[key] = self._overrides[key]
        try:
            value = self._declared[key]
        except KeyError:
            raise ParameterError(f"node {self.fully_qualified_name}: parameter {name!r} was not declared") from None
        return Parameter(name, value=value) if self._rclpy_style else value

    def get_parameters(self, names: Sequence[str]) -> list[Any]:
        """rclpy's ``get_parameters``: :meth:`get_parameter` of each name."""
        return [self.get_parameter(n) for n in names]

    def has_parameter(self, name: str) -> bool:
        """Whether ``name`` was declared."""
        return name.replace("/", ".") in self._declared

    def set_parameter(self, name: str, value: Any) -> None:
        """Change a declared parameter's value (the node reads it on its next use)."""
        key = name.replace("/", ".")
        if key not in self._declared:
            raise ParameterError(f"node {self.fully_qualified_name}: parameter {name!r} was not declared")
        self._declared[key] = _coerce(key, value, self._declared[key])

    def set_parameters(self, parameters: Sequence[Any]) -> list[Any]:
        """rclpy's ``set_parameters([Parameter(name, value=...)])``; returns one result (``.successful``) each."""
        results = []
        for p in parameters:
            self.set_parameter(p.name, p.value)
            results.append(SetParametersResult(successful=True))
        return results

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Any]:
        """Overrides under ``prefix.`` (undeclared ones too), with the prefix removed."""
        p = prefix.replace("/", ".") + "."
        return {k[len(p) :]: v for k, v in self._overrides.items() if k.startswith(p)}

    def list_parameters(self) -> list[str]:
        """Names of every parameter given to or declared by this node (rclpy's ``list_parameters``, unfiltered)."""
        return list(dict.fromkeys([*self._overrides, *self._declared]))

    def accept_parameters(self, prefix: str) -> None:
        """Mark every override under ``prefix.`` as known (for sub-objects that read them themselves)."""
        p = prefix.replace("/", ".") + "."
        for k in self._overrides:
            if k.startswith(p):
                self._declared.setdefault(k, self._overrides[k])

    def check_parameters(self) -> None:
        """Refuse overrides that no declaration asked for, suggesting the closest names (not for a node made
        with ``allow_undeclared_parameters=True``)."""
        if self._params_checked or self._allow_undeclared:
            return
        self._params_checked = True
        lines = []
        for key in (k for k in self._overrides if k not in self._declared):  # policy: params.check_unknown_key
            close = likely_typo(key, list(self._declared))
            if close:
                lines.append(f"{key!r} (did you mean {close[0]!r}?)")
            else:
                warnings.warn(
                    ParameterWarning(
                        f"node {self.fully_qualified_name}: unknown parameter {key!r} "
                        "ignored (ROS ignores what it does not read)",
                        key,
                    ),
                    stacklevel=2,
                )
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


def _transient_local(qos: Any) -> bool:
    """Whether an rclpy ``QoSProfile`` asks for transient_local durability (ROS 1's latching)."""
    durability = getattr(qos, "durability", None)
    return "TRANSIENT_LOCAL" in str(getattr(durability, "name", durability)).upper()


def _overrides_dict(overrides: Sequence[Any] | Mapping[str, Any] | None) -> dict[str, Any]:
    """rclpy's ``parameter_overrides`` (a list of Parameter) or a mapping, as navlab's nested dict."""
    if overrides is None:
        return {}
    if isinstance(overrides, Mapping):
        return dict(overrides)
    return {p.name.replace("/", "."): p.value for p in overrides}


def _as_list(x: Any | Sequence[Any]) -> list[Any]:
    return list(x) if isinstance(x, list | tuple) else [x]
