"""TCPROS framing (the ROS 1 transport): connection headers and length-prefixed messages.

A connection header is a 4-byte little-endian length followed by fields, each a 4-byte length and
``key=value``. Every message after it is a 4-byte length and the ROS 1 serialized bytes. A service
response starts with one ok byte (1 ok, 0 error: the payload is then the error text).
"""

from __future__ import annotations

import socket
import struct

from navlab.ros1.errors import Ros1Error

MAX_HEADER = 1 << 20  # bytes; a longer header is garbage
MAX_MESSAGE = 1 << 30  # bytes; ROS 1 has no hard limit, navlab drops a peer announcing more


def encode_header(fields: dict[str, str]) -> bytes:
    """A connection header: the fields as ``key=value`` entries, length-prefixed."""
    body = b"".join(struct.pack("<I", len(e)) + e for e in (f"{k}={v}".encode() for k, v in fields.items()))
    return struct.pack("<I", len(body)) + body


def decode_header(body: bytes) -> dict[str, str]:
    """The fields of a connection header body (without its leading length); ``Ros1Error`` on garbage."""
    out: dict[str, str] = {}
    i = 0
    while i < len(body):
        if i + 4 > len(body):
            raise Ros1Error("truncated connection header")
        (n,) = struct.unpack_from("<I", body, i)
        i += 4
        if i + n > len(body):
            raise Ros1Error("connection header field runs past its end")
        key, sep, value = body[i : i + n].decode("utf-8", "replace").partition("=")
        if not sep:
            raise Ros1Error(f"connection header field without '=': {key[:40]!r}")
        out[key] = value
        i += n
    return out


def recv_exact(sock: socket.socket, n: int) -> bytes:
    """Exactly ``n`` bytes from ``sock`` (``ConnectionError`` if the peer closes first)."""
    buf = bytearray()
    while len(buf) < n:
        chunk = sock.recv(min(n - len(buf), 1 << 20))
        if not chunk:
            raise ConnectionError("peer closed the connection")
        buf += chunk
    return bytes(buf)


def recv_frame(sock: socket.socket, limit: int = MAX_MESSAGE) -> bytes:
    """One length-prefixed frame (a header body or a message)."""
    (n,) = struct.unpack("<I", recv_exact(sock, 4))
    if n > limit:
        raise Ros1Error(f"a frame of {n} bytes announced (limit {limit})")
    return recv_exact(sock, n)


def recv_header(sock: socket.socket) -> dict[str, str]:
    """Read and decode a connection header."""
    return decode_header(recv_frame(sock, MAX_HEADER))


def frame(data: bytes) -> bytes:
    """``data`` with its 4-byte length in front."""
    return struct.pack("<I", len(data)) + data
