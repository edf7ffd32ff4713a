"""What the page shows, handed from the producer (the live viewer node or a replay) to the server's clients.

The producer's thread only stores references: the newest message of each topic with a sequence number,
the odometry traces and a small JSON state. Each connected client has a :class:`ClientStream` that, in
the server's thread, turns what changed into frames at its own rate per stream (wall-clock Hz) and drops
everything older — a slow page skips messages, it never makes the simulation wait.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from navlab.viz import frames as fr
from navlab.viz import sensor_frames

# kind of stream -> most frames per wall-clock second sent to one page
RATES_HZ = {
    "state": 30.0,
    "scan": 15.0,
    "map": 2.0,
    "costmap": 4.0,
    "path": 10.0,
    "poses": 5.0,
    "polygon": 10.0,
    "trace": 2.0,
    "graph": 0.5,
    "image": 5.0,
    "cloud": 5.0,
}
TRACE_STEP_M = 0.02  # a trace gets a point when the robot moved this far
TRACE_MAX = 20_000  # points kept per trace


@dataclass
class Slot:
    """The newest message of one topic: its kind (grid, scan, path, poses, polygon) and a sequence number."""

    kind: str
    msg: Any
    seq: int
    frame: str = ""
    pose: list[float] | None = None  # a scan's sensor pose in the fixed frame at its stamp (set by the producer)
    fixed: str = ""


@dataclass
class Trace:
    """A path drawn behind the robot (odometry or ground truth), in ``frame``."""

    frame: str
    xy: list[tuple[float, float]] = field(default_factory=list)
    seq: int = 0

    def add(self, x: float, y: float) -> None:
        """Append a point if the robot moved :data:`TRACE_STEP_M` since the last one."""
        if self.xy:
            lx, ly = self.xy[-1]
            if (x - lx) ** 2 + (y - ly) ** 2 < TRACE_STEP_M**2:
                return
        if len(self.xy) >= TRACE_MAX:
            del self.xy[: TRACE_MAX // 10]
        self.xy.append((x, y))
        self.seq += 1


class Hub:
    """The shared store. The producer calls :meth:`put`, :meth:`trace` and :meth:`set_state`; clients read."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.slots: dict[str, Slot] = {}
        self.placed: dict[str, Slot] = {}  # topic -> the newest scan given its sensor pose (what pages are sent)
        self.traces: dict[str, Trace] = {}
        self.state: dict[str, Any] = {}
        self.state_seq = 0
        self.graph: dict[str, Any] | None = None
        self.graph_seq = 0
        self._seq = 0
        self.handler: Callable[[dict[str, Any]], str | None] | None = None
        self.bytes_sent = 0  # everything every client was sent (bench)
        self.frames_sent = 0

    def put(self, topic: str, kind: str, msg: Any, frame: str = "") -> Slot:
        """The newest message of ``topic`` (producer thread; a reference, not a copy)."""
        self._seq += 1
        slot = self.slots[topic] = Slot(kind, msg, self._seq, frame)
        return slot

    def place_scans(self, fixed: str, lookup: Callable[[str, int], list[float] | None]) -> None:
        """Give each new scan its sensor's pose in ``fixed`` at its stamp: ``lookup(frame, t_ns)`` (producer
        thread). A scan is drawn where the robot was when it was taken, not where it is when drawn. Pages are sent
        the newest placed scan: faster than real time, a newer unplaced scan is almost always waiting."""
        for topic, slot in list(self.slots.items()):
            if slot.kind == "scan" and slot.pose is None:
                msg = slot.msg
                stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
                slot.pose, slot.fixed = lookup(str(msg.header.frame_id).lstrip("/"), stamp), fixed
                if slot.pose is not None:
                    self.placed[topic] = slot

    def trace(self, name: str, frame: str, x: float, y: float) -> None:
        """Extend a trace (producer thread)."""
        tr = self.traces.get(name)
        if tr is None or tr.frame != frame:
            tr = self.traces[name] = Trace(frame)
        with self.lock:
            tr.add(x, y)

    def set_trace(self, name: str, frame: str, xy: Any) -> None:
        """Replace a trace's points, (N, 2) in ``frame`` (a replay at a new time)."""
        tr = self.traces.get(name)
        if tr is None:
            tr = self.traces[name] = Trace(frame)
        with self.lock:
            tr.frame, tr.xy = frame, list(map(tuple, np.asarray(xy).tolist()))
            tr.seq += 1

    def clear_traces(self) -> None:
        """Forget every trace (a replay seeks backwards)."""
        with self.lock:
            for tr in self.traces.values():
                tr.xy.clear()
                tr.seq += 1

    def set_state(self, state: dict[str, Any]) -> None:
        """Replace the small JSON state (sim time, tf, move_base, ...)."""
        self.state = state
        self.state_seq += 1

    def set_graph(self, graph: dict[str, Any]) -> None:
        """The node/topic graph with rates (rqt_graph's data)."""
        self.graph = graph
        self.graph_seq += 1

    def handle(self, request: dict[str, Any]) -> str | None:
        """Hand a page's input to the producer; returns an error message, or None when accepted."""
        if self.handler is None:
            return "this viewer takes no inputs"
        return self.handler(request)


