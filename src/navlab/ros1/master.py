"""navlab's own ROS 1 master (``navlab roscore``): the master and parameter server XML-RPC APIs.

Implements the published ROS 1 Master API (registration of publishers, subscribers and services,
lookups, system state) and Parameter Server API (get/set/delete/has/search/subscribe/names), with the
``publisherUpdate`` and ``paramUpdate`` callbacks to nodes. Every reply is ``[code, statusMessage, value]``
(1 success, -1 caller error, 0 failure).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from navlab.ros1.net import LOG, XmlRpcServer, binding, proxy

MASTER_ID = "/master"
Reply = list[Any]


def namespace_of(name: str) -> str:
    """``/a/b/node`` -> ``/a/b/``."""
    return name.rsplit("/", 1)[0] + "/" if "/" in name.strip("/") else "/"


def resolve(caller_id: str, key: str) -> str:
    """A parameter or graph name resolved in the caller's namespace (no trailing slash except ``/``)."""
    if key.startswith("~"):
        key = caller_id.rstrip("/") + "/" + key[1:]
    elif not key.startswith("/"):
        key = namespace_of(caller_id) + key
    return "/" + "/".join(p for p in key.split("/") if p)


class ParamTree:
    """The parameter server's tree: nested dicts; a namespace reads as a dict of everything under it."""

    def __init__(self) -> None:
        self.root: dict[str, Any] = {}

    @staticmethod
    def _parts(key: str) -> list[str]:
        return [p for p in key.split("/") if p]

    def get(self, key: str) -> Any:
        node: Any = self.root
        for p in self._parts(key):
            if not isinstance(node, dict) or p not in node:
                raise KeyError(key)
            node = node[p]
        return node

    def has(self, key: str) -> bool:
        try:
            self.get(key)
        except KeyError:
            return False
        return True

    def set(self, key: str, value: Any) -> None:
        parts = self._parts(key)
        if not parts:
            self.root = dict(value) if isinstance(value, dict) else self.root
            return
        node = self.root
        for p in parts[:-1]:
            if not isinstance(node.get(p), dict):
                node[p] = {}
            node = node[p]
        node[parts[-1]] = value

    def delete(self, key: str) -> None:
        parts = self._parts(key)
        node = self.get("/" + "/".join(parts[:-1])) if parts else None
        if not isinstance(node, dict) or parts[-1] not in node:
            raise KeyError(key)
        del node[parts[-1]]

    def names(self) -> list[str]:
        out: list[str] = []

        def walk(prefix: str, node: Any) -> None:
            if isinstance(node, dict) and node:
                for k, v in node.items():
                    walk(f"{prefix}/{k}", v)
            elif prefix:
                out.append(prefix)

        walk("", self.root)
        return out


