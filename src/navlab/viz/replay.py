"""Replaying a recording in the viewer: ``navlab view --bag DIR`` — rviz and ``rosbag play`` in one page.

The bag is read once into memory: per drawable topic its messages and times, the odometry traces, and
a tf buffer holding the whole recording. A player thread moves the replay clock (play, pause, speed,
seek from the page) and hands the hub, at each step, the newest message of each topic at that time.
"""

from __future__ import annotations

import bisect
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import TfBuffer, TfError, with_layout
from navlab.io import bag_graph, bag_topics, read_bag
from navlab.viz.errors import VizError
from navlab.viz.hub import Hub
from navlab.viz.inputs import check_input
from navlab.viz.live import KINDS

STEP_S = 1.0 / 30.0  # wall-clock s between replay steps


@dataclass
class Recording:
    """A bag's drawable content: times (ns) and messages per topic, odometry traces, and tf."""

    t0: int
    t1: int
    topics: dict[str, tuple[str, list[int], list[Any]]] = field(default_factory=dict)  # topic -> kind, times, msgs
    traces: dict[str, tuple[str, np.ndarray, np.ndarray]] = field(default_factory=dict)  # topic -> frame, t, xy
    tf: TfBuffer = field(default_factory=TfBuffer)
    base_frame: str = "base_link"


def load_recording(path: str | Path, *, progress: bool = False) -> Recording:
    """Read a rosbag2 directory (as ``--record`` writes it) for replay; ``progress``: a bar on stderr (when it is a
    terminal) counting the messages read and the recording's time reached."""
    import sys

    from tqdm import tqdm

    p = Path(path)
    if not (p / "metadata.yaml").is_file():
        raise VizError(f"{p}: not a rosbag2 recording (no metadata.yaml); record one with --record DIR")
    total = sum(count for _type, count in bag_topics(p).values())
    bar = tqdm(
        total=total,
        unit="msg",
        desc=f"loading {p.name}",
        file=sys.stderr,
        mininterval=0.5,
        disable=not progress or not sys.stderr.isatty(),
    )
    topics: dict[str, tuple[str, list[int], list[Any]]] = {}
    odom: dict[str, tuple[str, list[int], list[tuple[float, float]]]] = {}
    tf_msgs: list[tuple[int, Any, bool]] = []
    t0, t1 = None, 0
    base = "base_link"
    for topic, t_ns, msg in read_bag(p):
        t0 = t_ns if t0 is None else min(t0, t_ns)
        t1 = max(t1, t_ns)
        bar.update()
        if bar.n % 2000 == 0:
            bar.set_postfix_str(f"t={(t1 - t0) / 1e9:.1f} s of the recording", refresh=False)
        if topic in ("/tf", "/tf_static"):
            tf_msgs.append((t_ns, msg, topic == "/tf_static"))
            continue
        if msgs.type_name(msg) == "nav_msgs/msg/Odometry":
            _frame, ts, xy = odom.setdefault(topic, (str(msg.header.frame_id).lstrip("/") or "odom", [], []))
            ts.append(t_ns)
            xy.append((float(msg.pose.pose.position.x), float(msg.pose.pose.position.y)))
            if topic == "/odom":
                base = str(msg.child_frame_id).lstrip("/") or base
            continue
        kind = KINDS.get(type(msg))
        if msgs.type_name(msg) == "geometry_msgs/msg/PoseStamped" and topic.endswith("current_goal"):
            kind = "goal"
        if kind is None:
            continue
        _, ts, ms = topics.setdefault(topic, (kind, [], []))
        ts.append(t_ns)
        ms.append(msg)
    bar.close()
    if t0 is None:
        raise VizError(f"{p}: the recording holds no messages")
    tf = TfBuffer(cache_ns=t1 - t0 + 10**9)
    for _t, msg, static in tf_msgs:
        tf.add_message(msg, static=static)
    traces = {
        k: (f, np.array(ts, dtype=np.int64), np.array(xy, dtype=np.float32).reshape(-1, 2))
        for k, (f, ts, xy) in odom.items()
    }
    return Recording(t0, t1, topics, traces, tf, base)


