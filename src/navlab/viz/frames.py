"""The viewer's wire format: binary frames for grids, scans, paths and pose sets; pure functions, no I/O.

A binary frame is ``[u32 n][n bytes of JSON header][padding to 4 bytes][payload]`` (little endian). The
header names the kind (``grid``, ``tiles``, ``scan``, ``path``, ``poses``), the topic and the frame the data
is in; the payload is raw: ``uint8`` cells for grids (an ``int8`` OccupancyGrid value -1 is sent as 255),
``float32`` ranges for scans, ``float32`` x,y pairs for paths and x,y,yaw triples for pose sets. A JSON
message (the state, the graph) travels as a frame that is all header.

Everything due for a page at one moment goes as one WebSocket message, a *batch*: ``[u32 m][m bytes: a
frame][padding to 4 bytes]`` repeated (:func:`batch`, :func:`unbatch`). Every frame starts at a multiple of
4 bytes, so the page reads the ``float32`` payloads in place.

Costmaps change little from one publication to the next: :class:`GridDiffer` sends only the changed
square tiles (``tiles``) while the grid's size, resolution and origin stay, and a whole ``grid`` otherwise.
"""

from __future__ import annotations

import json
import struct
from typing import Any

import numpy as np

TILE = 32  # cells on a tile's side
_PAD = b"\0\0\0"


def pack(header: dict[str, Any], payload: bytes | memoryview = b"") -> bytes:
    """A binary frame: a JSON header, padded so the payload starts at a multiple of 4 bytes."""
    head = json.dumps(header, separators=(",", ":")).encode()
    pad = (-(4 + len(head))) % 4
    return b"".join((struct.pack("<I", len(head)), head, _PAD[:pad], payload))


def batch(frames: list[bytes | str]) -> bytes:
    """One WebSocket message carrying ``frames`` (binary frames, or JSON texts sent as header-only frames)."""
    parts: list[bytes] = []
    for f in frames:
        if isinstance(f, str):
            text = f.encode()
            f = b"".join((struct.pack("<I", len(text)), text))
        parts += (struct.pack("<I", len(f)), f, _PAD[: (-len(f)) % 4])
    return b"".join(parts)


def unbatch(message: bytes) -> list[bytes]:
    """The frames of a :func:`batch` (tests and the Python clients)."""
    out, off = [], 0
    while off + 4 <= len(message):
        (m,) = struct.unpack_from("<I", message, off)
        out.append(message[off + 4 : off + 4 + m])
        off += 4 + m + (-m) % 4
    return out


def unpack(frame: bytes) -> tuple[dict[str, Any], bytes]:
    """Inverse of :func:`pack` (tests and the Python clients)."""
    (n,) = struct.unpack_from("<I", frame)
    header = json.loads(frame[4 : 4 + n])
    start = 4 + n + (-(4 + n)) % 4
    return header, frame[start:]


def grid_geometry(msg: Any) -> dict[str, Any]:
    """Size, resolution (m/cell), origin (x, y, yaw in its frame) and frame of an ``OccupancyGrid``."""
    info = msg.info
    o = info.origin
    qz, qw = float(o.orientation.z), float(o.orientation.w)
    return {
        "w": int(info.width),
        "h": int(info.height),
        "res": float(info.resolution),
        "ox": float(o.position.x),
        "oy": float(o.position.y),
        "oyaw": 2.0 * float(np.arctan2(qz, qw)),
        "frame": str(msg.header.frame_id).lstrip("/"),
    }


def grid_cells(msg: Any) -> np.ndarray:
    """The grid's cells as a (h, w) ``uint8`` array (row 0 at the origin; -1 becomes 255), no copy."""
    info = msg.info
    data = np.asarray(msg.data)
    return data.view(np.uint8).reshape(int(info.height), int(info.width))


def grid_frame(topic: str, msg: Any) -> bytes:
    """A whole grid as one binary frame."""
    geo = grid_geometry(msg)
    cells = grid_cells(msg)
    return pack({"k": "grid", "topic": topic, **geo}, np.ascontiguousarray(cells).tobytes())