class Master:
    """The ROS 1 master and parameter server, served over XML-RPC in background threads."""

    def __init__(self, *, port: int = 11311, host: str | None = None) -> None:
        bind = binding()
        self._lock = threading.RLock()
        self.params = ParamTree()
        self.publishers: dict[str, dict[str, str]] = {}  # topic -> caller_id -> caller_api
        self.subscribers: dict[str, dict[str, str]] = {}
        self.services: dict[str, dict[str, tuple[str, str]]] = {}  # service -> caller_id -> (service_api, caller_api)
        self.topic_types: dict[str, str] = {}
        self.nodes: dict[str, str] = {}  # caller_id -> caller_api
        self.param_subscribers: dict[str, dict[str, str]] = {}  # key -> caller_id -> caller_api
        self._notify = ThreadPoolExecutor(max_workers=4, thread_name_prefix="ros1-master-notify")
        functions: dict[str, Callable[..., Reply]] = {
            name: getattr(self, name)
            for name in (
                "registerService",
                "unregisterService",
                "registerSubscriber",
                "unregisterSubscriber",
                "registerPublisher",
                "unregisterPublisher",
                "lookupNode",
                "getPublishedTopics",
                "getTopicTypes",
                "getSystemState",
                "getUri",
                "lookupService",
                "getPid",
                "shutdown",
                "deleteParam",
                "setParam",
                "getParam",
                "searchParam",
                "subscribeParam",
                "unsubscribeParam",
                "hasParam",
                "getParamNames",
            )
        }
        self.server = XmlRpcServer(functions, host or bind.bind, bind.advertise, port)
        self.uri = self.server.uri
        self.stopped = threading.Event()
        LOG.info("ROS master at %s (%s)", self.uri, bind.why)

    def close(self) -> None:
        self.server.close()
        self._notify.shutdown(wait=False, cancel_futures=True)
        self.stopped.set()

    # --- registration ----------------------------------------------------------------------------------

    def _node(self, caller_id: str, caller_api: str) -> None:
        old = self.nodes.get(caller_id)
        if old and old != caller_api:  # a new node took the name: ROS shuts the old one down
            self._send(old, "shutdown", MASTER_ID, f"new node registered with the same name {caller_id}")
        self.nodes[caller_id] = caller_api

    def _send(self, api: str, method: str, *args: Any) -> None:
        def run() -> None:
            try:
                getattr(proxy(api, 2.0), method)(*args)
            except Exception as exc:
                LOG.info("master: %s on %s failed: %s", method, api, exc)

        self._notify.submit(run)

    def _publisher_update(self, topic: str) -> None:
        pubs = list(self.publishers.get(topic, {}).values())
        for api in self.subscribers.get(topic, {}).values():
            self._send(api, "publisherUpdate", MASTER_ID, topic, pubs)

    def registerService(self, caller_id: str, service: str, service_api: str, caller_api: str) -> Reply:
        with self._lock:
            self._node(caller_id, caller_api)
            self.services.setdefault(resolve(caller_id, service), {})[caller_id] = (service_api, caller_api)
        return [1, f"registered {service}", 0]

    def unregisterService(self, caller_id: str, service: str, service_api: str) -> Reply:
        with self._lock:
            entry = self.services.get(resolve(caller_id, service), {})
            n = 1 if entry.pop(caller_id, None) else 0
        return [1, f"unregistered {n}", n]

    def registerSubscriber(self, caller_id: str, topic: str, topic_type: str, caller_api: str) -> Reply:
        topic = resolve(caller_id, topic)
        with self._lock:
            self._node(caller_id, caller_api)
            self.subscribers.setdefault(topic, {})[caller_id] = caller_api
            if topic_type != "*":
                self.topic_types.setdefault(topic, topic_type)
            pubs = list(self.publishers.get(topic, {}).values())
        return [1, f"subscribed to {topic}", pubs]

    def unregisterSubscriber(self, caller_id: str, topic: str, caller_api: str) -> Reply:
        with self._lock:
            n = 1 if self.subscribers.get(resolve(caller_id, topic), {}).pop(caller_id, None) else 0
        return [1, f"unregistered {n}", n]

    def registerPublisher(self, caller_id: str, topic: str, topic_type: str, caller_api: str) -> Reply:
        topic = resolve(caller_id, topic)
        with self._lock:
            self._node(caller_id, caller_api)
            self.publishers.setdefault(topic, {})[caller_id] = caller_api
            self.topic_types[topic] = topic_type
            subs = list(self.subscribers.get(topic, {}).values())
            self._publisher_update(topic)
        return [1, f"registered {caller_id} as publisher of {topic}", subs]

    def unregisterPublisher(self, caller_id: str, topic: str, caller_api: str) -> Reply:
        topic = resolve(caller_id, topic)
        with self._lock:
            n = 1 if self.publishers.get(topic, {}).pop(caller_id, None) else 0
            if n:
                self._publisher_update(topic)
        return [1, f"unregistered {n}", n]

    # --- lookups ---------------------------------------------------------------------------------------

    def lookupNode(self, caller_id: str, node_name: str) -> Reply:
        api = self.nodes.get(resolve(caller_id, node_name))
        return [1, "node api", api] if api else [-1, f"unknown node {node_name}", ""]

    def lookupService(self, caller_id: str, service: str) -> Reply:
        entry = self.services.get(resolve(caller_id, service))
        if not entry:
            return [-1, f"no provider for {service}", ""]
        return [1, "rosrpc URI", next(iter(entry.values()))[0]]

    def getPublishedTopics(self, caller_id: str, subgraph: str) -> Reply:
        with self._lock:
            rows = [
                [t, self.topic_types.get(t, "*")]
                for t, p in self.publishers.items()
                if p and t.startswith(subgraph or "")
            ]
        return [1, "published topics", rows]

    def getTopicTypes(self, caller_id: str) -> Reply:
        with self._lock:
            return [1, "topic types", [[t, k] for t, k in self.topic_types.items()]]

    def getSystemState(self, caller_id: str) -> Reply:
        with self._lock:
            pubs = [[t, list(p)] for t, p in self.publishers.items() if p]
            subs = [[t, list(s)] for t, s in self.subscribers.items() if s]
            srvs = [[s, list(p)] for s, p in self.services.items() if p]
        return [1, "system state", [pubs, subs, srvs]]

    def getUri(self, caller_id: str) -> Reply:
        return [1, "master uri", self.uri]

    def getPid(self, caller_id: str) -> Reply:
        return [1, "pid", os.getpid()]

    def shutdown(self, caller_id: str, msg: str = "") -> Reply:
        LOG.warning("master: shutdown requested by %s: %s", caller_id, msg)
        threading.Thread(target=self.close, daemon=True).start()
        return [1, "shutdown", 0]

    # --- parameter server ------------------------------------------------------------------------------

    def setParam(self, caller_id: str, key: str, value: Any) -> Reply:
        key = resolve(caller_id, key)
        with self._lock:
            self.params.set(key, value)
            for watched, subs in self.param_subscribers.items():
                if key.startswith(watched.rstrip("/")) or watched.startswith(key):
                    for api in subs.values():
                        self._send(
                            api,
                            "paramUpdate",
                            MASTER_ID,
                            watched + "/" if not watched.endswith("/") else watched,
                            self._get_or_empty(watched),
                        )
        return [1, f"parameter {key} set", 0]

    def _get_or_empty(self, key: str) -> Any:
        try:
            return self.params.get(key)
        except KeyError:
            return {}

    def getParam(self, caller_id: str, key: str) -> Reply:
        key = resolve(caller_id, key)
        with self._lock:
            try:
                return [1, f"Parameter [{key}]", self.params.get(key)]
            except KeyError:
                return [-1, f"Parameter [{key}] is not set", 0]

    def deleteParam(self, caller_id: str, key: str) -> Reply:
        key = resolve(caller_id, key)
        with self._lock:
            try:
                self.params.delete(key)
            except KeyError:
                return [-1, f"parameter [{key}] is not set", 0]
        return [1, f"parameter {key} deleted", 0]

    def hasParam(self, caller_id: str, key: str) -> Reply:
        key = resolve(caller_id, key)
        with self._lock:
            return [1, key, self.params.has(key)]

    def searchParam(self, caller_id: str, key: str) -> Reply:
        """The closest ``key`` in the caller's namespace or above (ROS's upward search on the first part)."""
        first, _, rest = key.lstrip("~/").partition("/")
        ns = namespace_of(caller_id)
        with self._lock:
            while True:
                cand = ns + first
                if self.params.has(cand):
                    return [1, "found", cand + ("/" + rest if rest else "")]
                if ns == "/":
                    return [-1, f"cannot find parameter [{key}]", ""]
                ns = namespace_of(ns.rstrip("/"))

    def subscribeParam(self, caller_id: str, caller_api: str, key: str) -> Reply:
        key = resolve(caller_id, key)
        with self._lock:
            self.param_subscribers.setdefault(key, {})[caller_id] = caller_api
            return [1, f"subscribed to {key}", self._get_or_empty(key)]

    def unsubscribeParam(self, caller_id: str, caller_api: str, key: str) -> Reply:
        with self._lock:
            n = 1 if self.param_subscribers.get(resolve(caller_id, key), {}).pop(caller_id, None) else 0
        return [1, f"unsubscribed {n}", n]

    def getParamNames(self, caller_id: str) -> Reply:
        with self._lock:
            return [1, "parameter names", self.params.names()]
