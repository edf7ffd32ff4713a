"""The bridge: a navlab run as ROS 1 nodes on a master (its own or the user's).

Every topic of the run is offered both ways: what navlab publishes is registered with the master under
the publishing node's name and served over TCPROS; what navlab subscribes to is subscribed on the wire,
and outside messages enter the executor through its thread-safe inbox. The bridge adds ``/clock``
(the simulated time), ``/rosout`` (the nodes' log lines), the parameter server (each node's parameters
and ``/robot_description``) and the services of :mod:`navlab.ros1.services`. XML-RPC and socket work
happens in background threads; the executor thread only converts and serializes messages.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import queue
import threading
import time
import xmlrpc.client
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from navlab import msgs
from navlab.core import Executor, Timer
from navlab.msgs import TFMessage, type_name
from navlab.ros1.clock import ClockFollower
from navlab.ros1.errors import Ros1Error
from navlab.ros1.master import Master
from navlab.ros1.net import LOG, XmlRpcServer, binding, call, host_port, master_uri, proxy
from navlab.ros1.types import Ros1Types, WireType
from navlab.ros1.wire import Incoming, Publication, TcpRosServer

BRIDGE_NAME = "/navlab"  # + "_<pid>", as rospy names anonymous nodes: two navlab runs can share a graph
INTERNAL = "/_"  # navlab-internal subscribers (the tf buffer) and topics
CLOCK_PERIOD_NS = 10_000_000  # /clock every 10 ms of simulated time


def connect_or_start_master(uri: str | None = None) -> tuple[str, Master | None]:
    """The master at ``uri`` (default ``$ROS_MASTER_URI``) when one answers, else navlab's own started there."""
    uri = uri or master_uri()
    try:
        proxy(uri, 1.0).getUri(BRIDGE_NAME)
        return uri, None
    except (OSError, xmlrpc.client.Error):  # nothing answers (or not a master): start one
        pass
    host, port = host_port(uri)
    if host not in ("localhost", "127.0.0.1", binding().advertise):
        raise Ros1Error(
            f"no ROS master answers at {uri} (ROS_MASTER_URI), and navlab can only start its own on this machine"
        )
    master = Master(port=port)
    LOG.warning("no ROS master answered at %s: started navlab's own (navlab roscore)", uri)
    return master.uri, master


@dataclass
class WireSubscription:
    """A topic navlab reads from the wire: its type, the node it subscribes as, and one connection per publisher."""

    wtype: WireType
    caller_id: str
    deliver: Callable[[bytes], None]
    connections: dict[str, Incoming] = field(default_factory=dict)


