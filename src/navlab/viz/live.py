"""The live viewer: a node that subscribes what rviz would show, keeps the pace, and applies the page's inputs.

``ViewerNode`` finds the topics to draw by message type (maps and costmaps, scans, plans, the particle
cloud, footprints, goals, odometry) as they appear, hands each newest message to the :class:`Hub`, and
every frame (wall-clock 30 Hz at most) stores a small state: simulated time, real-time factor, the tf
poses of every frame in the fixed frame, move_base's state and last outcome, the obstacles placed here.

Inputs arrive from the server's thread as JSON objects; they are checked there and applied in the
executor's thread through its inbox (:meth:`Executor.post`). Only pause/resume and speed act on the
:class:`Pacer` directly (thread-safe flags); while paused, each input lets the executor step to its next
event (at most one pacing period, 10 simulated ms), where it reads its inbox.
"""

from __future__ import annotations

import functools
import json
import math
import time
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Graph, Node, TfError, with_layout
from navlab.drivers import MOVE_BINDINGS, SPEED_BINDINGS, TeleopState
from navlab.viz.hub import Hub
from navlab.viz.inputs import check_input
from navlab.viz.pacer import Pacer
from navlab.viz.sensor_frames import cloud_in_fixed

# rviz's 2D Pose Estimate: x/y variance 0.25 m², yaw variance (pi/12)² rad²
INITIALPOSE_COV = (0.25, 0.25, 0.0, 0.0, 0.0, 0.06853891945200942)
KINDS = {
    msgs.OccupancyGrid: "grid",
    msgs.LaserScan: "scan",
    msgs.Path: "path",
    msgs.PoseArray: "poses",
    msgs.PolygonStamped: "polygon",
    msgs.Image: "image",
    msgs.PointCloud2: "cloud",
}
ODOM_PERIOD_NS = 50_000_000  # simulated ns between odometry samples kept for the traces (20 Hz at most)
GRAPH_WALL_PERIOD = 1.0  # wall-clock s between refreshes of the node graph (at most)
PEEK_PERIOD = 0.2  # wall-clock s between copies of the plans and the particle cloud
ALL_FRAMES_PERIOD = 0.5  # wall-clock s between poses of every tf frame (the others: every snapshot)
SPEEDS = (0.0, 0.5, 1.0, 2.0, 5.0)  # 0 = as fast as possible
FAST_TICK_HZ = 100.0  # as fast as possible: the fewest pacing ticks per wall-clock s (snapshots are 30/s at most)


