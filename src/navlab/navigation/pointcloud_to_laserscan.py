"""``pointcloud_to_laserscan``: a ``sensor_msgs/PointCloud2`` (``cloud_in``) flattened into a ``LaserScan``
(``scan``) — the nearest point of each angular bin among the points between ``min_height`` and
``max_height``, as the ROS package does (its parameter names and defaults).

Parameters: ``target_frame`` ("" = the cloud's frame; else the points are moved there with tf at the cloud's
stamp), ``transform_tolerance`` (s, 0.01), ``min_height``/``max_height`` (m, the smallest positive double and
the largest), ``angle_min``/``angle_max`` (rad, -pi/pi), ``angle_increment`` (rad, pi/180), ``scan_time``
(s, 1/30), ``range_min``/``range_max`` (m, 0 and the largest double), ``use_inf`` (true: bins without a point
are ``inf``; false: ``range_max + inf_epsilon``), ``inf_epsilon`` (1.0).
"""

from __future__ import annotations

import math
import sys
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Node, TfError
from navlab.geometry import matrix_from_quat
from navlab.io import move_points, read_xyz
from navlab.navigation.errors import NavigationError

DOUBLE_MIN, DOUBLE_MAX = sys.float_info.min, sys.float_info.max


def flatten(
    points: np.ndarray,
    *,
    angle_min: float,
    angle_max: float,
    angle_increment: float,
    min_height: float,
    max_height: float,
    range_min: float,
    range_max: float,
    fill: float,
) -> np.ndarray:
    """Ranges (float32) of the scan bins from ``points`` (N, 3) in the scan's frame: the nearest planar range
    of the points in each bin, ``fill`` where none is."""
    n = math.ceil((angle_max - angle_min) / angle_increment)
    out = np.full(n, np.inf)
    p = points[np.isfinite(points).all(axis=1)]
    p = p[(p[:, 2] >= min_height) & (p[:, 2] <= max_height)]
    r = np.hypot(p[:, 0], p[:, 1])
    a = np.arctan2(p[:, 1], p[:, 0])
    keep = (r >= range_min) & (r <= range_max) & (a >= angle_min) & (a <= angle_max)
    idx = ((a[keep] - angle_min) / angle_increment).astype(np.int64)
    idx = np.minimum(idx, n - 1)
    np.minimum.at(out, idx, r[keep])
    out[~np.isfinite(out)] = fill
    return out.astype(np.float32)


class PointCloudToLaserScan(Node):
    """The ``pointcloud_to_laserscan_node`` (see the module docstring)."""

    def __init__(
        self,
        executor: Any,
        *,
        name: str = "pointcloud_to_laserscan",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.target_frame = str(self.declare_parameter("target_frame", "")).lstrip("/")
        self.tolerance = float(self.declare_parameter("transform_tolerance", 0.01))
        p = {
            k: float(self.declare_parameter(k, v))
            for k, v in (
                ("min_height", DOUBLE_MIN),
                ("max_height", DOUBLE_MAX),
                ("angle_min", -math.pi),
                ("angle_max", math.pi),
                ("angle_increment", math.pi / 180.0),
                ("scan_time", 1.0 / 30.0),
                ("range_min", 0.0),
                ("range_max", DOUBLE_MAX),
                ("inf_epsilon", 1.0),
            )
        }
        self.use_inf = bool(self.declare_parameter("use_inf", True))
        if not p["angle_increment"] > 0 or not p["angle_min"] < p["angle_max"]:
            raise NavigationError(
                f"{name}: expected angle_min < angle_max and angle_increment > 0, got "
                f"{p['angle_min']}, {p['angle_max']}, {p['angle_increment']}"
            )
        if p["min_height"] > p["max_height"] or p["range_min"] > p["range_max"]:
            raise NavigationError(f"{name}: expected min_height <= max_height and range_min <= range_max")
        self.p = p
        self.pub = self.create_publisher(msgs.LaserScan, "scan", 10)
        self.create_subscription(msgs.PointCloud2, "cloud_in", self.on_cloud, 10)

    def on_cloud(self, msg: Any) -> None:
        """Flatten one cloud and publish the scan (stamped as the cloud)."""
        pts = read_xyz(msg).astype(np.float64)
        frame = str(msg.header.frame_id).lstrip("/")
        stamp = msgs.stamp_ns(msg)
        if self.target_frame and self.target_frame != frame:
            try:
                t = self.executor.tf.lookup(self.target_frame, frame, stamp)
            except TfError as exc:
                self.get_logger().warning(f"cannot transform the cloud from {frame} to {self.target_frame}: {exc}")
                return
            pts = move_points(pts, matrix_from_quat(t[3:]), t[:3]).astype(np.float64)
            frame = self.target_frame
        p = self.p
        fill = math.inf if self.use_inf else p["range_max"] + p["inf_epsilon"]
        ranges = flatten(
            pts,
            angle_min=p["angle_min"],
            angle_max=p["angle_max"],
            angle_increment=p["angle_increment"],
            min_height=p["min_height"],
            max_height=p["max_height"],
            range_min=p["range_min"],
            range_max=p["range_max"],
            fill=fill,
        )
        self.pub.publish(
            msgs.LaserScan(
                header=msgs.header(stamp, frame),
                angle_min=p["angle_min"],
                angle_max=p["angle_max"],
                angle_increment=p["angle_increment"],
                time_increment=0.0,
                scan_time=p["scan_time"],
                range_min=p["range_min"],
                range_max=p["range_max"],
                ranges=ranges,
                intensities=np.zeros(0, np.float32),
            )
        )
