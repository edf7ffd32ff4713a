"""Monitors that runs add to a launch: ground truth beside the estimate, sampled in simulated time."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError

NAN3 = (math.nan, math.nan, math.nan)


class PoseMonitor(Node):
    """Every ``1/rate`` s: the true pose (``truth_topic``, world frame), the estimate (tf
    ``estimate_frame`` → ``base_frame``) and odometry (tf ``odom_frame`` → ``base_frame``); (x, y, yaw) in
    m and rad, NaN where not available yet. ``samples()`` returns them as arrays."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "pose_monitor",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.base_frame = self.declare_parameter("base_frame", "base_link")
        self.estimate_frame = self.declare_parameter("estimate_frame", "map")
        self.odom_frame = self.declare_parameter("odom_frame", "odom")
        truth_topic = self.declare_parameter("truth_topic", "/ground_truth/odom")
        rate = self.declare_parameter("rate", 2.0)
        self._truth: Any = None  # the latest truth message (converted when sampled, not at 50 Hz)
        self._rows: list[tuple[float, ...]] = []
        self.create_subscription(msgs.Odometry, truth_topic, self._on_truth, 1)
        self.create_timer(1.0 / rate, self._sample)

    def _on_truth(self, msg: Any) -> None:
        self._truth = msg

    def _lookup(self, frame: str) -> tuple[float, float, float]:
        try:
            return self.executor.tf.lookup_pose2d(frame, self.base_frame)
        except TfError:
            return NAN3

    def _sample(self) -> None:
        if self._truth is None:
            return
        row = (
            self.executor.now_ns / 1e9,
            *msgs.pose2d(self._truth.pose.pose),
            *self._lookup(self.estimate_frame),
            *self._lookup(self.odom_frame),
        )
        self._rows.append(row)

    def samples(self) -> dict[str, np.ndarray]:
        """``t`` (N,) s, ``truth``, ``estimate``, ``odometry`` (N, 3) each."""
        a = np.array(self._rows, dtype=np.float64).reshape(-1, 10)
        return {"t": a[:, 0], "truth": a[:, 1:4], "estimate": a[:, 4:7], "odometry": a[:, 7:10]}
