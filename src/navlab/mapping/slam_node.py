"""The ``slam_gmapping`` node: online SLAM with slam_gmapping's topics, frames and parameters.

Subscribes to the laser scan (topic ``scan``; parameter ``scan_topic`` renames it) and reads odometry
from tf ``odom_frame`` → ``base_frame`` at each scan's stamp. Processes a scan when the robot has moved
``linearUpdate`` m / turned ``angularUpdate`` rad (or ``temporalUpdate`` s passed). Publishes ``map``
(nav_msgs/OccupancyGrid, latched, at most every ``map_update_interval`` s), ``map_metadata``,
tf ``map_frame`` → ``odom_frame`` every ``transform_publish_period`` s, and the best trajectory on
``trajectory`` (nav_msgs/Path). ``mode`` selects the algorithm: ``gmapping`` (default, the RBPF) or
``graph`` (scan matching + loop closure + pose-graph optimisation).
"""

from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.geometry import between2, compose2, inverse2
from navlab.grid import GridMap
from navlab.mapping.errors import MappingError
from navlab.mapping.gmapping import GMapping, GMappingParams
from navlab.mapping.graph_slam import GraphSlam, GraphSlamParams
from navlab.mapping.occupancy import build_map


class SlamGMapping(Node):
    """slam_gmapping: the RBPF (or the graph mode) driven by scans and tf odometry."""

    def __init__(
        self, executor: Executor, *, name: str = "slam_gmapping", parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:  # fmt: skip
        super().__init__(name, executor, parameters=parameters, namespace=namespace)
        self.base_frame = self.declare_parameter("base_frame", "base_link")
        self.odom_frame = self.declare_parameter("odom_frame", "odom")
        self.map_frame = self.declare_parameter("map_frame", "map")
        self.map_update_interval = float(self.declare_parameter("map_update_interval", 5.0))
        self.transform_publish_period = float(self.declare_parameter("transform_publish_period", 0.05))
        self.throttle_scans = int(self.declare_parameter("throttle_scans", 1))
        self.scan_topic = self.declare_parameter("scan_topic", "scan")
        self.mode = self.declare_parameter("mode", "gmapping")
        gm_values = {f.name: self.declare_parameter(f.name, f.default) for f in fields(GMappingParams)}
        if self.mode == "gmapping":
            self.params: Any = GMappingParams.from_dict(gm_values)
            self.slam: Any = GMapping(self.params, rng=self.rng)
        elif self.mode == "graph":
            graph_values = {
                f.name: self.declare_parameter(f"graph.{f.name}", f.default) for f in fields(GraphSlamParams)
            }
            self.params = GraphSlamParams.from_dict(graph_values)
            self.gm = GMappingParams.from_dict(gm_values)  # update gating and map parameters
            self.slam = GraphSlam(self.params)
        else:
            raise MappingError(f"node {self.fully_qualified_name}: parameter 'mode' is {self.mode!r}, "
                               "expected 'gmapping' or 'graph'")  # fmt: skip
        self.check_parameters()

        self.map_pub = self.create_publisher(msgs.OccupancyGrid, "map", 1, latched=True)
        self.meta_pub = self.create_publisher(msgs.MapMetaData, "map_metadata", 1, latched=True)
        self.path_pub = self.create_publisher(msgs.Path, "trajectory", 1, latched=True)
        self.create_subscription(msgs.LaserScan, self.scan_topic, self._on_scan, 5)
        self.create_timer(self.transform_publish_period, self._publish_tf)
        self.map_to_odom = np.zeros(3)
        self.grid: GridMap | None = None
        self.scans_received = 0
        self.scans_processed = 0
        self._laser_in_base: dict[str, np.ndarray] = {}
        self._stamps: list[int] = []
        self._graph_scans: list[tuple[np.ndarray, np.ndarray]] = []
        self._last_map_ns: int | None = None
        self._last_processed: tuple[np.ndarray, int] | None = None
        self._max_range = 0.0

    # --- inputs ---------------------------------------------------------------------------------

    def _laser_pose(self, frame: str) -> np.ndarray | None:
        if frame not in self._laser_in_base:
            try:
                self._laser_in_base[frame] = np.array(self.executor.tf.lookup_pose2d(self.base_frame, frame))
            except TfError as exc:
                self.get_logger().warning(f"no transform {self.base_frame} → {frame}: {exc}")
                return None
        return self._laser_in_base[frame]

    def _odom(self, t_ns: int) -> np.ndarray | None:
        err: Exception | None = None
        for t in (t_ns, None):
            try:
                return np.array(self.executor.tf.lookup_pose2d(self.odom_frame, self.base_frame, t))
            except TfError as exc:
                err = exc
        # Before the first processed scan this is the start-up order (a scan ahead of the first odometry),
        # which slam_gmapping's tf message filter drops silently.
        log = self.get_logger().warning if self.scans_processed else self.get_logger().debug
        log(f"no odometry {self.odom_frame} → {self.base_frame}: {err}")
        return None

    def _due(self, odom_laser: np.ndarray, t_ns: int) -> bool:
        """Graph mode: process like gmapping, after linearUpdate / angularUpdate / temporalUpdate."""
        if self._last_processed is None:
            return True
        gm = self.gm
        moved = between2(self._last_processed[0], odom_laser)
        dt = (t_ns - self._last_processed[1]) * 1e-9
        return (
            math.hypot(moved[0], moved[1]) >= gm.linearUpdate
            or abs(moved[2]) >= gm.angularUpdate
            or (gm.temporalUpdate >= 0 and dt > gm.temporalUpdate)
        )

    def _on_scan(self, msg: Any) -> None:
        self.scans_received += 1
        if (self.scans_received - 1) % max(self.throttle_scans, 1):
            return
        t_ns = msgs.stamp_ns(msg)
        laser = self._laser_pose(str(msg.header.frame_id).lstrip("/") or self.base_frame)
        odom = self._odom(t_ns)
        if laser is None or odom is None:
            return
        odom_laser = compose2(odom, laser)
        r = np.asarray(msg.ranges, dtype=np.float64).copy()
        rmax = float(msg.range_max)
        # slam_gmapping: readings below range_min count as range_max; non-finite readings are no returns
        r[~np.isfinite(r) | (r < float(msg.range_min))] = rmax
        if self.mode == "gmapping":
            if self.params.maxRange <= 0:
                self.params.maxRange = rmax - 0.01
                self.params.maxUrange = min(self.params.maxUrange, self.params.maxRange)
            before = self.slam.updates
            pose = self.slam.add_scan(
                r, float(msg.angle_min), float(msg.angle_increment), odom_laser, stamp=t_ns * 1e-9
            )
            if self.slam.updates == before and self.scans_processed > 0:
                return
            self._stamps.append(t_ns)
        else:
            if not self._due(odom_laser, t_ns):
                return
            self._last_processed = (odom_laser, t_ns)
            ranges = np.where(r >= rmax - 0.01, np.inf, r)
            pose = self.slam.add_scan(ranges, float(msg.angle_min), float(msg.angle_increment), odom_laser)
            self._graph_scans.append((ranges, float(msg.angle_min) + float(msg.angle_increment) * np.arange(len(r))))
            self._stamps.append(t_ns)
            self._max_range = rmax
        self.scans_processed += 1
        # map_T_odom = map_T_laser ∘ (odom_T_laser)^-1
        self.map_to_odom = compose2(pose, inverse2(odom_laser))
        self._publish_tf()
        if self._last_map_ns is None or (t_ns - self._last_map_ns) * 1e-9 >= self.map_update_interval:
            self._last_map_ns = t_ns
            self.publish_map(t_ns)

    # --- outputs --------------------------------------------------------------------------------

    def _publish_tf(self) -> None:
        stamp = self.get_clock().now_ns() + int(self.transform_publish_period * 1e9)
        x, y, yaw = self.map_to_odom
        self.send_transform(msgs.transform_stamped(stamp, self.map_frame, self.odom_frame, x, y, yaw))

    def current_map(self) -> GridMap | None:
        """The map now: the best particle's (gmapping) or one built at the graph's poses (graph)."""
        if self.mode == "gmapping":
            return self.slam.map(frame_id=self.map_frame) if self.slam.particles else None
        if not self._graph_scans:
            return None
        return build_map(
            self.slam.poses, self._graph_scans, resolution=self.gm.delta,
            max_urange=min(self.gm.maxUrange, self._max_range), max_range=self._max_range, frame_id=self.map_frame,
        )  # fmt: skip

    def trajectory(self) -> list[tuple[int, np.ndarray]]:
        """(stamp ns, laser pose in the map frame) of every processed scan along the best trajectory."""
        if self.mode == "gmapping":
            traj = self.slam.trajectory()
            return [(self._stamps[i], traj[k]) for i, k in enumerate(sorted(traj)) if i < len(self._stamps)]
        return list(zip(self._stamps, self.slam.poses, strict=True))

    def publish_map(self, stamp_ns: int | None = None) -> None:
        """Publish ``map``, ``map_metadata`` and ``trajectory`` now."""
        stamp = self.get_clock().now_ns() if stamp_ns is None else stamp_ns
        grid = self.current_map()
        if grid is None:
            return
        self.grid = grid
        msg = grid.to_msg(stamp)
        self.map_pub.publish(msg)
        self.meta_pub.publish(msg.info)
        poses = [msgs.pose_stamped(t, self.map_frame, *p) for t, p in self.trajectory()]
        self.path_pub.publish(msgs.Path(header=msgs.header(stamp, self.map_frame), poses=poses))
