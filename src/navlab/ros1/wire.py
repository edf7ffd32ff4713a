"""TCPROS connections: publications served to outside subscribers, subscriptions to outside publishers,
and service calls. Each connection has its own thread; nothing here ever blocks the executor.

A publication hands each serialized message to every connection's bounded queue (the oldest message is
dropped when a subscriber falls behind, as roscpp's ``queue_size`` does); a peer that disconnects or
sends garbage is dropped with a log line.
"""

from __future__ import annotations

import contextlib
import socket
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from navlab.ros1.errors import Ros1Error
from navlab.ros1.net import LOG, call, host_port
from navlab.ros1.tcpros import encode_header, frame, recv_frame, recv_header
from navlab.ros1.types import ServiceType, WireType

QUEUE_SIZE = 100  # messages per outgoing connection before the oldest is dropped
SEND_BUFFER = 128 * 1024  # bytes of kernel send buffer per outgoing connection (Linux doubles it)


class Outgoing:
    """One subscriber's connection to a publication: a bounded queue drained by a writer thread."""

    def __init__(self, sock: socket.socket, peer: str, topic: str, queue_size: int = QUEUE_SIZE) -> None:
        self.sock, self.peer, self.topic = sock, peer, topic
        self.queue: deque[bytes] = deque(maxlen=queue_size)
        self.cond = threading.Condition()
        self.closed = False
        self.sent = self.dropped = 0
        threading.Thread(target=self._write, name=f"ros1-out{topic}", daemon=True).start()

    def put(self, data: bytes) -> None:
        with self.cond:
            if len(self.queue) == self.queue.maxlen:
                self.dropped += 1
            self.queue.append(data)
            self.cond.notify()

    def _write(self) -> None:
        try:
            while True:
                with self.cond:
                    while not self.queue and not self.closed:
                        self.cond.wait()
                    if self.closed:
                        return
                    data = self.queue.popleft()
                self.sock.sendall(data)
                self.sent += 1
        except OSError as exc:
            LOG.info("ros1: subscriber %s of %s dropped (%s)", self.peer, self.topic, exc)
        finally:
            self.close()

    def close(self) -> None:
        with self.cond:
            self.closed = True
            self.cond.notify()
        with contextlib.suppress(OSError):
            self.sock.close()


@dataclass
class Publication:
    """A topic navlab publishes on the wire: its type, its connections, and what a new one gets first."""

    topic: str
    wtype: WireType
    caller_id: str
    latched: Callable[[], list[bytes]] = lambda: []
    connections: list[Outgoing] = field(default_factory=list)
    count: int = 0

    def send(self, payload: bytes) -> None:
        data = frame(payload)
        self.count += 1
        for conn in list(self.connections):
            if conn.closed:
                self.connections.remove(conn)
            else:
                conn.put(data)


@dataclass
class Service:
    """A service navlab offers on the wire: its type and a function from request bytes to response bytes."""

    name: str
    stype: ServiceType
    caller_id: str
    handle: Callable[[bytes], bytes]


