"""The viewer's server: static files only from its folder, loopback by default, same-origin WebSockets,
and it survives malformed messages and clients that vanish mid-frame."""

from __future__ import annotations

import base64
import http.client
import json
import os
import socket
import struct
from collections.abc import Iterator

import pytest
from viz_helpers import headers, next_state
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from navlab.viz import Hub
from navlab.viz.server import ViewerServer, safe_static_path, static_dir
from navlab.viz.viewer import host_warning


@pytest.fixture
def server() -> Iterator[ViewerServer]:
    hub = Hub()
    hub.set_state({"t": 1.5, "tf": {}})
    received: list[dict[str, object]] = []
    hub.handler = lambda req: received.append(req) or None  # type: ignore[func-returns-value]
    with ViewerServer(hub, port=0) as srv:
        srv.received = received  # type: ignore[attr-defined]
        yield srv


def _get(srv: ViewerServer, path: str, host: str | None = None) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=5)
    conn.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
    conn.putheader("Host", host or f"127.0.0.1:{srv.port}")
    conn.endheaders()
    resp = conn.getresponse()
    body = resp.read()
    conn.close()
    return resp.status, body


def _ws(srv: ViewerServer, origin: str | None = None) -> object:
    headers = {"Origin": origin} if origin else None
    return connect(f"ws://127.0.0.1:{srv.port}/ws", additional_headers=headers, open_timeout=5)


def test_serves_the_page_and_refuses_paths_outside_its_folder(server: ViewerServer) -> None:
    status, body = _get(server, "/")
    assert status == 200 and b"navlab viewer" in body
    assert _get(server, "/app.js")[0] == 200
    assert _get(server, "/missing.js")[0] == 404
    secret = "/etc/passwd"
    for path in [
        "/../../../../etc/passwd",
        "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "/..%2f..%2f..%2fetc%2fpasswd",
        "/%2E%2E%5C%2E%2E%5Cetc%5Cpasswd",
        "/..\\..\\etc\\passwd",
        "//etc/passwd",
        "/%2fetc%2fpasswd",
        "/static/../../pyproject.toml",
        "/./app.js",
        "/app.js%00.png",
        "http://127.0.0.1/../../etc/passwd",
        secret,
    ]:
        status, body = _get(server, path)
        assert status in (400, 403, 404), path
        assert b"root:" not in body and b"[project]" not in body, path


def test_static_paths_resolve_inside_the_folder_only() -> None:
    root = static_dir()
    assert (root.parent / "viewer.py").is_file()  # there is something to steal next door
    assert safe_static_path(root, "/index.html") == (root / "index.html").resolve()
    for path in ["/%2e%2e/viewer.py", "/../viewer.py", "/..%5Cviewer.py", "/x/../../viewer.py"]:
        assert safe_static_path(root, path) == 403, path


def test_binds_loopback_by_default_and_warns_otherwise(server: ViewerServer) -> None:
    assert server.host == "127.0.0.1" and server.url.startswith("http://127.0.0.1:")
    addresses = {ip for *_, (ip, *_rest) in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)}
    for ip in addresses - {"127.0.0.1"}:  # the machine's other addresses do not reach the viewer
        with pytest.raises(OSError):
            socket.create_connection((ip, server.port), timeout=1).close()
    assert host_warning("127.0.0.1") is None and "anyone" in str(host_warning("0.0.0.0"))


def test_websocket_from_another_origin_or_host_is_refused(server: ViewerServer) -> None:
    for origin in [
        "http://evil.example",
        f"http://evil.example:{server.port}",
        f"http://127.0.0.1:{server.port + 1}",
        "null",
        f"file://127.0.0.1:{server.port}",
    ]:
        with pytest.raises(InvalidStatus) as info:
            _ws(server, origin)
        assert info.value.response.status_code == 403, origin
    assert _get(server, "/", host=f"rebind.example:{server.port}")[0] == 403  # DNS rebinding
    for origin in [f"http://127.0.0.1:{server.port}", f"http://localhost:{server.port}", None]:
        with _ws(server, origin) as ws:
            assert next_state(ws)["t"] == 1.5


def test_survives_malformed_messages_and_mid_frame_disconnects(server: ViewerServer) -> None:
    with _ws(server) as ws:
        for bad in ["not json", "[1, 2]", '{"op": "goal", "x": Infinity, "y": 0, "yaw": 0}', "{" * 5000, b"\x00\x01"]:
            ws.send(bad)
    with pytest.raises(ConnectionClosed), _ws(server) as ws:  # larger than any input: this connection only closes
        ws.send("x" * 200_000)
        while True:
            ws.recv(timeout=5)
    # a raw client: handshake, then half a frame announcing 4000 bytes, then gone
    sock = socket.create_connection(("127.0.0.1", server.port), timeout=5)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(
        (
            f"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n"
        ).encode()
    )
    assert b"101" in sock.recv(4096).split(b"\r\n")[0]
    sock.sendall(bytes([0x81, 0x80 | 126]) + struct.pack(">H", 4000) + os.urandom(4) + b'{"op": "go')
    sock.close()
    with _ws(server) as ws:  # the server still answers
        ws.send(json.dumps({"op": "cancel"}))
        kinds = set()
        for _ in range(5):
            for msg in headers(ws):
                kinds.add(msg["k"])
                if msg["k"] == "ack":
                    assert msg["error"] is None
            if "ack" in kinds:
                break
        assert "ack" in kinds
    assert {"op": "cancel"} in server.received  # type: ignore[attr-defined]


def test_a_port_in_use_is_a_clear_error(server: ViewerServer) -> None:
    from navlab.viz import VizError

    with pytest.raises(VizError, match=f"cannot serve the viewer on 127.0.0.1:{server.port}"):
        ViewerServer(Hub(), port=server.port).start()
