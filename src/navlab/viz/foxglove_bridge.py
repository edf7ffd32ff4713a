"""The run's topics over the Foxglove WebSocket protocol (``foxglove-sdk``), as foxglove_bridge serves a ROS 2 graph.

Every topic is advertised as a channel with its ROS 2 schema (``ros2msg``) and CDR encoding, so Foxglove's
panels read navlab's messages as they read a robot's. A topic is subscribed in the executor only while a
Foxglove client subscribes its channel (heavy messages — particle clouds, plans — are built only then).
Clients may publish (``clientPublish``): goals on ``/move_base_simple/goal``, initial poses on
``/initialpose``, ``cmd_vel`` or clicked points, CDR- or JSON-encoded; they are published in the executor's
thread (its inbox) by a node named ``/foxglove_bridge``.
"""

from __future__ import annotations

import functools
import json
import logging
import threading
from typing import Any

from foxglove.websocket import ServerListener

from navlab import msgs
from navlab.core import Executor, Node, Subscription
from navlab.viz.errors import VizError

_log = logging.getLogger("navlab.viz.foxglove")
PUBLISHABLE = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "geometry_msgs/msg/Twist",
    "geometry_msgs/msg/PointStamped",
)


def ros2_schema(typename: str) -> bytes:
    """The ``ros2msg`` definition of a message type with its dependencies (as rosbag2's MCAP stores it)."""
    return msgs.TYPESTORE.generate_msgdef(typename, ros_version=2)[0].encode()


def message_from_json(typename: str, data: dict[str, Any]) -> Any:
    """A navlab message from a JSON object with ROS field names (what Foxglove publishes in JSON)."""

    def header(d: dict[str, Any]) -> Any:
        stamp = d.get("stamp") or {}
        sec, nsec = int(stamp.get("sec", 0)), int(stamp.get("nanosec", stamp.get("nsec", 0)))
        return msgs.header(sec * 1_000_000_000 + nsec, str(d.get("frame_id", "")))

    def vec(d: dict[str, Any], cls: Any, keys: str = "xyz") -> Any:
        return cls(**{k: float(d.get(k, 0.0)) for k in keys})

    def pose(d: dict[str, Any]) -> Any:
        q = d.get("orientation") or {"w": 1.0}
        return msgs.Pose(position=vec(d.get("position") or {}, msgs.Point), orientation=vec(q, msgs.Quaternion, "xyzw"))

    if typename == "geometry_msgs/msg/PoseStamped":
        return msgs.PoseStamped(header=header(data.get("header") or {}), pose=pose(data.get("pose") or {}))
    if typename == "geometry_msgs/msg/PoseWithCovarianceStamped":
        inner = data.get("pose") or {}
        import numpy as np

        cov = np.array(inner.get("covariance") or [0.0] * 36, dtype=np.float64).reshape(36)
        return msgs.PoseWithCovarianceStamped(
            header=header(data.get("header") or {}),
            pose=msgs.PoseWithCovariance(pose=pose(inner.get("pose") or {}), covariance=cov),
        )
    if typename == "geometry_msgs/msg/Twist":
        return msgs.Twist(
            linear=vec(data.get("linear") or {}, msgs.Vector3), angular=vec(data.get("angular") or {}, msgs.Vector3)
        )
    if typename == "geometry_msgs/msg/PointStamped":
        cls = msgs.get_type("geometry_msgs/msg/PointStamped")
        return cls(header=header(data.get("header") or {}), point=vec(data.get("point") or {}, msgs.Point))
    raise VizError(f"foxglove: cannot publish {typename} (accepted: {', '.join(PUBLISHABLE)})")