class BagPlayer:
    """Plays a :class:`Recording` into a hub in its own thread; the page's play/pause/speed/seek steer it."""

    def __init__(self, rec: Recording, hub: Hub, *, speed: float = 1.0, graph: dict[str, Any] | None = None) -> None:
        self.rec, self.hub = rec, hub
        self.speed = speed
        self.paused = False
        self.t_ns = rec.t0
        self._sent: dict[str, int] = {}
        self._lock = threading.Lock()
        self._closed = threading.Event()
        self._seeked = True
        if graph:
            hub.set_graph({**with_layout(graph), "rates": {}, "types": {}})
        hub.handler = self.submit
        self._thread = threading.Thread(target=self._loop, name="navlab-replay", daemon=True)

    def start(self) -> BagPlayer:
        """Start playing."""
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop the player thread."""
        self._closed.set()
        self._thread.join(2.0)

    def submit(self, request: dict[str, Any]) -> str | None:
        """A page input: play, pause, speed, seek (anything else is not for a replay)."""
        try:
            op, args = check_input(request)
        except ValueError as exc:
            return str(exc)
        with self._lock:
            if op in ("play", "resume"):
                self.paused = False
                if self.t_ns >= self.rec.t1:
                    self.t_ns, self._seeked = self.rec.t0, True
            elif op == "pause":
                self.paused = True
            elif op == "speed":
                self.speed = args["value"] or 1.0
            elif op == "seek":
                self.t_ns = int(min(max(self.rec.t0 + args["t"] * 1e9, self.rec.t0), self.rec.t1))
                self._seeked = True
            else:
                return f"{op}: a replay cannot change the recording"
        return None

    def seek(self, t_s: float) -> None:
        """Jump to ``t_s`` seconds after the recording's start."""
        self.submit({"op": "seek", "t": float(t_s)})

    def _loop(self) -> None:
        last = time.perf_counter()
        while not self._closed.wait(STEP_S):
            now = time.perf_counter()
            with self._lock:
                if not self.paused:
                    self.t_ns = min(self.t_ns + int((now - last) * self.speed * 1e9), self.rec.t1)
                    if self.t_ns >= self.rec.t1:
                        self.paused = True
                seeked, self._seeked = self._seeked, False
                t = self.t_ns
            last = now
            self.show(t, reset=seeked)

    def show(self, t_ns: int, *, reset: bool = False) -> None:
        """Hand the hub everything as it was at ``t_ns``."""
        rec, hub = self.rec, self.hub
        if reset:
            self._sent.clear()
        for topic, (kind, ts, ms) in rec.topics.items():
            i = bisect.bisect_right(ts, t_ns) - 1
            if i >= 0 and self._sent.get(topic) != i:
                self._sent[topic] = i
                hub.put(topic, kind, ms[i])
        for topic, (frame, stamps, xy) in rec.traces.items():
            n = int(np.searchsorted(stamps, t_ns, side="right"))
            if self._sent.get("trace:" + topic) != n:
                self._sent["trace:" + topic] = n
                hub.set_trace(topic, frame, xy[:n])
        tf = {}
        frames = rec.tf.frames()
        fixed = "map" if "map" in frames else "odom"
        for frame in frames:
            try:
                tf[frame] = [round(v, 4) for v in rec.tf.lookup_pose2d_or_latest(fixed, frame, t_ns)]
            except TfError:
                continue
        tf.setdefault("world", [0.0, 0.0, 0.0])  # ground truth: the world is the map (or odom's start)
        hub.place_scans(fixed, lambda frame, stamp: self._pose_at(fixed, frame, stamp))
        hub.set_state(
            {
                "t": (t_ns - rec.t0) / 1e9,
                "t0": 0.0,
                "t1": (rec.t1 - rec.t0) / 1e9,
                "rtf": self.speed,
                "paused": self.paused,
                "speed": self.speed,
                "fixed": fixed,
                "base": rec.base_frame,
                "tf": tf,
                "move_base": None,
                "obstacles": [],
                "replay": True,
            }
        )

    def _pose_at(self, fixed: str, frame: str, t_ns: int) -> list[float] | None:
        try:
            return [round(v, 5) for v in self.rec.tf.lookup_pose2d_or_latest(fixed, frame, t_ns)]
        except TfError:
            return None


def play_bag(path: str | Path, hub: Hub, *, rate: float = 1.0, speed: float | None = None) -> BagPlayer:
    """Load a recording and start playing it into ``hub`` at ``rate`` (simulated s per wall-clock s; ``speed``,
    its old name, is deprecated)."""
    from navlab.deprecation import renamed

    rate = renamed(rate, speed, old="speed", new="rate", where="play_bag")
    rec = load_recording(path, progress=True)
    return BagPlayer(rec, hub, speed=rate, graph=bag_graph(path)).start()