class RosBridge:
    """Offer the run of ``executor`` on the ROS 1 master at ``master``; ``close()`` unregisters everything."""

    def __init__(
        self,
        executor: Executor,
        *,
        master: str | None = None,
        params: dict[str, Any] | None = None,
        name: str | None = None,
        follow_clock: bool = False,
    ) -> None:
        self.ex = executor
        self.name = name or f"{BRIDGE_NAME}_{os.getpid()}"
        name = self.name
        self.types = Ros1Types()
        self.master_uri, self.own_master = connect_or_start_master(master)
        bind = binding()
        LOG.warning("ROS 1 bridge: master %s, listening on %s (%s)", self.master_uri, bind.bind, bind.why)
        self.tcpros = TcpRosServer(bind.bind, bind.advertise, name)
        self.xmlrpc = XmlRpcServer(self._slave_api(), bind.bind, bind.advertise)
        self.uri = self.xmlrpc.uri
        self.subs: dict[str, WireSubscription] = {}
        self._from_run: dict[str, Publication] = {}  # the run's topics offered on the wire
        self._jobs: queue.SimpleQueue[Callable[[], None] | None] = queue.SimpleQueue()
        self._injecting = False
        self._warned: set[str] = set()
        self._closed = False
        threading.Thread(target=self._registrar, name="ros1-registrar", daemon=True).start()
        self._set_params(params or {})
        self.offer("/rosout", "rosgraph_msgs/msg/Log", name)
        for tf_topic in ("/tf", "/tf_static"):  # read from the graph even before a node of the run publishes tf
            executor.topic(tf_topic, TFMessage)
        self.follower: ClockFollower | None = None
        self._clock: Timer | None = None
        if follow_clock:  # the graph owns the time: no /clock of our own
            follower = self.follower = ClockFollower(executor)
            clock_type = "rosgraph_msgs/msg/Clock"
            self.subscribe(
                "/clock",
                clock_type,
                name,
                lambda raw: follower.tick(msgs.ns_from_time(self.types.deserialize(raw, clock_type).clock)),
            )
        else:
            clock = self.offer("/clock", "rosgraph_msgs/msg/Clock", name)
            self._clock = Timer(
                executor, CLOCK_PERIOD_NS, self._tick_clock, -100, executor.now_ns, idle=lambda: not clock.connections
            )
        self._log_handler = _RosoutHandler(self)
        logging.getLogger("navlab").addHandler(self._log_handler)
        executor.add_listener(self._on_publish)
        from navlab.ros1.actionlib import offer_move_base
        from navlab.ros1.services import offer_services

        offer_services(self)
        offer_move_base(self)
        self.sync()
        self._syncer = threading.Thread(target=self._sync_loop, name="ros1-sync", daemon=True)
        self._syncer.start()

    # --- registration with the master (in the registrar thread) ----------------------------------------

    def _registrar(self) -> None:
        while True:
            job = self._jobs.get()
            if job is None:
                return
            try:
                job()
            except Ros1Error as exc:
                LOG.warning("ros1: %s", exc)

    def _master(self, method: str, *args: Any) -> Any:
        return call(self.master_uri, method, *args)

    def _set_params(self, params: dict[str, Any]) -> None:
        for key, value in params.items():
            safe = _xmlrpc_value(value)
            if safe is not None:
                self._jobs.put(functools.partial(self._master, "setParam", self.name, key, safe))

    def offer(
        self, topic: str, ros1_type: str, caller_id: str, latched: Callable[[], list[bytes]] | None = None
    ) -> Publication:
        pub = Publication(topic, self.types.wire_type(ros1_type), caller_id, latched or (lambda: []))
        self.tcpros.publications[topic] = pub
        self._jobs.put(lambda: self._master("registerPublisher", caller_id, topic, pub.wtype.wire, self.uri))
        return pub

    def sync(self) -> None:
        """Offer topics and subscriptions that appeared in the executor since the last call (executor thread)."""
        for name, topic in list(self.ex.topics.items()):
            if name.startswith(INTERNAL):
                continue
            ros1 = self.types.ros1_type_of(type_name(topic.msgtype))
            if ros1 is None:
                if name not in self._warned:
                    self._warned.add(name)
                    LOG.info("ros1: %s (%s) has no ROS 1 type: not bridged", name, type_name(topic.msgtype))
                continue
            if topic.publishers and name not in self.tcpros.publications:
                self._from_run[name] = self.offer(name, ros1, topic.publishers[0], self._latched_of(name, ros1))
            readers = [s.node for s in topic.subscriptions]
            if readers and name not in self.subs:
                caller = next((r for r in readers if not r.startswith(INTERNAL)), self.name)
                self.subscribe(name, ros1, caller, self._deliverer(name, ros1, type_name(topic.msgtype)))

    def flush(self, timeout: float = 10.0) -> bool:
        """Wait until every registration queued so far reached the master (False on timeout)."""
        done = threading.Event()
        self._jobs.put(done.set)
        return done.wait(timeout)

    def _sync_loop(self) -> None:
        while not self._closed:
            time.sleep(1.0)
            self.ex.post(self.sync)

    def _latched_of(self, name: str, ros1: str) -> Callable[[], list[bytes]]:
        topic = self.ex.topics[name]

        def latched() -> list[bytes]:
            return [self.types.serialize(self.types.to_ros1(m, ros1), ros1) for m in list(topic.latched.values())]

        return latched

    def subscribe(self, topic: str, ros1: str, caller: str, deliver: Callable[[bytes], None]) -> None:
        """Subscribe on the wire to ``topic`` as node ``caller``; ``deliver`` gets each message's bytes
        (in a connection thread)."""
        sub = self.subs[topic] = WireSubscription(self.types.wire_type(ros1), caller, deliver)

        def register() -> None:
            self._update_publishers(topic, self._master("registerSubscriber", caller, topic, sub.wtype.wire, self.uri))

        self._jobs.put(register)

    def _update_publishers(self, topic: str, apis: list[str]) -> None:
        sub = self.subs.get(topic)
        if sub is None or self._closed:
            return
        conns = sub.connections
        for api in apis:
            if api != self.uri and (api not in conns or conns[api].closed):
                conns[api] = Incoming(
                    api, topic, sub.wtype, sub.caller_id, sub.deliver, lambda c: _discard(conns, c.api)
                )
        for api in list(conns):
            if api not in apis:
                conns.pop(api).close()

    def _deliverer(self, topic: str, ros1: str, ros2: str) -> Callable[[bytes], None]:
        def deliver(payload: bytes) -> None:
            msg = self.types.to_ros2(self.types.deserialize(payload, ros1), ros2)
            self.ex.post(lambda: self.inject(topic, msg))

        return deliver

    def inject(self, topic: str, msg: Any) -> None:
        """Publish an outside message into the run (executor thread); it is not echoed back to the wire."""
        self._injecting = True
        try:
            self.ex.publish(self.ex.topics[topic], msg)
        finally:
            self._injecting = False

    # --- the executor's side ---------------------------------------------------------------------------

    def _on_publish(self, topic: str, msg: Any, t_ns: int) -> None:
        pub = self._from_run.get(topic)  # not the bridge's own (/clock, actionlib's status on move_base's name)
        if pub is None or not pub.connections or self._injecting:
            return
        ros1 = pub.wtype.typename
        pub.send(self.types.serialize(self.types.to_ros1(msg, ros1), ros1))

    def _tick_clock(self) -> None:
        clock_type = self.types.store.types["rosgraph_msgs/msg/Clock"]
        self.tcpros.publications["/clock"].send(
            self.types.serialize(clock_type(clock=msgs.time_from_ns(self.ex.now_ns)), "rosgraph_msgs/msg/Clock")
        )

    # --- the slave API ---------------------------------------------------------------------------------

    def _slave_api(self) -> dict[str, Callable[..., list[Any]]]:
        def pubs() -> list[list[str]]:
            return [[t, p.wtype.wire] for t, p in self.tcpros.publications.items()]

        def bus_info(caller_id: str) -> list[Any]:
            rows: list[list[Any]] = []
            for i, (t, p) in enumerate(self.tcpros.publications.items()):
                rows += [[i, c.peer, "o", "TCPROS", t, True] for c in p.connections]
            for t, sub in self.subs.items():
                rows += [[0, api, "i", "TCPROS", t, True] for api in sub.connections]
            return [1, "bus info", rows]

        def request_topic(caller_id: str, topic: str, protocols: list[Any]) -> list[Any]:
            if topic not in self.tcpros.publications:
                return [-1, f"not a publisher of {topic}", []]
            if not any(p and p[0] == "TCPROS" for p in protocols):
                return [0, "navlab speaks TCPROS only", []]
            return [1, "ready", ["TCPROS", self.tcpros.host, self.tcpros.port]]

        def publisher_update(caller_id: str, topic: str, publishers: list[str]) -> list[Any]:
            self._jobs.put(lambda: self._update_publishers(topic, publishers))
            return [1, "ok", 0]

        def shutdown(caller_id: str, msg: str = "") -> list[Any]:
            LOG.warning("ros1: %s asked navlab to shut down: %s", caller_id, msg)
            self.ex.post(self.ex.stop)
            return [1, "shutdown", 0]

        return {
            "getBusStats": lambda caller_id: [
                1,
                "stats",
                [[[t, 0, [[0, p.count, 0, True]]] for t, p in self.tcpros.publications.items()], [], []],
            ],
            "getBusInfo": bus_info,
            "getMasterUri": lambda caller_id: [1, "master", self.master_uri],
            "shutdown": shutdown,
            "getPid": lambda caller_id: [1, "pid", os.getpid()],
            "getSubscriptions": lambda caller_id: [
                1,
                "subscriptions",
                [[t, s.wtype.wire] for t, s in self.subs.items()],
            ],
            "getPublications": lambda caller_id: [1, "publications", pubs()],
            "paramUpdate": lambda caller_id, key, value: [1, "ok", 0],
            "publisherUpdate": publisher_update,
            "requestTopic": request_topic,
        }

    # --- shutting down ---------------------------------------------------------------------------------

    def close(self) -> None:
        """Unregister from the master (best effort, 2 s) and close every connection."""
        if self._closed:
            return
        self._closed = True
        if self._clock is not None:
            self._clock.cancel()
        if self.follower is not None:
            self.follower.close()
        logging.getLogger("navlab").removeHandler(self._log_handler)
        with contextlib.suppress(ValueError):
            self.ex.remove_listener(self._on_publish)
        done = threading.Event()

        def unregister() -> None:
            for topic, pub in self.tcpros.publications.items():
                _quiet("unregisterPublisher", self.master_uri, pub.caller_id, topic, self.uri)
            for topic, sub in self.subs.items():
                _quiet("unregisterSubscriber", self.master_uri, sub.caller_id, topic, self.uri)
                for conn in list(sub.connections.values()):
                    conn.close()
            for srv in self.tcpros.services.values():
                _quiet("unregisterService", self.master_uri, srv.caller_id, srv.name, self.tcpros.uri)
            done.set()

        self._jobs.put(unregister)
        self._jobs.put(None)
        done.wait(5.0)
        self.tcpros.close()
        self.xmlrpc.close()
        if self.own_master is not None:
            self.own_master.close()