class GridDiffer:
    """Sends a grid topic as changed tiles while its geometry holds, a whole frame when it changes."""

    def __init__(self, tile: int = TILE, *, max_fraction: float = 0.5) -> None:
        self.tile = tile
        self.max_fraction = max_fraction
        self._geo: dict[str, Any] | None = None
        self._cells: np.ndarray | None = None

    def reset(self) -> None:
        """Forget what was sent (the next frame is whole)."""
        self._geo = self._cells = None

    def frame(self, topic: str, msg: Any) -> bytes | None:
        """The frame that brings the receiver up to ``msg``: None if nothing changed."""
        geo = grid_geometry(msg)
        cells = grid_cells(msg)
        if self._geo != geo or self._cells is None:
            self._geo, self._cells = geo, cells.copy()
            return grid_frame(topic, msg)
        changed = changed_tiles(self._cells, cells, self.tile)
        if not changed.any():
            return None
        ty, tx = np.nonzero(changed)
        if len(ty) > self.max_fraction * changed.size:
            self._cells = cells.copy()
            return grid_frame(topic, msg)
        t = self.tile
        h, w = cells.shape
        tiles, parts = [], []
        for y0, x0 in zip((ty * t).tolist(), (tx * t).tolist(), strict=True):
            y1, x1 = min(y0 + t, h), min(x0 + t, w)
            tiles.append([x0, y0, x1 - x0, y1 - y0])
            parts.append(np.ascontiguousarray(cells[y0:y1, x0:x1]).tobytes())
            self._cells[y0:y1, x0:x1] = cells[y0:y1, x0:x1]
        return pack({"k": "tiles", "topic": topic, **geo, "tiles": tiles}, b"".join(parts))


def changed_tiles(old: np.ndarray, new: np.ndarray, tile: int) -> np.ndarray:
    """(ceil(h/tile), ceil(w/tile)) booleans: which tiles of two same-shaped grids differ."""
    h, w = new.shape
    diff = old != new
    ph, pw = (-h) % tile, (-w) % tile
    if ph or pw:
        diff = np.pad(diff, ((0, ph), (0, pw)))
    th, tw = diff.shape[0] // tile, diff.shape[1] // tile
    return diff.reshape(th, tile, tw, tile).any(axis=(1, 3))


def scan_frame(
    topic: str, msg: Any, *, frame: str | None = None, pose: list[float] | None = None, fixed: str = ""
) -> bytes:
    """A ``LaserScan``'s ranges as ``float32`` with its angles and range limits (and, if known, the sensor's
    ``pose`` x, y, yaw in the ``fixed`` frame at the scan's stamp)."""
    ranges = np.asarray(msg.ranges, dtype=np.float32)
    header = {
        "k": "scan",
        "topic": topic,
        "frame": frame or str(msg.header.frame_id).lstrip("/"),
        "a0": float(msg.angle_min),
        "da": float(msg.angle_increment),
        "rmin": float(msg.range_min),
        "rmax": float(msg.range_max),
        "n": len(ranges),
        "pose": pose,
        "fixed": fixed,
    }
    return pack(header, ranges.tobytes())


def path_frame(topic: str, frame: str, xy: np.ndarray, *, kind: str = "path") -> bytes:
    """Points (N, 2) in ``frame`` as ``float32`` pairs (a plan, a trace, a footprint)."""
    pts = np.ascontiguousarray(np.asarray(xy, dtype=np.float32).reshape(-1, 2))
    return pack({"k": kind, "topic": topic, "frame": frame, "n": len(pts)}, pts.tobytes())


def poses_frame(topic: str, frame: str, poses: np.ndarray) -> bytes:
    """Poses (N, 3) x, y, yaw in ``frame`` as ``float32`` triples (a particle cloud)."""
    p = np.ascontiguousarray(np.asarray(poses, dtype=np.float32).reshape(-1, 3))
    return pack({"k": "poses", "topic": topic, "frame": frame, "n": len(p)}, p.tobytes())


def path_xy(msg: Any) -> np.ndarray:
    """(N, 2) positions of a ``nav_msgs/Path``."""
    poses = msg.poses
    out = np.empty((len(poses), 2), dtype=np.float32)
    for i, ps in enumerate(poses):
        p = ps.pose.position
        out[i, 0], out[i, 1] = p.x, p.y
    return out


def pose_array_xyyaw(msg: Any) -> np.ndarray:
    """(N, 3) x, y, yaw of a ``geometry_msgs/PoseArray`` (yaw of a planar quaternion)."""
    poses = msg.poses
    out = np.empty((len(poses), 4), dtype=np.float64)
    for i, p in enumerate(poses):
        q = p.orientation
        out[i] = (p.position.x, p.position.y, q.z, q.w)
    yaw = 2.0 * np.arctan2(out[:, 2], out[:, 3])
    return np.column_stack([out[:, 0], out[:, 1], yaw])


def polygon_xy(msg: Any) -> np.ndarray:
    """(N, 2) corners of a ``geometry_msgs/PolygonStamped``."""
    return np.array([(p.x, p.y) for p in msg.polygon.points], dtype=np.float32).reshape(-1, 2)