class ViewerNode(Node):
    """rviz in a node: subscribes what it draws, publishes ``initialpose``, goals and ``cmd_vel``.

    Parameters: ``fixed_frame`` (default ``map`` when tf knows it, else ``odom``), ``base_frame``
    (default: the simulated robot's), ``pace_period`` (simulated s between pacing ticks, 0.01; as fast as
    possible, the ticks only take snapshots: up to ``max_pace_period``, 0.1, so that they still come
    ``FAST_TICK_HZ`` times per wall-clock s),
    ``frame_hz`` (most state snapshots per wall-clock s, 30), ``graph_period`` (simulated s, 1.0).
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "navlab_viewer",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        hub: Hub | None = None,
        pacer: Pacer | None = None,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.hub = hub if hub is not None else Hub()
        self.pacer = pacer if pacer is not None else Pacer(executor.rate or 1.0)
        self._rate = executor.rate
        executor.rate = 0.0  # the pacer keeps the pace from now on (it can pause and change speed)
        self.fixed_frame = str(self.declare_parameter("fixed_frame", ""))
        self.base_frame = str(self.declare_parameter("base_frame", ""))
        frame_hz = float(self.declare_parameter("frame_hz", 30.0))
        self._frame_wall = 1.0 / frame_hz if frame_hz > 0 else 0.0
        self.teleop = TeleopState()
        self.goal_pub = self.create_publisher(msgs.PoseStamped, "move_base_simple/goal", 1)
        self.pose_pub = self.create_publisher(msgs.PoseWithCovarianceStamped, "initialpose", 1)
        self.cmd_pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self._subscribed: set[str] = set()
        self._last_frame = -1e9
        self._rtf_mark = (executor.now_ns, time.perf_counter())
        self.rtf = 0.0
        self.obstacles: dict[str, dict[str, Any]] = {}  # placed from the page: name -> kind, dims, x, y
        self.last_outcome: dict[str, Any] = {}
        self._counts: dict[str, tuple[int, int]] = {}  # topic -> (count, t_ns) at the last graph
        self._graph_key, self._layout = "", None  # the last graph's structure and its dot layout
        self._odom_due: dict[str, int] = {}  # topic -> simulated ns of its next trace sample
        self._direct: dict[str, tuple[str, Any]] | None = None
        self._last_peek = -1e9
        self._last_graph = -1e9
        self._n_topics = len(executor.topics)
        self._last_all_frames = -1e9
        self._discover()
        self._pace_period = float(self.declare_parameter("pace_period", 0.01))
        self._max_pace_period = max(self._pace_period, float(self.declare_parameter("max_pace_period", 0.1)))
        self._pace_timer = self.create_timer(self._pace_period, self._tick, priority=-10)
        self.create_timer(float(self.declare_parameter("graph_period", 1.0)), self._on_graph_timer)
        self.hub.handler = self.submit
        self._snapshot(force=True)

    # --- what to draw -------------------------------------------------------------------------------

    def _on_graph_timer(self) -> None:
        """Every ``graph_period`` simulated s: subscribe the topics that appeared, and refresh the graph at most
        once per ``GRAPH_WALL_PERIOD`` wall-clock s (as fast as possible, simulated seconds come many times a
        wall-clock second; the page takes the graph every 2 s)."""
        if len(self.executor.topics) != self._n_topics:
            self._n_topics = len(self.executor.topics)
            self._discover()
        wall = time.perf_counter()
        if wall - self._last_graph >= GRAPH_WALL_PERIOD:
            self._last_graph = wall
            self._publish_graph()

    def _discover(self) -> None:
        """Subscribe every drawable topic that appeared since the last look."""
        mine = {p.topic_name for p in self.publishers} | set(self._direct_topics())
        for name, topic in list(self.executor.topics.items()):
            if name in self._subscribed or name in mine:
                continue
            kind = KINDS.get(topic.msgtype)
            if topic.msgtype is msgs.Odometry:
                self.create_subscription(msgs.Odometry, name, functools.partial(self._on_odom, name), 5)
            elif topic.msgtype is msgs.PoseStamped and name.endswith("current_goal"):
                self.create_subscription(msgs.PoseStamped, name, functools.partial(self._on_msg, name, "goal"), 1)
            elif kind is not None:
                self.create_subscription(topic.msgtype, name, functools.partial(self._on_msg, name, kind), 1)
            else:
                continue
            self._subscribed.add(name)

    def _direct_topics(self) -> dict[str, tuple[str, Any]]:
        """Topics read from their node's arrays instead (the node builds no message for us):
        topic -> (frame, a function returning the array or None)."""
        out: dict[str, tuple[str, Any]] = {}
        mb = self._move_base()
        if mb is not None and hasattr(mb, "plan_pub"):
            out[mb.plan_pub.topic_name] = (mb.global_costmap.global_frame, lambda: mb.global_plan)
            out[mb.local_plan_pub.topic_name] = (
                mb.local_costmap.global_frame,
                lambda: getattr(mb.controller, "local_plan", None),
            )
        amcl = self._node_with("filter", "cloud_pub", "global_frame")
        if amcl is not None:
            out[amcl.cloud_pub.topic_name] = (
                str(amcl.global_frame),
                lambda: None if amcl.filter is None else amcl.filter.particles,
            )
        return out

    def _peek(self) -> None:
        """Copy the plans and the particle cloud from their nodes (executor thread, a few times a second)."""
        if self._direct is None:
            self._direct = self._direct_topics()
        for topic, (frame, get) in self._direct.items():
            arr = get()
            if arr is None:
                continue
            arr = np.asarray(arr)
            kind = "poses_arr" if topic.endswith("particlecloud") else "path_arr"
            self.hub.put(topic, kind, arr[:, :3].copy() if kind == "poses_arr" else arr[:, :2].copy(), frame)

    def _on_msg(self, topic: str, kind: str, msg: Any) -> None:
        if kind == "cloud":  # moved into the fixed frame here, where tf is (a few thousand points)
            fixed, frame, tf = self._fixed(), str(msg.header.frame_id).lstrip("/"), self.executor.tf
            try:
                t = (
                    tf.lookup(fixed, frame, msgs.stamp_ns(msg))
                    if tf.can_transform(fixed, frame, msgs.stamp_ns(msg))
                    else tf.lookup(fixed, frame)
                )
            except TfError:
                return
            xyz = cloud_in_fixed(msg, t, self.rng)
            if xyz is not None:
                self.hub.put(topic, "cloud_arr", xyz, fixed)
            return
        self.hub.put(topic, kind, msg)

    def _on_odom(self, topic: str, msg: Any) -> None:
        """A trace sample, throttled in simulated time (as fast as possible, odometry comes ~1000 times/s)."""
        now = self.executor.now_ns
        if now < self._odom_due.get(topic, 0):
            return
        self._odom_due[topic] = now + ODOM_PERIOD_NS
        p = msg.pose.pose.position
        self.hub.trace(topic, str(msg.header.frame_id).lstrip("/") or "odom", float(p.x), float(p.y))

    def _publish_graph(self) -> None:
        ex = self.executor
        graph = Graph.from_executor(ex).to_json()
        rates = {}
        for name, topic in ex.topics.items():
            c0, t0 = self._counts.get(name, (topic.count, ex.now_ns))
            rates[name] = round((topic.count - c0) / ((ex.now_ns - t0) / 1e9), 2) if ex.now_ns > t0 else 0.0
            self._counts[name] = (topic.count, ex.now_ns)
        key = json.dumps(graph, sort_keys=True)
        if key != self._graph_key:  # the structure changed: lay it out again (dot takes ~20 ms)
            self._graph_key, self._layout = key, with_layout(graph).get("layout")
        self.hub.set_graph(
            {
                **graph,
                "rates": rates,
                "layout": self._layout,
                "types": {n: msgs.type_name(t.msgtype) for n, t in ex.topics.items()},
            }
        )

    # --- pace and state -------------------------------------------------------------------------------

    def _tick(self) -> None:
        self.pacer.tick(self.executor.now_ns, idle=lambda: self._snapshot(force=True))
        self._snapshot()
        period = self._tick_period()
        if abs(period - self._pace_timer.period_ns / 1e9) > 1e-9:  # the pace changed: a new period from now
            self._pace_timer.cancel()
            self.timers.remove(self._pace_timer)
            self._pace_timer = self.create_timer(period, self._tick, priority=-10)

    def _tick_period(self) -> float:
        """``pace_period`` while paced or paused. As fast as possible a tick only takes the snapshots, so it
        comes every ``FAST_TICK_HZ``-th of a wall-clock s at the measured pace (whole ``pace_period``s, at
        most ``max_pace_period``): the simulation pays for fewer events."""
        if self.pacer.speed > 0 or self.pacer.paused or self.rtf <= 0:
            return self._pace_period
        k = int(self.rtf / FAST_TICK_HZ / self._pace_period)
        return min(self._max_pace_period, max(1, k) * self._pace_period)

    def _snapshot(self, *, force: bool = False) -> None:
        wall = time.perf_counter()
        if not force and wall - self._last_frame < self._frame_wall:
            return
        self._last_frame = wall
        ex = self.executor
        if wall - self._last_peek >= PEEK_PERIOD:
            self._last_peek = wall
            self._peek()
        n0, w0 = self._rtf_mark
        if wall - w0 >= 0.5:
            self.rtf = (ex.now_ns - n0) / 1e9 / (wall - w0)
            self._rtf_mark = (ex.now_ns, wall)
        fixed = self._fixed()
        tf = {}
        every = wall - self._last_all_frames >= ALL_FRAMES_PERIOD  # the tf display's other frames, now and then
        if every:
            self._last_all_frames = wall
        for frame in ex.tf.frames() if every else self._drawn_frames(fixed):
            try:
                tf[frame] = [round(v, 4) for v in ex.tf.lookup_pose2d(fixed, frame)]
            except TfError:
                continue
        tf.setdefault("world", [0.0, 0.0, 0.0])  # ground truth: the world is the map (or odom's start)
        self.hub.place_scans(fixed, self._pose_at)
        self.hub.set_state(
            {
                "t": ex.now_ns / 1e9,
                "rtf": round(self.rtf, 2),
                "paused": self.pacer.paused,
                "speed": self.pacer.speed,
                "fixed": fixed,
                "base": self._base(),
                "tf": tf,
                "move_base": self._move_base_state(),
                "obstacles": [{"name": k, **v} for k, v in self.obstacles.items()],
                "replay": False,
                "teleop": {"speed": round(self.teleop.speed, 3), "turn": round(self.teleop.turn, 3)},
            }
        )

    def _pose_at(self, frame: str, t_ns: int) -> list[float] | None:
        """(x, y, yaw) of ``frame`` in the fixed frame at ``t_ns`` (the latest if tf has none then)."""
        try:
            return [round(v, 5) for v in self.executor.tf.lookup_pose2d_or_latest(self._fixed(), frame, t_ns)]
        except TfError:
            return None

    def _drawn_frames(self, fixed: str) -> set[str]:
        """The frames the page places something in: the fixed and base frames, and every stream's frame."""
        frames = {fixed, self._base(), "odom"}
        for slot in list(self.hub.slots.values()):
            frames.add(slot.frame or str(getattr(getattr(slot.msg, "header", None), "frame_id", "")).lstrip("/"))
        frames.update(tr.frame for tr in list(self.hub.traces.values()))
        frames.discard("")
        return frames

    def _fixed(self) -> str:
        if self.fixed_frame:
            return self.fixed_frame
        frames = self.executor.tf.frames()
        return "map" if "map" in frames else "odom"

    def _base(self) -> str:
        if self.base_frame:
            return self.base_frame
        gz = self._gazebo()
        robot = getattr(getattr(gz, "sim", None), "robot", None)
        if robot is not None:
            dd = robot.diff_drive
            self.base_frame = dd.robot_base_frame if dd else robot.root_link
            return self.base_frame
        return "base_link"

    def _node_with(self, *attrs: str) -> Any:
        for node in self.executor.nodes.values():
            if all(hasattr(node, a) for a in attrs):
                return node
        return None

    def _gazebo(self) -> Any:
        return self._node_with("spawn", "delete", "sim")

    def _move_base(self) -> Any:
        return self._node_with("send_goal", "cancel_goal", "handle")

    def _move_base_state(self) -> dict[str, Any] | None:
        mb = self._move_base()
        if mb is None:
            return None
        h = mb.handle
        goal = None if h is None else {"goal": list(h.goal), "frame": h.frame_id, "state": h.state, "reason": h.reason}
        if h is not None and h.done():
            self.last_outcome = {"state": h.state, "reason": h.reason, "goal": list(h.goal)}
        return {"state": str(mb.state), "goal": goal, "outcome": self.last_outcome or None}

    # --- inputs ------------------------------------------------------------------------------------

    def submit(self, request: dict[str, Any]) -> str | None:
        """Thread-safe: check a page input and queue it for the executor; returns an error or None."""
        try:
            op, args = check_input(request)
        except ValueError as exc:
            return str(exc)
        if op == "pause":
            self.pacer.pause()
        elif op == "resume":
            self.pacer.resume()
        elif op == "speed":
            self.pacer.set_speed(args["value"])
        else:
            self.executor.post(functools.partial(self._apply, op, args))
            self.pacer.step()  # applied at once, even while paused
        return None

    def _apply(self, op: str, a: dict[str, Any]) -> None:
        """Apply one checked input (executor thread)."""
        now = self.executor.now_ns
        if op == "goal":
            self.goal_pub.publish(msgs.pose_stamped(now, a.get("frame") or self._fixed(), a["x"], a["y"], a["yaw"]))
        elif op == "initialpose":
            cov = msgs.covariance(INITIALPOSE_COV)
            frame = a.get("frame") or self._fixed()
            self.pose_pub.publish(
                msgs.PoseWithCovarianceStamped(
                    header=msgs.header(now, frame),
                    pose=msgs.PoseWithCovariance(pose=msgs.pose_from_2d(a["x"], a["y"], a["yaw"]), covariance=cov),
                )
            )
        elif op == "cancel":
            mb = self._move_base()
            if mb is not None:
                mb.cancel_goal()
        elif op == "key":
            self.teleop.key(a["key"])
            self.cmd_pub.publish(self.teleop.twist())
        elif op in ("spawn", "move", "delete"):
            self._obstacle(op, a)
        self._snapshot(force=True)

    def _obstacle(self, op: str, a: dict[str, Any]) -> None:
        ex = self.executor
        if "/spawn_entity" not in ex.services:
            self.get_logger().warning("no simulator in this launch: obstacles cannot be placed")
            return
        name = a.get("name") or ""
        if op in ("move", "delete"):
            if name not in self.obstacles:
                self.get_logger().warning(f"no obstacle {name!r} placed from the viewer")
                return
            ex.call_service("/delete_entity", {"name": name})
            spec = self.obstacles.pop(name)
            if op == "delete":
                return
            spec = {**spec, "x": a["x"], "y": a["y"]}
        else:
            k = 1
            while f"viewer_{a['kind']}_{k}" in self.obstacles or f"viewer_{a['kind']}_{k}" in self._models():
                k += 1
            name = f"viewer_{a['kind']}_{k}"
            spec = {"kind": a["kind"], "dims": list(a["dims"]), "x": a["x"], "y": a["y"], "yaw": a.get("yaw", 0.0)}
        wx, wy = self._to_world(spec["x"], spec["y"])
        reply = ex.call_service(
            "/spawn_entity",
            {
                "kind": spec["kind"],
                "name": name,
                "dims": tuple(spec["dims"]),
                "x": wx,
                "y": wy,
                "yaw": spec.get("yaw", 0.0),
            },
        )
        if reply.get("success"):
            self.obstacles[name] = spec
        else:
            self.get_logger().warning(f"could not place {name}: {reply.get('status_message')}")

    def _models(self) -> list[str]:
        gz = self._gazebo()
        return list(gz.sim.model_names()) if gz is not None else []

    def _to_world(self, x: float, y: float) -> tuple[float, float]:
        """A point in the fixed frame, in the simulated world (map = world; odom from the true pose)."""
        fixed = self._fixed()
        gz = self._gazebo()
        if fixed == "map" or gz is None:
            return x, y
        try:
            bx, by, byaw = self.executor.tf.lookup_pose2d(fixed, self._base())
        except TfError:
            return x, y
        tx, ty, tyaw = gz.sim.base_pose2d()
        dx, dy = x - bx, y - by  # the point relative to the robot, rotated into the world by the heading error
        c, s = math.cos(tyaw - byaw), math.sin(tyaw - byaw)
        return tx + c * dx - s * dy, ty + s * dx + c * dy

    def close(self) -> None:
        """Stop pacing for good (a paused run finishes)."""
        self.pacer.close()
        self.hub.handler = None
        self.executor.rate = self._rate


__all__ = ["INITIALPOSE_COV", "MOVE_BINDINGS", "SPEEDS", "SPEED_BINDINGS", "Pacer", "ViewerNode"]
