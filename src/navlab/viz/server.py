"""The viewer's web server: the static page over HTTP and the live streams over a WebSocket, on one port.

It runs an asyncio loop (``websockets``) in its own thread. HTTP requests get files from the static
folder only: a path that leaves it (``..``, encoded or not, backslashes, NUL) is refused with 403, one
that does not exist gets 404. A WebSocket handshake must come from a page of this server (its
``Origin`` names an allowed host and this port) or from a non-browser client (no ``Origin``). The
``Host`` header must name an allowed host too, so a DNS-rebinding page cannot read the streams.
Malformed messages get an error reply; a client that goes away mid-frame only ends its own connection.
"""

from __future__ import annotations

import asyncio
import contextlib
import http
import json
import logging
import mimetypes
import socket
import threading
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlsplit

from websockets.asyncio.server import ServerConnection, serve
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from navlab.viz.errors import VizError
from navlab.viz.frames import batch
from navlab.viz.hub import ClientStream, Hub

LOOPBACK = ("127.0.0.1", "localhost", "::1")
MAX_MESSAGE = 64 * 1024  # bytes: the largest input a page may send
SEND_HZ = 30.0  # how often each client's streams are checked for due frames
_TYPES = {
    ".js": "text/javascript",
    ".mjs": "text/javascript",
    ".css": "text/css",
    ".html": "text/html",
    ".svg": "image/svg+xml",
    ".png": "image/png",
    ".json": "application/json",
}
_log = logging.getLogger("navlab.viz.server")


def static_dir() -> Path:
    """The page's files shipped with the package."""
    return Path(str(resources.files("navlab.viz") / "static"))


def safe_static_path(root: Path, raw_path: str) -> Path | int:
    """The file under ``root`` that an HTTP request path names, or an HTTP status (403 outside, 404 missing)."""
    path = urlsplit(raw_path).path or "/"
    decoded = unquote(path)
    if "\\" in decoded or "\0" in decoded or not decoded.startswith("/") or decoded.startswith("//"):
        return 403
    parts = [p for p in decoded.split("/") if p]
    if any(p in ("..", ".") or ":" in p for p in parts):
        return 403
    rel = "/".join(parts) or "index.html"
    base = root.resolve()
    target = (base / rel).resolve()
    if not target.is_relative_to(base):
        return 403
    if target.is_dir():
        target = target / "index.html"
    return target if target.is_file() else 404


def _host_of(value: str) -> tuple[str, int | None]:
    """(host, port) of a Host header or an Origin's netloc; brackets of IPv6 literals removed."""
    split = urlsplit("//" + value)
    try:
        port = split.port
    except ValueError:
        port = -1
    return (split.hostname or "").lower(), port


