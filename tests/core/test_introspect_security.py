"""The launch socket (issue 14): a private folder, error replies to bad clients, stale sockets removed."""

from __future__ import annotations

import base64
import json
import os
import socket
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from navlab.core import CoreError, introspect
from navlab.core.introspect import IntrospectionServer, RemotePublisher, find_running
from navlab.core.launch import start
from navlab.msgs import TYPESTORE


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "navlab-sockets"
    monkeypatch.setattr(introspect, "socket_dir", lambda: path)
    return path


def test_a_planted_or_open_socket_folder_is_refused(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    ex = start("talker_listener").executor
    folder.mkdir(mode=0o777)
    os.chmod(folder, 0o777)  # another user could put a socket here
    with pytest.raises(CoreError, match=r"mode 0777, expected 0700"):
        IntrospectionServer(ex)
    with pytest.raises(CoreError, match=r"mode 0777, expected 0700"):
        find_running()
    os.chmod(folder, 0o700)
    real_uid = os.getuid()
    monkeypatch.setattr(introspect.os, "getuid", lambda: real_uid + 4242)  # the folder now belongs to "another"
    with pytest.raises(CoreError, match=r"belongs to user id \d+, not to you"):
        IntrospectionServer(ex)
    with pytest.raises(CoreError, match=r"belongs to user id"):
        find_running()


def test_a_socket_served_by_another_process_is_not_trusted(folder: Path) -> None:
    folder.mkdir(mode=0o700)
    fake = folder / f"{os.getppid()}.sock"  # named after a live process, served by this one
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(str(fake))
    server.listen(1)
    try:
        with pytest.raises(CoreError, match=r"is served by process \d+ .* not trusted"):
            introspect.request(find_running(os.getppid()), "info")
    finally:
        server.close()


@pytest.fixture
def running(folder: Path) -> Iterator[tuple[Any, IntrospectionServer]]:
    session = start("talker_listener", rate=1.0, launch_args={"rate": 50.0})
    ex = session.executor
    thread = threading.Thread(target=ex.run, args=(60.0,), daemon=True)
    thread.start()
    server = IntrospectionServer(ex, name="t")
    try:
        yield ex, server
    finally:
        server.close()
        ex.post(ex.stop)
        thread.join(10)


def _send(path: Path, lines: list[bytes]) -> list[dict[str, Any]]:
    """Send raw lines on one connection, then read the replies until the server closes or goes quiet."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.connect(str(path))
    sock.settimeout(3.0)
    replies = []
    with sock, sock.makefile("rwb") as f:
        for line in lines:
            f.write(line + b"\n")
        f.flush()
        try:
            for raw in f:
                replies.append(json.loads(raw))
                if len(replies) >= len(lines) - 1:
                    break
        except TimeoutError:
            pass
    return replies


def test_bad_clients_get_error_replies_and_the_launch_goes_on(running: tuple[Any, IntrospectionServer]) -> None:
    ex, server = running
    assert _send(server.path, [b"[1, 2]"])[0]["error"].startswith("malformed request line")
    assert "error" in _send(server.path, [b"\xff\xfe not json"])[0]
    twist = TYPESTORE.types["geometry_msgs/msg/Twist"]
    vec = TYPESTORE.types["geometry_msgs/msg/Vector3"]
    cdr = base64.b64encode(
        bytes(TYPESTORE.serialize_cdr(twist(vec(1.0, 0.0, 0.0), vec(0.0, 0.0, 0.0)), "geometry_msgs/msg/Twist"))
    ).decode()
    replies = _send(
        server.path,
        [
            b'{"cmd": "publish"}',
            json.dumps({"topic": "/chatter", "type": "geometry_msgs/msg/Twist", "cdr": cdr}).encode(),  # wrong type
            b"not json at all",
            json.dumps({"topic": "/x", "type": "no_pkg/msg/Nope", "cdr": cdr}).encode(),
            json.dumps({"topic": "/x", "type": "std_msgs/msg/String", "cdr": "!!!"}).encode(),
        ],
    )
    errors = [r["error"] for r in replies]
    assert any("'/chatter' has type std_msgs/msg/String, but geometry_msgs/msg/Twist" in e for e in errors)
    assert any("malformed request line" in e for e in errors)
    assert any("unknown message type 'no_pkg/msg/Nope'" in e for e in errors)
    assert any("cdr is not a serialised std_msgs/msg/String" in e for e in errors)
    before = ex.now_ns
    pub = RemotePublisher(server.path)  # a good client still works and the simulation still runs
    pub.publish("/cmd_vel", twist(vec(0.1, 0.0, 0.0), vec(0.0, 0.0, 0.0)))
    pub.close()
    assert introspect.request(server.path, "info")["sim_time"] * 1e9 >= before
    assert "/chatter" in introspect.request(server.path, "graph")["types"]


def test_over_long_lines_and_too_many_clients_are_refused(
    running: tuple[Any, IntrospectionServer], monkeypatch: pytest.MonkeyPatch
) -> None:
    _ex, server = running
    monkeypatch.setattr(introspect, "MAX_LINE", 1000)
    assert "longer than 1000 bytes" in _send(server.path, [b'{"cmd": "' + b"x" * 2000 + b'"}'])[0]["error"]
    held = []
    for _ in range(introspect.MAX_CONNECTIONS):  # subscribers hold their connection open
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(str(server.path))
        s.sendall(b'{"cmd": "subscribe", "topic": "/chatter"}\n')
        held.append(s)
    try:
        with pytest.raises(CoreError, match=r"too many clients"):
            introspect.request(server.path, "info")
    finally:
        for s in held:
            s.close()


def test_sockets_of_dead_launches_are_removed(folder: Path) -> None:
    folder.mkdir(mode=0o700)
    stale = folder / "999999999.sock"  # no such process
    stale.touch()
    with pytest.raises(CoreError, match="no running navlab launch found"):
        find_running()
    assert not stale.exists()
