"""The page's inputs, checked before they reach the executor: one JSON object per WebSocket text message.

``{"op": "goal", "x": m, "y": m, "yaw": rad}`` (2D Nav Goal), ``{"op": "initialpose", ...}`` (2D Pose
Estimate), ``{"op": "cancel"}``, ``{"op": "key", "key": "i"}`` (teleop_twist_keyboard's keys),
``{"op": "spawn", "kind": "box"|"cylinder", "x", "y"[, "size" | "radius"]}``, ``{"op": "move", "name", "x",
"y"}``, ``{"op": "delete", "name"}``, ``{"op": "pause"}``, ``{"op": "resume"}``, ``{"op": "speed", "value": r}``
(0 = as fast as possible), and for replays ``{"op": "seek", "t": s}``. Positions are in the fixed frame
(or ``"frame"``). Anything else is refused with a message naming the key and what was expected.
"""

from __future__ import annotations

import math
import re
from typing import Any

from navlab.drivers import MOVE_BINDINGS, SPEED_BINDINGS

OPS = ("goal", "initialpose", "cancel", "key", "spawn", "move", "delete", "pause", "resume", "speed", "seek", "play")
_NAME = re.compile(r"^[A-Za-z0-9_]{1,64}$")
_FRAME = re.compile(r"^[A-Za-z0-9_/]{0,64}$")
MAX_COORD = 1e4  # m: farther than any world
OBSTACLE_HEIGHT = 0.5  # m


def _num(
    req: dict[str, Any], key: str, *, lo: float = -MAX_COORD, hi: float = MAX_COORD, default: float | None = None
) -> float:
    value = req.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"{req.get('op')}: {key!r} must be a finite number, got {value!r}")
    if not lo <= value <= hi:
        raise ValueError(f"{req.get('op')}: {key!r} must be in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


def check_input(req: Any) -> tuple[str, dict[str, Any]]:
    """(op, checked arguments) of a page input; raises ``ValueError`` naming what is wrong."""
    if not isinstance(req, dict):
        raise ValueError(f"expected a JSON object with an 'op', got {type(req).__name__}")
    op = req.get("op")
    if op not in OPS:
        raise ValueError(f"unknown op {op!r} (expected one of {', '.join(OPS)})")
    frame = req.get("frame", "")
    if not isinstance(frame, str) or not _FRAME.match(frame):
        raise ValueError(f"{op}: 'frame' must be a frame name, got {frame!r}")
    if op in ("goal", "initialpose"):
        return op, {"x": _num(req, "x"), "y": _num(req, "y"), "yaw": _num(req, "yaw", lo=-10, hi=10), "frame": frame}
    if op == "key":
        key = req.get("key")
        if not isinstance(key, str) or len(key) != 1:
            raise ValueError(f"key: 'key' must be one character, got {key!r}")
        return op, {"key": key, "known": key in MOVE_BINDINGS or key in SPEED_BINDINGS}
    if op == "spawn":
        kind = req.get("kind", "box")
        if kind == "box":
            dims = [_num(req, "size", lo=0.05, hi=5.0, default=0.4)] * 2 + [OBSTACLE_HEIGHT]
        elif kind == "cylinder":
            dims = [_num(req, "radius", lo=0.03, hi=2.5, default=0.2), OBSTACLE_HEIGHT]
        else:
            raise ValueError(f"spawn: 'kind' must be 'box' or 'cylinder', got {kind!r}")
        return op, {
            "kind": kind,
            "dims": dims,
            "x": _num(req, "x"),
            "y": _num(req, "y"),
            "yaw": _num(req, "yaw", lo=-10, hi=10, default=0.0),
        }
    if op in ("move", "delete"):
        name = req.get("name")
        if not isinstance(name, str) or not _NAME.match(name):
            raise ValueError(f"{op}: 'name' must be an obstacle name, got {name!r}")
        if op == "delete":
            return op, {"name": name}
        return op, {"name": name, "x": _num(req, "x"), "y": _num(req, "y")}
    if op == "speed":
        return op, {"value": _num(req, "value", lo=0.0, hi=100.0)}
    if op == "seek":
        return op, {"t": _num(req, "t", lo=0.0, hi=1e9)}
    return op, {}
