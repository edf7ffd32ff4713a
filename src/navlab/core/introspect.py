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

Safety: the socket folder must be a directory of this user with mode 0700 (it is created so, and
refused if another user owns it or others may enter it); the socket file is 0600; a client checks
that the socket belongs to this user and that the process serving it is the launch its name says
(``SO_PEERCRED``), and the server answers only clients of its own user. Requests are lines of at
most ``MAX_LINE`` bytes; a malformed line, an unknown message type or a message of another type than
the topic's gets an error line back and the launch goes on; at most ``MAX_CONNECTIONS`` clients are
served at once. Sockets of launches that died are removed when a launch starts or a client looks.
"""

from __future__ import annotations

import base64
import contextlib
import functools
import json
import os
import queue
import socket
import stat
import struct
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from navlab.core.errors import CoreError
from navlab.core.executor import Executor
from navlab.core.graph import Graph
from navlab.msgs import TYPESTORE, type_name

MAX_LINE = 16 << 20  # bytes of one request or message line (a CDR map of 2000 x 2000 cells is 4 MB in base64)
MAX_CONNECTIONS = 16  # clients served at once


def socket_dir() -> Path:
    """Where running launches put their sockets (one per process)."""
    return Path(tempfile.gettempdir()) / f"navlab-{os.getuid()}"


def checked_socket_dir(*, create: bool) -> Path | None:
    """The socket folder after checking that only this user can use it (created 0700 when ``create``).

    Returns None when it does not exist (and ``create`` is false). Raises ``CoreError`` when it is not a
    directory, belongs to another user, or is open to others: a folder planted by another local user
    could hold a socket that impersonates a launch.
    """
    folder = socket_dir()
    if create:
        with contextlib.suppress(FileExistsError):
            folder.mkdir(mode=0o700)
    try:
        st = os.lstat(folder)
    except FileNotFoundError:
        return None
    if not stat.S_ISDIR(st.st_mode):
        raise CoreError(f"{folder}: not a directory; navlab keeps its launch sockets there (remove it)")
    if st.st_uid != os.getuid():
        raise CoreError(
            f"{folder}: belongs to user id {st.st_uid}, not to you ({os.getuid()}); refusing to use "
            "another user's socket folder (remove it, or set TMPDIR to a private folder)"
        )
    if st.st_mode & 0o077:
        raise CoreError(
            f"{folder}: mode {stat.S_IMODE(st.st_mode):04o}, expected 0700; refusing a socket folder "
            f"others can enter (chmod 700 {folder})"
        )
    return folder


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_sockets(folder: Path) -> list[Path]:
    """Remove the sockets of launches that are no longer running (``<pid>.sock`` of dead processes,
    nothing else); returns what was removed."""
    removed = []
    for path in sorted(folder.glob("*.sock")):
        if path.stem.isdigit() and not _alive(int(path.stem)):
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(path)
    return removed


def _peer(sock: socket.socket) -> tuple[int, int]:
    """(pid, uid) of the process at the other end of a Unix socket (Linux ``SO_PEERCRED``)."""
    pid, uid, _gid = struct.unpack("3i", sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i")))
    return pid, uid


class IntrospectionServer:
    """Serves introspection requests about ``executor`` on a Unix socket until :meth:`close`."""

    def __init__(self, executor: Executor, *, name: str = "") -> None:
        self.executor = executor
        self.name = name
        folder = checked_socket_dir(create=True)
        assert folder is not None
        remove_stale_sockets(folder)
        self.path = folder / f"{os.getpid()}.sock"
        with contextlib.suppress(FileNotFoundError):
            self.path.unlink()
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._sock.bind(str(self.path))
        os.chmod(self.path, 0o600)
        self._sock.listen(8)
        self._slots = threading.BoundedSemaphore(MAX_CONNECTIONS)
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
            refusal = None
            try:
                if _peer(conn)[1] != os.getuid():
                    refusal = "this launch answers only its own user"
            except OSError:
                refusal = "cannot tell who is connecting"
            if refusal is None and not self._slots.acquire(blocking=False):
                refusal = f"too many clients (at most {MAX_CONNECTIONS} at once); try again later"
            if refusal is not None:
                with contextlib.suppress(OSError), conn:
                    conn.sendall(json.dumps({"error": refusal}).encode() + b"\n")
                continue
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
        try:
            with contextlib.suppress(OSError):  # the client went away: nothing to answer
                self._serve_one(conn)
        finally:
            self._slots.release()

    @staticmethod
    def _line(f: Any) -> Any:
        """The next request line as JSON (a dict), or None at the end; raises ValueError when malformed."""
        raw = f.readline(MAX_LINE + 1)
        if not raw:
            return None
        if len(raw) > MAX_LINE:
            raise ValueError(f"line longer than {MAX_LINE} bytes")
        try:
            req = json.loads(raw)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"malformed request line (expected one JSON object): {exc}") from None
        if not isinstance(req, dict):
            raise ValueError(f"malformed request line: expected a JSON object, got {type(req).__name__}")
        return req

    @staticmethod
    def _reply(f: Any, reply: dict[str, Any]) -> None:
        with contextlib.suppress(OSError):
            f.write(json.dumps(reply).encode() + b"\n")
            f.flush()

    def _serve_one(self, conn: socket.socket) -> None:
        with conn, conn.makefile("rwb") as f:
            try:
                req = self._line(f) or {}
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
            self._reply(f, reply)

    def _answer(self, cmd: Any) -> dict[str, Any]:
        ex = self.executor
        if cmd == "info":
            return {"pid": os.getpid(), "name": self.name, "sim_time": ex.now_ns / 1e9}
        if cmd == "graph":
            types = {n: [type_name(t.msgtype), t.count] for n, t in ex.topics.items()}
            return {**Graph.from_executor(ex).to_json(), "types": types}
        return {"error": f"unknown request {cmd!r} (info, graph, subscribe)"}

    def _receive(self, f: Any) -> None:
        """Publish every message line the client sends, until it disconnects; a bad line gets an error line."""
        while True:
            try:
                line = self._line(f)
                if line is None:
                    return
                topic, msgtype, cdr = line.get("topic"), line.get("type"), line.get("cdr")
                if not (isinstance(topic, str) and topic and isinstance(msgtype, str) and isinstance(cdr, str)):
                    raise ValueError("a publish line needs 'topic', 'type' and 'cdr' (base64) strings")
                if msgtype not in TYPESTORE.types:
                    raise ValueError(f"unknown message type {msgtype!r}")
                try:
                    msg = TYPESTORE.deserialize_cdr(base64.b64decode(cdr, validate=True), msgtype)
                except Exception as exc:  # rosbags raises several kinds on bytes that are not this type
                    raise ValueError(f"cdr is not a serialised {msgtype} ({type(exc).__name__})") from None
                error = self._in_executor(functools.partial(self._publish, topic, msg))
                if error:
                    raise ValueError(error)
            except (CoreError, ValueError) as exc:
                self._reply(f, {"error": str(exc)})

    def _publish(self, topic: str, msg: Any) -> str | None:
        """Publish ``msg`` on ``topic`` (executor thread); the reason it cannot be, or None."""
        try:
            pub = self._publisher(topic, type(msg))
            if pub.topic.msgtype is not type(msg):
                return (
                    f"topic {topic!r} carries {type_name(pub.topic.msgtype)}, not {type_name(msg)}; "
                    "message not published"
                )
            pub.publish(msg)
        except CoreError as exc:
            return str(exc)
        return None

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
                line = {
                    "t": t_ns,
                    "type": type_name(msg),
                    "cdr": base64.b64encode(bytes(TYPESTORE.serialize_cdr(msg, type_name(msg)))).decode(),
                }
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
    folder = checked_socket_dir(create=False)
    live = []
    if folder is not None:
        remove_stale_sockets(folder)  # left behind by launches that were killed
        for path in sorted(folder.glob("*.sock")):
            st = os.lstat(path)
            if stat.S_ISSOCK(st.st_mode) and st.st_uid == os.getuid():
                live.append(path)
    pids = ", ".join(p.stem for p in live) or "none"
    if pid is not None:
        for path in live:
            if path.stem == str(pid):
                return path
        raise CoreError(f"no running navlab launch with pid {pid} (running: {pids})")
    if not live:
        raise CoreError(
            "no running navlab launch found; start one (navlab launch FILE) in another shell, "
            "or look at one here with --launch FILE or at a recording with --bag DIR"
        )
    if len(live) > 1:
        raise CoreError(f"several navlab launches are running (pids {pids}); choose one with --pid")
    return live[0]


def _connect(path: Path, request: dict[str, Any]) -> tuple[socket.socket, Any]:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(str(path))
        peer_pid, peer_uid = _peer(sock)
    except OSError as exc:
        sock.close()
        raise CoreError(f"cannot reach the launch at {path} ({exc.strerror})") from None
    if peer_uid != os.getuid() or (path.stem.isdigit() and peer_pid != int(path.stem)):
        sock.close()
        raise CoreError(
            f"{path} is served by process {peer_pid} of user id {peer_uid}, not by the launch "
            f"{path.stem} of yours; not trusted"
        )
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
