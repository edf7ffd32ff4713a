"""Scripted routes (a repeatable drive for mapping runs): a YAML file of velocity segments
(``{linear, angular, duration}``) and/or waypoints (``[x, y]`` in the odom frame), driven by ``RouteFollower``
with the ``PurePursuit`` controller."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError, read_yaml
from navlab.drivers.errors import DriverError
from navlab.navigation import PurePursuit


def load_route(path: str | Path) -> tuple[list[tuple[float, float, float]], np.ndarray]:
    """A route file (or a shipped route's name, ``room``): ``segments: [{linear, angular, duration}]`` and/or
    ``waypoints: [[x, y], ...]``."""
    text = str(path)
    if not Path(text).exists() and not Path(text).suffix and "/" not in text:
        from navlab import resources

        path = resources.route(text)
    data = read_yaml(path)
    if not isinstance(data, dict) or not ({"segments", "waypoints"} & set(data)):
        raise DriverError(f"{path}: a route file needs 'segments' and/or 'waypoints'")
    segments = []
    raw_segments = data.get("segments") or []
    if not isinstance(raw_segments, list):
        raise DriverError(f"{path}: segments: expected a list of {{linear, angular, duration}}, got {raw_segments!r}")
    for k, seg in enumerate(raw_segments):
        try:
            values = [seg.get("linear", 0.0), seg.get("angular", 0.0), seg["duration"]]
            if any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
                raise TypeError
            lin, ang, dur = (float(v) for v in values)
        except (KeyError, TypeError, ValueError, AttributeError):
            raise DriverError(f"{path}: segments[{k}]: expected {{linear, angular, duration}} numbers") from None
        if not (math.isfinite(lin) and math.isfinite(ang) and math.isfinite(dur) and dur > 0):
            raise DriverError(f"{path}: segments[{k}]: expected finite speeds and a duration > 0 s, got {seg!r}")
        segments.append((lin, ang, dur))
    raw = data.get("waypoints") or []
    if not isinstance(raw, list) or not all(
        isinstance(w, list)
        and len(w) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in w)
        for w in raw
    ):
        raise DriverError(f"{path}: waypoints: expected a list of [x, y] pairs of finite numbers, got {raw!r}")
    return segments, np.array(raw, dtype=float).reshape(-1, 2)


class RouteFollower(Node):
    """Drives a scripted route: velocity segments first, then waypoints (pure pursuit, ``PurePursuit``).

    Parameters: ``segments`` (list of {linear, angular, duration}), ``waypoints`` (list of [x, y] in
    ``odom_frame``), ``base_frame``, ``odom_frame``, ``max_vel_x``, ``rate``, ``loop`` (drive the waypoints
    round and round), ``pose_topic`` (steer on a ``nav_msgs/Odometry`` topic such as
    ``/ground_truth/odom`` instead of tf; its frame is then the waypoints' frame), ``waypoint_tolerance``
    (m). ``done`` becomes True at the end of a route that does not loop.
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "route_follower",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        raw_segments = self.declare_parameter("segments", [])
        self.waypoints = np.array(self.declare_parameter("waypoints", []), dtype=float).reshape(-1, 2)
        self.base_frame = self.declare_parameter("base_frame", "chassis")
        self.odom_frame = self.declare_parameter("odom_frame", "odom")
        self.max_v = self.declare_parameter("max_vel_x", 0.3)
        self.loop = self.declare_parameter("loop", False)
        self.tolerance = self.declare_parameter("waypoint_tolerance", 0.1)
        pose_topic = self.declare_parameter("pose_topic", "")
        rate = self.declare_parameter("rate", 10.0)
        self.segments = [
            (float(s.get("linear", 0)), float(s.get("angular", 0)), float(s["duration"])) for s in raw_segments
        ]
        self.follower = PurePursuit(lookahead=0.05, max_vel_x=self.max_v, xy_goal_tolerance=0.0)
        self.done = False
        self.index = 0  # the waypoint driven to
        self._seg_end: int | None = None
        self._topic_pose: tuple[float, float, float] | None = None
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        if pose_topic:
            self.create_subscription(msgs.Odometry, pose_topic, self._on_pose, 10)
        self._use_topic = bool(pose_topic)
        self.create_timer(1.0 / rate, self._tick)

    def _on_pose(self, msg: Any) -> None:
        self._topic_pose = msgs.pose2d(msg.pose.pose)

    def _pose(self) -> tuple[float, float, float] | None:
        if self._use_topic:
            return self._topic_pose
        try:
            return self.executor.tf.lookup_pose2d(self.odom_frame, self.base_frame)
        except TfError:
            return None

    def _tick(self) -> None:
        if self.done:
            return
        now = self.executor.now_ns
        if self.segments:
            if self._seg_end is None:
                self._seg_end = now + round(self.segments[0][2] * 1e9)
            if now < self._seg_end:
                v, w, _ = self.segments[0]
                self.pub.publish(msgs.twist(v, w))
                return
            self.segments.pop(0)
            self._seg_end = None
            self._tick()
            return
        if self.index >= len(self.waypoints):
            if self.loop and len(self.waypoints):
                self.index = 0
            else:
                self.done = True
                self.pub.publish(msgs.twist(0.0, 0.0))
                return
        pose = self._pose()
        if pose is None:
            return
        target = self.waypoints[self.index]
        if math.hypot(target[0] - pose[0], target[1] - pose[1]) < self.tolerance:
            self.index += 1
            self._tick()
            return
        self.follower.set_plan(np.array([pose[:2], target]))
        self.pub.publish(msgs.twist(*self.follower.compute_velocity(pose)))
