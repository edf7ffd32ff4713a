"""The navigation run's ground truth: :class:`NavMonitor` samples the true path, the clearance, the localization
error and the plan tracking at ``SAMPLE_S``, and records contacts, commands and the last scan."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.experiments.metrics import distance_to_path
from navlab.geometry import compose2, transform_points2

SAFETY_DISTANCE_M = 0.10  # clearance (m) under which the drive counts time "under the safety distance"
SAMPLE_S = 0.1  # NavMonitor's sampling period (s)


class NavMonitor(Node):
    """Ground truth for the goals: the true path and the clearance (m between the robot's collision geometry and
    the world's, ``Simulation.clearance``) at 10 Hz, contact episodes on ``/collisions``; and, with ``keep_scan``
    (default true), the last scan's points in the world for the pictures."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "nav_monitor",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Any = None,
        move_base: Any = None,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.safety_distance = float(self.declare_parameter("safety_distance", SAFETY_DISTANCE_M))
        self.base_frame = str(self.declare_parameter("base_frame", "base_link"))
        self.sim, self.move_base = sim, move_base
        self.path: list[tuple[float, float, float]] = []
        self.clearance: list[float] = []
        self.contacts: list[float] = []  # times (s) of /collisions messages
        self._scan: Any = None
        self.estimate_frame = str(self.declare_parameter("estimate_frame", "map"))
        self.localization_error: list[float] = []  # |estimate - truth| (m) at each sample, where there is one
        self.cmd: list[tuple[float, float]] = []  # (t s, linear x m/s) of every cmd_vel
        self.tracking: list[float] = []  # distance (m) of the true pose to move_base's current plan, per sample
        self.create_subscription(msgs.Twist, "cmd_vel", self._on_cmd, 10)
        self.create_subscription(msgs.String, "/collisions", lambda _m: self.contacts.append(self.now_s()), 10)
        if self.declare_parameter("keep_scan", True):  # for scan_points (the pictures); else no scan is delivered
            self.create_subscription(msgs.LaserScan, "scan", self._on_scan, 5)
        self.create_timer(SAMPLE_S, self._sample)

    def _on_cmd(self, msg: Any) -> None:
        self.cmd.append((self.now_s(), float(msg.linear.x)))

    def _on_scan(self, msg: Any) -> None:
        self._scan = msg

    def now_s(self) -> float:
        """Simulated time (s)."""
        return self.executor.now_ns / 1e9

    def _sample(self) -> None:
        x, y, _ = self.sim.base_pose2d()
        self.path.append((self.now_s(), x, y))
        if self.estimate_frame:
            try:
                ex, ey, _ = self.executor.tf.lookup_pose2d(self.estimate_frame, self.base_frame)
                self.localization_error.append(math.hypot(ex - x, ey - y))
            except TfError:
                pass
        self.clearance.append(self.sim.clearance())
        plan = getattr(self.move_base, "global_plan", None)  # in the map frame: the world's with a true map
        ok = self.estimate_frame == "map" and plan is not None and len(plan) > 0
        self.tracking.append(
            float(distance_to_path(np.array([[x, y]]), plan)[0]) if ok and plan is not None else math.nan
        )

    def scan_points(self) -> np.ndarray | None:
        """The last scan's returns (N, 2) in the world frame (from the true pose), or None."""
        msg = self._scan
        if msg is None:
            return None
        try:
            laser = self.sensor_pose(self.base_frame, str(msg.header.frame_id).lstrip("/"))
        except TfError:
            return None
        r = np.asarray(msg.ranges, dtype=np.float64)
        a = float(msg.angle_min) + float(msg.angle_increment) * np.arange(len(r))
        ok = np.isfinite(r) & (r < float(msg.range_max))
        pose = compose2(self.sim.base_pose2d(), laser)
        return transform_points2(pose, np.stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])], axis=1))