class FoxgloveBridge(ServerListener):
    """Serves ``executor``'s topics to Foxglove on ``host:port`` until :meth:`close`."""

    def __init__(self, executor: Executor, *, host: str = "127.0.0.1", port: int = 8766) -> None:
        import foxglove
        from foxglove.websocket import Capability

        self.executor = executor
        self._foxglove = foxglove
        self.ctx = foxglove.Context()
        self.node = Node(executor, name="foxglove_bridge")
        self.channels: dict[str, Any] = {}  # topic -> foxglove Channel
        self._subs: dict[str, Subscription] = {}
        self._client_channels: dict[tuple[int, int], tuple[str, str, str]] = {}  # -> topic, encoding, type
        self._lock = threading.Lock()
        # the SDK's server object may not be used from two threads at once (stop() in the caller's thread, the
        # time broadcast in the executor's: "Already mutably borrowed")
        self._server_lock = threading.Lock()
        self._closed = False
        self._clients: dict[str, int] = {}  # topic -> how many clients subscribe it
        self.received = 0  # messages published by clients
        self._advertise()
        self.node.create_timer(1.0, self._advertise)
        self.node.create_timer(0.1, self.server_time)
        try:
            self.server = foxglove.start_server(
                name="navlab",
                host=host,
                port=port,
                capabilities=[Capability.ClientPublish, Capability.Time],
                supported_encodings=["cdr", "json"],
                server_listener=self,
                context=self.ctx,
            )
        except Exception as exc:
            self.node.destroy_node()
            raise VizError(f"cannot serve Foxglove on {host}:{port} ({exc})") from None
        self.port = int(self.server.port)

    def close(self) -> None:
        """Stop the Foxglove server and this bridge's subscriptions."""
        with self._server_lock:
            self._closed = True
            self.server.stop()
        self.executor.post(self.node.destroy_node)

    # --- channels (executor thread) -------------------------------------------------------------------

    def _advertise(self) -> None:
        for name, topic in list(self.executor.topics.items()):
            if name in self.channels:
                continue
            typename = msgs.type_name(topic.msgtype)
            schema = self._foxglove.Schema(name=typename, encoding="ros2msg", data=ros2_schema(typename))
            self.channels[name] = self._foxglove.Channel(name, schema=schema, message_encoding="cdr", context=self.ctx)

    def server_time(self) -> None:
        """Tell clients the simulated time (Foxglove's ``time`` capability)."""
        server = getattr(self, "server", None)
        with self._server_lock:
            if server is not None and not self._closed:
                server.broadcast_time(self.executor.now_ns)

    def _subscribe(self, topic: str) -> None:
        t = self.executor.topics.get(topic)
        if t is None or topic in self._subs:
            return
        self._subs[topic] = self.node.create_subscription(t.msgtype, topic, functools.partial(self._forward, topic), 10)

    def _unsubscribe(self, topic: str) -> None:
        sub = self._subs.pop(topic, None)
        t = self.executor.topics.get(topic)
        if sub is not None and t is not None and sub in t.subscriptions:
            t.subscriptions.remove(sub)
            self.node.subscriptions.remove(sub)

    def _forward(self, topic: str, msg: Any) -> None:
        ch = self.channels.get(topic)
        if ch is not None:
            ch.log(bytes(msgs.TYPESTORE.serialize_cdr(msg, msgs.type_name(msg))), log_time=self.executor.now_ns)

    # --- the SDK's ServerListener (its threads) --------------------------------------------------------

    def on_subscribe(self, client: Any, channel: Any) -> None:
        """A client subscribed a channel: subscribe its topic in the executor."""
        topic = str(channel.topic)
        with self._lock:
            self._clients[topic] = self._clients.get(topic, 0) + 1
        self.executor.post(functools.partial(self._subscribe, topic))

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        """A client left a channel (or disconnected): the topic is unsubscribed when no client is left."""
        topic = str(channel.topic)
        with self._lock:
            self._clients[topic] = left = max(self._clients.get(topic, 0) - 1, 0)
        if not left:
            self.executor.post(functools.partial(self._unsubscribe, topic))

    def on_client_advertise(self, client: Any, channel: Any) -> None:
        """A client will publish on ``channel.topic``."""
        typename = str(channel.schema_name or "")
        if "/msg/" not in typename and typename.count("/") == 1:  # ROS 1 style name
            typename = typename.replace("/", "/msg/")
        with self._lock:
            self._client_channels[(int(client.id), int(channel.id))] = (
                str(channel.topic),
                str(channel.encoding),
                typename,
            )

    def on_client_unadvertise(self, client: Any, client_channel_id: int) -> None:
        """A client stopped publishing a channel."""
        with self._lock:
            self._client_channels.pop((int(client.id), int(client_channel_id)), None)

    def on_message_data(self, client: Any, client_channel_id: int, data: bytes) -> None:
        """A client published a message: decode it and publish it in the executor's thread."""
        with self._lock:
            info = self._client_channels.get((int(client.id), int(client_channel_id)))
        if info is None:
            return
        topic, encoding, typename = info
        try:
            if typename not in PUBLISHABLE:
                raise VizError(f"cannot publish {typename!r} on {topic}")
            if encoding == "cdr":
                msg = msgs.TYPESTORE.deserialize_cdr(bytes(data), typename)
            elif encoding == "json":
                msg = message_from_json(typename, json.loads(bytes(data)))
            else:
                raise VizError(f"unsupported encoding {encoding!r}")
        except Exception as exc:
            _log.warning("foxglove: message on %s dropped: %s", topic, exc)
            return
        self.received += 1
        self.executor.post(functools.partial(self._publish, topic, msg))

    def _publish(self, topic: str, msg: Any) -> None:
        name = topic if topic.startswith("/") else "/" + topic
        for pub in self.node.publishers:
            if pub.topic_name == name:
                pub.publish(msg)
                return
        self.node.create_publisher(type(msg), name, 10).publish(msg)
