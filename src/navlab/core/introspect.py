"""Looking into a running launch from another process (``navlab topic echo /odom`` in a second shell).

A running ``navlab launch`` serves a Unix socket in ``$TMPDIR/navlab-$UID/PID.sock``. A client sends one
JSON request line and reads JSON lines back:

- ``{"cmd": "info"}`` → ``{"pid", "name", "sim_time"}``
- ``{"cmd": "graph"}`` → the node/topic graph with message types and counts
- ``{"cmd": "subscribe", "topic": "/odom"}`` → one line per message: ``{"t": ns, "type": ..., "cdr": base64}``
  (messages are CDR-serialised as in a rosbag2, and deserialised by the client)
- ``{"cmd": "publish"}`` then one line per message ``{"topic", "type", "cdr"}``: published in the launch
  by a node named ``/navlab_remote`` (teleop from another shell)

Everything that touches the executor runs in the executor's thread (through its inbox), so the
server never races the simulation.
"""

from __future__ import annotations

import base64
import contextlib
import functools
import json
import os
import queue
import socket
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from navlab.core.errors import CoreError
from navlab.core.executor import Executor
from navlab.core.graph import Graph
from navlab.msgs import TYPESTORE, type_name


def socket_dir() -> Path:
    """Where running launches put their sockets (one per process)."""
    return Path(tempfile.gettempdir()) / f"navlab-{os.getuid()}"


class IntrospectionServer:
    """Serves introspection requests about ``executor`` on a Unix socket until :meth:`close`."""

    def __init__(self, executor: Executor, *, name: str = "") -> None:
        self.executor = executor
        self.name = name
        socket_dir().mkdir(mode=0o700, exist_ok=True)
        self.path = socket_dir() / f"{os.getpid()}.sock"
        with contextlib.suppress(FileNotFoundError):
            self.path.unlink()
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._sock.bind(str(self.path))
        self._sock.listen(8)
        self._closed = threading.Event()
        self._remote: Any = None
        threading.Thread(target=self._accept, name="navlab-introspection", daemon=True).start()

    def close(self) -> None:
        """Stop serving and remove the socket file."""
        self._closed.set()
        self._sock.close()
        with contextlib.suppress(FileNotFoundError):
            self.path.unlink()

    def __enter__(self) -> IntrospectionServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- serving --------------------------------------------------------------------------------

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                conn, _ = self._sock.accept()
            except OSError:
                return
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _in_executor(self, fn: Callable[[], Any], timeout: float = 5.0) -> Any:
        """Run ``fn()`` in the executor's thread and return its result."""
        done = threading.Event()
        box: list[Any] = []

        def run() -> None:
            box.append(fn())
            done.set()

        self.executor.post(run)
        if not done.wait(timeout):
            raise CoreError("the launch did not answer (is it paused or finished?)")
        return box[0]

    def _serve(self, conn: socket.socket) -> None:
        with contextlib.suppress(OSError):  # the client went away: nothing to answer
            self._serve_one(conn)

    def _serve_one(self, conn: socket.socket) -> None:
        with conn, conn.makefile("rwb") as f:
            try:
                req = json.loads(f.readline() or b"{}")
                cmd = req.get("cmd")
                if cmd == "subscribe":
                    self._stream(f, str(req.get("topic", "")))
                    return
                if cmd == "publish":
                    self._receive(f)
                    return
                reply = self._in_executor(lambda: self._answer(cmd))
            except (CoreError, ValueError) as exc:
                reply = {"error": str(exc)}
            except OSError:
                return
            with contextlib.suppress(OSError):
                f.write(json.dumps(reply).encode() + b"\n")
                f.flush()

    def _answer(self, cmd: Any) -> dict[str, Any]:
        ex = self.executor
        if cmd == "info":
            return {"pid": os.getpid(), "name": self.name, "sim_time": ex.now_ns / 1e9}
        if cmd == "graph":
            types = {n: [type_name(t.msgtype), t.count] for n, t in ex.topics.items()}
            return {**Graph.from_executor(ex).to_json(), "types": types}
        return {"error": f"unknown request {cmd!r} (info, graph, subscribe)"}

    def _receive(self, f: Any) -> None:
        """Publish every message line the client sends, until it disconnects."""
        for raw in f:
            line = json.loads(raw)
            msg = TYPESTORE.deserialize_cdr(base64.b64decode(line["cdr"]), line["type"])
            self.executor.post(functools.partial(self._publish, str(line["topic"]), msg))

    def _publish(self, topic: str, msg: Any) -> None:
        self._publisher(topic, type(msg)).publish(msg)

    def _publisher(self, topic: str, msgtype: type) -> Any:
        """The remote node's publisher on ``topic`` (made on first use, in the executor's thread)."""
        from navlab.core.node import Node

        if self._remote is None:
            self._remote = Node(self.executor, name="navlab_remote")
        for pub in self._remote.publishers:
            if pub.topic_name == topic:
                return pub
        return self._remote.create_publisher(msgtype, topic, 10)

    def _stream(self, f: Any, topic: str) -> None:
        q: queue.Queue[bytes] = queue.Queue(maxsize=1000)

        def listen(name: str, msg: Any, t_ns: int) -> None:
            if name == topic:
                line = {"t": t_ns, "type": type_name(msg), "cdr": base64.b64encode(
                    bytes(TYPESTORE.serialize_cdr(msg, type_name(msg)))).decode()}
                with contextlib.suppress(queue.Full):  # a slow reader drops messages, never stalls the sim
                    q.put_nowait(json.dumps(line).encode() + b"\n")

        def attach() -> bool:
            if topic not in self.executor.topics:
                return False
            for msg in self.executor.topics[topic].latched.values():
                listen(topic, msg, self.executor.now_ns)
            self.executor.add_listener(listen)
            return True

        if not self._in_executor(attach):
            known = self._in_executor(lambda: sorted(self.executor.topics))
            f.write(json.dumps({"error": f"no topic {topic!r} (topics: {', '.join(known)})"}).encode() + b"\n")
            f.flush()
            return
        try:
            while not self._closed.is_set():
                try:
                    line = q.get(timeout=0.5)
                except queue.Empty:
                    continue
                f.write(line)
                f.flush()
        except OSError:
            pass
        finally:
            self.executor.post(lambda: self.executor.remove_listener(listen))