class ClientStream:
    """One page's view of the hub: what it was sent, per stream, and when."""

    def __init__(self, hub: Hub) -> None:
        self.hub = hub
        self._sent: dict[str, int] = {}
        self._last: dict[str, float] = {}
        self._differs: dict[str, fr.GridDiffer] = {}

    def _due(self, key: str, kind: str, now: float) -> bool:
        return now - self._last.get(key, -1e9) >= 1.0 / RATES_HZ[kind]

    def frames(self, now: float | None = None) -> list[bytes | str]:
        """Frames (binary or JSON text) for everything that changed and is due; marks them sent."""
        now = time.perf_counter() if now is None else now
        hub = self.hub
        out: list[bytes | str] = []
        out_state = self._state(now)
        if out_state is not None:
            out.append(out_state)
        for topic, newest in list(hub.slots.items()):
            slot = hub.placed.get(topic) if newest.kind == "scan" else newest
            if slot is None:
                continue  # no scan placed yet: the next snapshot places one
            kind = _rate_kind(topic, slot.kind)
            if self._sent.get(topic) == slot.seq or not self._due(topic, kind, now):
                continue
            frame = self._convert(topic, slot)
            self._sent[topic] = slot.seq
            self._last[topic] = now
            if frame is not None:
                out.append(frame)
        for name, tr in list(hub.traces.items()):
            key = "trace:" + name
            if self._sent.get(key) == tr.seq or not self._due(key, "trace", now):
                continue
            with hub.lock:
                xy = np.array(tr.xy, dtype=np.float32).reshape(-1, 2)
                seq = tr.seq
            out.append(fr.path_frame(name, tr.frame, xy, kind="trace"))
            self._sent[key], self._last[key] = seq, now
        if hub.graph is not None and self._sent.get("graph") != hub.graph_seq and self._due("graph", "graph", now):
            out.append(json.dumps({"k": "graph", **hub.graph}))
            self._sent["graph"], self._last["graph"] = hub.graph_seq, now
        return out

    def _state(self, now: float) -> str | None:
        hub = self.hub
        if self._sent.get("state") == hub.state_seq or not self._due("state", "state", now):
            return None
        self._sent["state"], self._last["state"] = hub.state_seq, now
        return json.dumps({"k": "state", **hub.state})

    def _convert(self, topic: str, slot: Slot) -> bytes | None:
        msg = slot.msg
        if slot.kind == "grid":
            differ = self._differs.setdefault(topic, fr.GridDiffer())
            return differ.frame(topic, msg)
        frame = slot.frame or str(msg.header.frame_id).lstrip("/")
        if slot.kind == "scan":
            return fr.scan_frame(topic, msg, frame=frame, pose=slot.pose, fixed=slot.fixed)
        if slot.kind == "path":
            return fr.path_frame(topic, frame, fr.path_xy(msg))
        if slot.kind == "poses":
            return fr.poses_frame(topic, frame, fr.pose_array_xyyaw(msg))
        if slot.kind == "polygon":
            return fr.path_frame(topic, frame, fr.polygon_xy(msg), kind="polygon")
        if slot.kind == "path_arr":
            return fr.path_frame(topic, frame, msg)
        if slot.kind == "poses_arr":
            return fr.poses_frame(topic, frame, msg)
        if slot.kind == "image":
            return sensor_frames.image_frame(topic, msg)
        if slot.kind == "cloud_arr":
            return sensor_frames.cloud_frame(topic, slot.frame, msg)
        if slot.kind == "goal":
            p = msg.pose
            yaw = 2.0 * float(np.arctan2(p.orientation.z, p.orientation.w))
            return fr.poses_frame(topic, frame, np.array([[p.position.x, p.position.y, yaw]]))
        return None


def _rate_kind(topic: str, kind: str) -> str:
    if kind == "grid":
        return "costmap" if "costmap" in topic else "map"
    if kind in ("goal", "poses_arr"):
        return "poses"
    if kind == "path_arr":
        return "path"
    if kind == "cloud_arr":
        return "cloud"
    return kind