class TcpRosServer:
    """The listening socket of one navlab process: topic subscribers and service clients connect here."""

    def __init__(self, host: str, advertise: str, caller_id: str) -> None:
        self.caller_id = caller_id
        self.publications: dict[str, Publication] = {}
        self.services: dict[str, Service] = {}
        self._sock = socket.create_server((host, 0))
        self.host, self.port = advertise, self._sock.getsockname()[1]
        self.uri = f"rosrpc://{advertise}:{self.port}"
        self._closed = False
        threading.Thread(target=self._accept, name="ros1-tcpros", daemon=True).start()

    def close(self) -> None:
        self._closed = True
        self._sock.close()
        for pub in self.publications.values():
            for conn in pub.connections:
                conn.close()

    def _accept(self) -> None:
        while not self._closed:
            try:
                sock, addr = self._sock.accept()
            except OSError:
                return
            threading.Thread(target=self._handshake, args=(sock, f"{addr[0]}:{addr[1]}"), daemon=True).start()

    def _handshake(self, sock: socket.socket, peer: str) -> None:
        try:
            sock.settimeout(10.0)
            header = recv_header(sock)
            if "service" in header:
                self._serve_service(sock, header, peer)
            elif "topic" in header:
                self._serve_topic(sock, header, peer)
            else:
                raise Ros1Error("connection header names neither topic nor service")
        except (Ros1Error, OSError) as exc:
            LOG.warning("ros1: dropped peer %s: %s", peer, exc)
            sock.close()

    def _refuse(self, sock: socket.socket, error: str) -> None:
        sock.sendall(encode_header({"error": error}))
        raise Ros1Error(error)

    def _serve_topic(self, sock: socket.socket, header: dict[str, str], peer: str) -> None:
        topic = header["topic"]
        pub = self.publications.get(topic)
        if pub is None:
            self._refuse(sock, f"navlab does not publish {topic}")
            return
        md5 = header.get("md5sum", "*")
        if md5 not in ("*", pub.wtype.md5sum):
            self._refuse(
                sock,
                f"{topic}: md5sum mismatch: theirs {md5} ({header.get('type')}), "
                f"ours {pub.wtype.md5sum} ({pub.wtype.wire})",
            )
            return
        latched = pub.latched()
        sock.sendall(
            encode_header(
                {
                    "callerid": pub.caller_id,
                    "md5sum": pub.wtype.md5sum,
                    "type": pub.wtype.wire,
                    "topic": topic,
                    "message_definition": pub.wtype.definition,
                    "latching": "1" if latched else "0",
                }
            )
        )
        if header.get("tcp_nodelay") == "1":
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        # a small kernel buffer: a subscriber that stops reading backs up into its bounded queue, not into megabytes
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER)
        sock.settimeout(None)
        conn = Outgoing(sock, f"{header.get('callerid', '?')} ({peer})", topic)
        for payload in latched:
            conn.put(frame(payload))
        pub.connections.append(conn)

    def _serve_service(self, sock: socket.socket, header: dict[str, str], peer: str) -> None:
        srv = self.services.get(header["service"])
        if srv is None:
            self._refuse(sock, f"navlab offers no service {header['service']}")
            return
        md5 = header.get("md5sum", "*")
        if md5 not in ("*", srv.stype.md5sum):
            self._refuse(sock, f"{srv.name}: md5sum mismatch: theirs {md5}, ours {srv.stype.md5sum}")
            return
        reply = {
            "callerid": srv.caller_id,
            "md5sum": srv.stype.md5sum,
            "type": srv.stype.name.replace("/srv/", "/"),
            "request_type": srv.stype.request.replace("/msg/", "/"),
            "response_type": srv.stype.response.replace("/msg/", "/"),
        }
        sock.sendall(encode_header(reply))
        if header.get("probe") == "1":
            sock.close()
            return
        persistent = header.get("persistent") == "1"
        sock.settimeout(None if persistent else 60.0)
        while True:
            try:
                request = recv_frame(sock)
            except ConnectionError:
                sock.close()
                return
            try:
                response, ok = srv.handle(request), b"\x01"
            except Exception as exc:
                response, ok = str(exc).encode(), b"\x00"
            sock.sendall(ok + frame(response))
            if not persistent:
                sock.close()
                return


class Incoming:
    """navlab's subscription to one outside publisher: a reader thread handing each message to ``deliver``."""

    def __init__(
        self,
        publisher_api: str,
        topic: str,
        wtype: WireType,
        caller_id: str,
        deliver: Callable[[bytes], None],
        on_close: Callable[[Incoming], None],
    ) -> None:
        self.api, self.topic, self.wtype, self.caller_id = publisher_api, topic, wtype, caller_id
        self._deliver, self._on_close = deliver, on_close
        self.sock: socket.socket | None = None
        self.closed = False
        self.received = 0
        threading.Thread(target=self._run, name=f"ros1-in{topic}", daemon=True).start()

    def _run(self) -> None:
        try:
            proto = call(self.api, "requestTopic", self.caller_id, self.topic, [["TCPROS"]])
            if not proto or proto[0] != "TCPROS":
                raise Ros1Error(f"publisher {self.api} offers no TCPROS for {self.topic}")
            self.sock = socket.create_connection((proto[1], int(proto[2])), timeout=10.0)
            self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.sock.sendall(
                encode_header(
                    {
                        "callerid": self.caller_id,
                        "topic": self.topic,
                        "md5sum": self.wtype.md5sum,
                        "type": self.wtype.wire,
                        "message_definition": self.wtype.definition,
                        "tcp_nodelay": "1",
                    }
                )
            )
            header = recv_header(self.sock)
            if "error" in header:
                raise Ros1Error(header["error"])
            self.sock.settimeout(None)
            while not self.closed:
                payload = recv_frame(self.sock)
                self.received += 1
                self._deliver(payload)
        except (Ros1Error, OSError) as exc:
            if not self.closed:
                LOG.warning("ros1: dropped publisher %s of %s: %s", self.api, self.topic, exc)
        except Exception as exc:
            LOG.warning("ros1: dropped publisher %s of %s: garbage message (%s)", self.api, self.topic, exc)
        finally:
            self.close()

    def close(self) -> None:
        if self.sock is not None:
            with contextlib.suppress(OSError):
                self.sock.close()
        if not self.closed:
            self.closed = True
            self._on_close(self)


def service_call(
    uri: str, service: str, stype: ServiceType, caller_id: str, request: bytes, timeout: float = 10.0
) -> bytes:
    """Call an outside ROS 1 service at ``uri`` (``rosrpc://host:port``); the response bytes."""
    sock = socket.create_connection(host_port(uri), timeout=timeout)
    try:
        sock.sendall(encode_header({"callerid": caller_id, "service": service, "md5sum": stype.md5sum}))
        header = recv_header(sock)
        if "error" in header:
            raise Ros1Error(f"service {service}: {header['error']}")
        sock.sendall(frame(request))
        ok = sock.recv(1)
        payload = recv_frame(sock)
        if ok != b"\x01":
            raise Ros1Error(f"service {service} failed: {payload.decode(errors='replace')}")
        return payload
    finally:
        sock.close()