# --- client --------------------------------------------------------------------------------------


def find_running(pid: int | None = None) -> Path:
    """The socket of the running launch (the only one, or the one with ``pid``)."""
    live = []
    for path in sorted(socket_dir().glob("*.sock")) if socket_dir().is_dir() else []:
        try:
            os.kill(int(path.stem), 0)
            live.append(path)
        except (ProcessLookupError, ValueError):
            with contextlib.suppress(OSError):
                path.unlink()  # left behind by a launch that was killed
        except PermissionError:
            live.append(path)
    pids = ", ".join(p.stem for p in live) or "none"
    if pid is not None:
        for path in live:
            if path.stem == str(pid):
                return path
        raise CoreError(f"no running navlab launch with pid {pid} (running: {pids})")
    if not live:
        raise CoreError("no running navlab launch found; start one (navlab launch FILE) in another shell, "
                        "or look at one here with --launch FILE or at a recording with --bag DIR")  # fmt: skip
    if len(live) > 1:
        raise CoreError(f"several navlab launches are running (pids {pids}); choose one with --pid")
    return live[0]


def _connect(path: Path, request: dict[str, Any]) -> tuple[socket.socket, Any]:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(str(path))
    except OSError as exc:
        sock.close()
        raise CoreError(f"cannot reach the launch at {path} ({exc.strerror})") from None
    f = sock.makefile("rwb")
    f.write(json.dumps(request).encode() + b"\n")
    f.flush()
    return sock, f


def request(path: Path, cmd: str, timeout: float = 10.0) -> dict[str, Any]:
    """Send one request and return its JSON answer."""
    sock, f = _connect(path, {"cmd": cmd})
    sock.settimeout(timeout)
    with sock, f:
        reply = json.loads(f.readline() or b"{}")
    if "error" in reply:
        raise CoreError(reply["error"])
    return reply


class RemotePublisher:
    """Publishes messages into a running launch (one connection, many messages)."""

    def __init__(self, path: Path) -> None:
        self._sock, self._f = _connect(path, {"cmd": "publish"})

    def publish(self, topic: str, msg: Any) -> None:
        """Send ``msg`` to be published on ``topic`` in the launch."""
        cdr = base64.b64encode(bytes(TYPESTORE.serialize_cdr(msg, type_name(msg)))).decode()
        self._f.write(json.dumps({"topic": topic, "type": type_name(msg), "cdr": cdr}).encode() + b"\n")
        self._f.flush()

    def close(self) -> None:
        """Disconnect."""
        with contextlib.suppress(OSError):
            self._f.close()
            self._sock.close()


def subscribe(path: Path, topic: str) -> Iterator[tuple[int, Any]]:
    """Yield ``(t_ns, msg)`` for each message the running launch publishes on ``topic``."""
    sock, f = _connect(path, {"cmd": "subscribe", "topic": topic})
    with sock, f:
        for raw in f:
            line = json.loads(raw)
            if "error" in line:
                raise CoreError(line["error"])
            yield int(line["t"]), TYPESTORE.deserialize_cdr(base64.b64decode(line["cdr"]), line["type"])