def _quiet(method: str, uri: str, *args: Any) -> None:
    """A master call whose failure does not matter (unregistering while shutting down)."""
    with contextlib.suppress(Ros1Error):
        call(uri, method, *args, timeout=1.0)


def _discard(conns: dict[str, Incoming], api: str) -> None:
    conns.pop(api, None)


def _xmlrpc_value(value: Any) -> Any:
    """A parameter value XML-RPC can carry (numpy to Python, tuples to lists, None and huge ints left out)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, bool | float | str):
        return value
    if isinstance(value, int):
        return value if -(2**31) <= value < 2**31 else float(value)
    if isinstance(value, dict):
        out = {str(k): _xmlrpc_value(v) for k, v in value.items()}
        return {k: v for k, v in out.items() if v is not None}
    if isinstance(value, list | tuple):
        items = [_xmlrpc_value(v) for v in value]
        return [v for v in items if v is not None]
    return None


class _RosoutHandler(logging.Handler):
    """navlab's log lines as ``rosgraph_msgs/Log`` on ``/rosout`` (level, node name, text)."""

    LEVELS: ClassVar[dict[int, int]] = {
        logging.DEBUG: 1,
        logging.INFO: 2,
        logging.WARNING: 4,
        logging.ERROR: 8,
        logging.CRITICAL: 16,
    }

    def __init__(self, bridge: RosBridge) -> None:
        super().__init__(logging.INFO)
        self.bridge = bridge

    def emit(self, record: logging.LogRecord) -> None:
        pub = self.bridge.tcpros.publications.get("/rosout")
        if pub is None or not pub.connections or record.name.startswith("navlab.ros1"):
            return
        from navlab.msgs import time_from_ns

        store = self.bridge.types.store
        node = getattr(record, "node", None) or "/" + record.name.removeprefix("navlab").strip(".").replace(".", "/")
        msg = store.types["rosgraph_msgs/msg/Log"](
            header=store.types["std_msgs/msg/Header"](seq=0, stamp=time_from_ns(self.bridge.ex.now_ns), frame_id=""),
            level=self.LEVELS.get(record.levelno, 2),
            name=node,
            msg=record.getMessage(),
            file=record.pathname,
            function=record.funcName,
            line=record.lineno,
            topics=[t for t, p in self.bridge.tcpros.publications.items() if p.caller_id == node],
        )
        pub.send(self.bridge.types.serialize(msg, "rosgraph_msgs/msg/Log"))


def session_params(nodes: dict[str, Any]) -> dict[str, Any]:
    """The parameter server's content for a run: each node's parameters under its name, and
    ``/robot_description`` (the expanded URDF of the simulated robot, when there is one)."""
    out: dict[str, Any] = {}
    for name, node in nodes.items():
        values = {**getattr(node, "_overrides", {}), **getattr(node, "_declared", {})}  # declared wins
        tree: dict[str, Any] = {}
        for key, value in sorted(values.items()):
            parts = key.split(".")
            branch = tree
            for part in parts[:-1]:
                nxt = branch.setdefault(part, {})
                if not isinstance(nxt, dict):
                    break
                branch = nxt
            else:
                branch[parts[-1]] = value
        out[name] = tree
        sim = getattr(node, "sim", None)
        urdf = getattr(getattr(sim, "robot", None), "urdf_xml", "")
        if urdf:
            out["/robot_description"] = urdf
    return out