class ViewerServer:
    """Serves ``hub`` to pages on ``host:port`` (port 0: any free port) until :meth:`close`."""

    def __init__(self, hub: Hub, *, host: str = "127.0.0.1", port: int = 8765, root: Path | None = None) -> None:
        self.hub = hub
        self.host = host
        self.port = port
        self.root = root or static_dir()
        self.allowed_hosts = {*LOOPBACK, host.lower().strip("[]")}
        if host in ("0.0.0.0", "::"):  # listening everywhere: the machine's own names are allowed too
            self.allowed_hosts |= {socket.gethostname().lower(), socket.getfqdn().lower()}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Future[None] | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self.connections = 0

    @property
    def url(self) -> str:
        """The page's address."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        if self.host in ("0.0.0.0", "::"):
            host = "127.0.0.1"
        return f"http://{host}:{self.port}/"

    def start(self) -> str:
        """Bind and serve in a background thread; returns the URL. Raises ``VizError`` if it cannot bind."""
        self._thread = threading.Thread(target=self._run, name="navlab-viewer", daemon=True)
        self._thread.start()
        self._ready.wait(10.0)
        if self._error is not None:
            raise VizError(f"cannot serve the viewer on {self.host}:{self.port} ({self._error})") from None
        return self.url

    def close(self) -> None:
        """Stop serving and wait for the thread."""
        loop, stop = self._loop, self._stop
        if loop is not None and stop is not None and not loop.is_closed():

            def finish() -> None:
                if not stop.done():
                    stop.set_result(None)

            with contextlib.suppress(RuntimeError):
                loop.call_soon_threadsafe(finish)
        if self._thread is not None:
            self._thread.join(5.0)

    def __enter__(self) -> ViewerServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the loop ---------------------------------------------------------------------------------

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        try:
            loop.run_until_complete(self._main())
        except BaseException as exc:
            self._error = exc
        finally:
            self._ready.set()
            loop.close()

    async def _main(self) -> None:
        self._stop = asyncio.get_running_loop().create_future()
        # permessage-deflate costs this process's CPU (and the page's) on every frame: only worth it off loopback
        compression = None if self.host in LOOPBACK else "deflate"
        # close_timeout: on close, a page that does not answer the closing handshake is dropped after 1 s (the
        # default 10 s outlasts close()'s 5 s join)
        async with serve(
            self._client,
            self.host,
            self.port,
            process_request=self._http,
            max_size=MAX_MESSAGE,
            ping_interval=20,
            ping_timeout=20,
            close_timeout=1.0,
            logger=_log,
            compression=compression,
        ) as server:
            sock = next(iter(server.sockets))
            self.port = int(sock.getsockname()[1])
            self._ready.set()
            await self._stop

    # --- HTTP --------------------------------------------------------------------------------------

    def _http(self, connection: ServerConnection, request: Request) -> Response | None:
        host, _ = _host_of(request.headers.get("Host", ""))
        if host not in self.allowed_hosts:
            return _response(http.HTTPStatus.FORBIDDEN, b"unknown Host\n")
        if request.headers.get("Upgrade", "").lower() == "websocket":
            origin = request.headers.get("Origin")
            if origin is not None and not self._origin_ok(origin):
                return _response(http.HTTPStatus.FORBIDDEN, b"WebSocket connections from other origins are refused\n")
            return None
        found = safe_static_path(self.root, request.path)
        if isinstance(found, int):
            status = http.HTTPStatus(found)
            return _response(status, f"{found} {status.phrase}\n".encode())
        ctype = _TYPES.get(found.suffix) or mimetypes.guess_type(found.name)[0] or "application/octet-stream"
        return _response(http.HTTPStatus.OK, found.read_bytes(), ctype)

    def _origin_ok(self, origin: str) -> bool:
        split = urlsplit(origin)
        if split.scheme not in ("http", "https"):
            return False
        host, port = _host_of(split.netloc)
        return host in self.allowed_hosts and port == self.port

    # --- WebSocket ---------------------------------------------------------------------------------

    async def _client(self, ws: ServerConnection) -> None:
        self.connections += 1
        stream = ClientStream(self.hub)
        sender = asyncio.create_task(self._send_loop(ws, stream))
        try:
            async for message in ws:
                reply = self._on_message(message)
                if reply is not None:
                    await ws.send(json.dumps(reply))
        except ConnectionClosed:
            pass
        finally:
            sender.cancel()
            with contextlib.suppress(asyncio.CancelledError, ConnectionClosed):
                await sender

    def _on_message(self, message: str | bytes) -> dict[str, Any] | None:
        if isinstance(message, bytes):
            return {"k": "error", "error": "inputs are JSON text messages"}
        try:
            req = json.loads(message)
        except (json.JSONDecodeError, RecursionError):
            return {"k": "error", "error": "not valid JSON"}
        op = req.get("op") if isinstance(req, dict) else None
        try:
            error = self.hub.handle(req)
        except Exception as exc:
            _log.warning("input %r failed: %s", op, exc)
            error = f"{op}: {exc}"
        return {"k": "ack", "op": op if isinstance(op, str) else None, "error": error}

    async def _send_loop(self, ws: ServerConnection, stream: ClientStream) -> None:
        """Every 1/SEND_HZ wall-clock s: encode what is due and send it as one message (a batch), unless the
        page has not taken the previous one yet (bytes still in the socket's buffer): then nothing is encoded
        this time, and the page gets the newest of everything once it has."""
        period = 1.0 / SEND_HZ
        transport = ws.transport
        hub = self.hub
        while True:
            if transport is None or transport.get_write_buffer_size() == 0:
                frames = stream.frames()
                if frames:
                    message = batch(frames)
                    await ws.send(message)  # waits while the socket is full: the stream skips, never queues
                    hub.bytes_sent += len(message)
                hub.frames_sent += 1
            await asyncio.sleep(period)


def _response(status: http.HTTPStatus, body: bytes, ctype: str = "text/plain; charset=utf-8") -> Response:
    headers = Headers(
        {
            "Content-Type": ctype,
            "Content-Length": str(len(body)),
            "Cache-Control": "no-store",
            "X-Content-Type-Options": "nosniff",
            "Referrer-Policy": "no-referrer",
            "Content-Security-Policy": "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; "
            "style-src 'self' 'unsafe-inline'",
        }
    )
    return Response(status.value, status.phrase, headers, body)
