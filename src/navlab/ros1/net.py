"""Addresses and XML-RPC plumbing shared by navlab's ROS 1 master and its nodes.

Where to listen follows ROS: ``ROS_IP`` (an address) or ``ROS_HOSTNAME`` (a name) say which address
peers use to reach this process; without either navlab listens on loopback only, so nothing outside
this machine can reach the run (ROS 1 itself would listen on every interface).
"""

from __future__ import annotations

import logging
import os
import socketserver
import threading
import xmlrpc.client
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlparse
from xmlrpc.server import SimpleXMLRPCRequestHandler, SimpleXMLRPCServer

from navlab.ros1.errors import Ros1Error

LOG = logging.getLogger("navlab.ros1")
DEFAULT_MASTER_URI = "http://localhost:11311/"


@dataclass(frozen=True)
class Binding:
    """Where this process listens (``bind``) and the host name it gives peers (``advertise``)."""

    bind: str
    advertise: str
    why: str


def binding(environ: dict[str, str] | None = None) -> Binding:
    """Loopback unless ``ROS_IP``/``ROS_HOSTNAME`` say otherwise (as ROS reads them: ROS_IP wins)."""
    env = os.environ if environ is None else environ
    ip, host = env.get("ROS_IP", "").strip(), env.get("ROS_HOSTNAME", "").strip()
    if ip:
        return Binding(ip, ip, f"ROS_IP={ip}")
    if host:
        loop = host in ("localhost", "127.0.0.1")
        return Binding("127.0.0.1" if loop else "0.0.0.0", host, f"ROS_HOSTNAME={host}")
    return Binding("127.0.0.1", "127.0.0.1", "loopback only; set ROS_IP or ROS_HOSTNAME to reach other machines")


def master_uri(environ: dict[str, str] | None = None) -> str:
    """``$ROS_MASTER_URI`` or ROS's default ``http://localhost:11311/``."""
    env = os.environ if environ is None else environ
    return env.get("ROS_MASTER_URI", "").strip() or DEFAULT_MASTER_URI


def host_port(uri: str) -> tuple[str, int]:
    """(host, port) of an ``http://host:port/`` or ``rosrpc://host:port`` URI (``Ros1Error`` if malformed)."""
    parsed = urlparse(uri)
    if not parsed.hostname or not parsed.port:
        raise Ros1Error(f"malformed ROS URI {uri!r}: expected scheme://host:port/")
    return parsed.hostname, parsed.port


class _Quiet(SimpleXMLRPCRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        pass


class _Server(socketserver.ThreadingMixIn, SimpleXMLRPCServer):
    daemon_threads = True
    allow_reuse_address = True


class XmlRpcServer:
    """A threaded XML-RPC server in the background serving ``functions`` (the ROS master or slave API)."""

    def __init__(self, functions: dict[str, Callable[..., Any]], host: str, advertise: str, port: int = 0) -> None:
        try:
            self._server = _Server((host, port), requestHandler=_Quiet, logRequests=False, allow_none=False)
        except OSError as exc:
            raise Ros1Error(f"cannot listen on {host}:{port} for XML-RPC ({exc.strerror or exc})") from None
        for name, fn in functions.items():
            self._server.register_function(fn, name)
        self.port = self._server.server_address[1]
        self.uri = f"http://{advertise}:{self.port}/"
        self._thread = threading.Thread(target=self._server.serve_forever, name="ros1-xmlrpc", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()


def proxy(uri: str, timeout: float = 5.0) -> xmlrpc.client.ServerProxy:
    """An XML-RPC client for ``uri`` whose calls give up after ``timeout`` seconds."""
    transport = _TimeoutTransport()
    transport.timeout = timeout
    return xmlrpc.client.ServerProxy(uri, transport=transport, allow_none=False)


class _TimeoutTransport(xmlrpc.client.Transport):
    timeout = 5.0

    def make_connection(self, host: Any) -> Any:
        conn = super().make_connection(host)
        conn.timeout = self.timeout
        return conn


def call(uri: str, method: str, *args: Any, timeout: float = 5.0) -> Any:
    """Call a ROS XML-RPC API method; its value on success (code 1), ``Ros1Error`` otherwise."""
    try:
        code, msg, value = getattr(proxy(uri, timeout), method)(*args)
    except (OSError, xmlrpc.client.Error) as exc:
        raise Ros1Error(f"{uri} {method}: {exc}") from None
    if code != 1:
        raise Ros1Error(f"{uri} {method}: {msg}")
    return value
