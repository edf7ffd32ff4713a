"""costmap_2d's ``Costmap2DROS``: a ``LayeredCostmap`` fed from topics and tf inside a node (move_base).

It subscribes the static layer's ``map`` topic and each observation source's ``LaserScan`` topic, keeps
the newest scan of each source (``observation_persistence`` 0, as ROS's default), and at
``update_frequency`` (simulated time) applies them, re-centres a rolling window and lets the layers write
the master grid. At ``publish_frequency`` it publishes ``<name>/costmap`` (``nav_msgs/OccupancyGrid`` with
costmap_2d's cost translation) and ``<name>/footprint`` (``geometry_msgs/PolygonStamped``).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Node, TfError
from navlab.geometry import compose2, transform_points2
from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid, GridMap
from navlab.navigation.costmap.layered import LayeredCostmap
from navlab.navigation.costmap.obstacle_layer import ObstacleLayer
from navlab.navigation.costmap_sensors import CostmapSensorFeeds
from navlab.navigation.scan_points import ScanPoints


def cost_translation() -> np.ndarray:
    """costmap_2d_publisher's table: cost (0..255) -> OccupancyGrid value (0..100, -1)."""
    table = np.zeros(256, dtype=np.int8)
    table[1:253] = 1 + (97 * (np.arange(1, 253) - 1)) // 251
    table[COST_INSCRIBED], table[COST_LETHAL], table[COST_UNKNOWN] = 99, 100, -1
    return table


class Costmap2DROS:
    """A costmap named ``name`` (``global_costmap``, ``local_costmap``) living in ``node``.

    ``params``: the costmap's ROS parameters (``costmap_common_params.yaml`` merged with its own file);
    ``topic_prefix``: where ``costmap`` and ``footprint`` are published (default ``name``; move_base uses
    ``/move_base/global_costmap``); ``scan_points``: a ``ScanPoints`` shared with other costmaps of the node (each
    scan's laser-frame points are then worked out once).
    """

    def __init__(
        self,
        node: Node,
        name: str,
        params: dict[str, Any],
        *,
        topic_prefix: str | None = None,
        scan_points: ScanPoints | None = None,
    ) -> None:
        self.node, self.name = node, name
        self.scan_points = scan_points or ScanPoints()  # move_base shares one between its two costmaps
        prefix = topic_prefix if topic_prefix is not None else name
        self.layered = LayeredCostmap(params)
        p = self.layered.params
        self.global_frame = p.global_frame.lstrip("/")
        self.base_frame = p.robot_base_frame.lstrip("/")
        self.updated_ns: int | None = None
        self.updates = 0
        self._table = cost_translation()
        self._pending: dict[str, Any] = {}
        self._sensor_in_base: dict[str, tuple[float, float, float]] = {}
        statics = self.layered.map_layers
        if statics:
            node.create_subscription(msgs.OccupancyGrid, statics[0].map_topic, self._on_map, 1)
        self.feeds = CostmapSensorFeeds(node, name, self.global_frame, self.layered.layers, prefix=prefix)
        for src_name, src in p.sources.items():
            if src_name in self.feeds.sources:
                continue
            if src.data_type != "LaserScan":
                node.get_logger().warning(
                    f"{name}: observation source {src_name} has data_type {src.data_type}; "
                    "navlab's sensors are LaserScan only, it is ignored"
                )
                continue
            topic = src.topic or src_name
            node.create_subscription(msgs.LaserScan, topic, functools.partial(self._on_scan, src_name), 5)
        self.costmap_pub = node.create_publisher(msgs.OccupancyGrid, f"{prefix}/costmap", 1, latched=True)
        self.footprint_pub = node.create_publisher(msgs.PolygonStamped, f"{prefix}/footprint", 1)
        if p.update_frequency > 0:
            node.create_timer(1.0 / p.update_frequency, self._on_update_timer)
        if p.publish_frequency > 0:  # as costmap_2d's publisher: no work while nobody subscribes (or listens)
            node.create_timer(
                1.0 / p.publish_frequency, self.publish, idle=self._unwatched, idle_until_graph_changes=True
            )

    @property
    def costmap(self) -> Grid:
        """The master grid (uint8 costs) in ``global_frame``."""
        return self.layered.costmap

    # --- inputs -----------------------------------------------------------------------------------

    def _on_map(self, msg: Any) -> None:
        grid = GridMap.from_msg(msg)
        map_frame = grid.frame_id.lstrip("/") or "map"
        if map_frame == self.global_frame:
            in_costmap = (0.0, 0.0, 0.0)
        else:
            try:
                in_costmap = self.node.executor.tf.lookup_pose2d(self.global_frame, map_frame)
            except TfError as exc:
                self.node.get_logger().warning(f"{self.name}: cannot place map frame {map_frame}: {exc}")
                return
        self.layered.set_map(grid, map_in_costmap=in_costmap)

    def robot_pose(self, t_ns: int | None = None) -> tuple[float, float, float] | None:
        """The robot in ``global_frame`` (x, y, yaw), or None without tf."""
        try:
            return self.node.executor.tf.lookup_pose2d(self.global_frame, self.base_frame, t_ns)
        except TfError:
            return None

    def _apply_scan(self, source: str, msg: Any) -> None:
        frame = str(msg.header.frame_id).lstrip("/")
        tf = self.node.executor.tf
        if frame not in self._sensor_in_base:
            try:
                self._sensor_in_base[frame] = tf.lookup_pose2d(self.base_frame, frame)
            except TfError as exc:
                self.node.get_logger().warning(f"{self.name}: no transform {self.base_frame} -> {frame}: {exc}")
                return
        try:  # the robot at the scan's stamp, else the latest (a scan stamped after the newest odometry)
            base = tf.lookup_pose2d_or_latest(self.global_frame, self.base_frame, msgs.stamp_ns(msg))
        except TfError:
            return
        sensor = compose2(base, self._sensor_in_base[frame])
        src = self.layered.params.sources[source]
        # rays without a return clear out to raytrace_range (inf_is_valid), others end at their return
        clear_to = src.raytrace_range if src.inf_is_valid else float(msg.range_max)
        world: tuple[np.ndarray, np.ndarray] | None = None
        for layer in self.layered.scan_targets(source):
            if isinstance(layer, ObstacleLayer):  # the whole observation in one compiled call
                limits = (float(msg.range_min), float(msg.range_max), clear_to)
                layer.add_ranges(sensor, np.asarray(msg.ranges), self.scan_points.beams(msg), limits, source=source)
                continue
            if world is None:  # any other ScanLayer plugin takes the endpoints
                pts, valid = self.scan_points.points(msg, clear_to)
                world = (transform_points2(sensor, pts), valid)
            layer.add_scan(sensor[:2], *world, source=source)

    def _on_scan(self, source: str, msg: Any) -> None:
        """Keep the newest scan of each observation source for the next update."""
        self._pending[source] = msg

    # --- update, publish, clear --------------------------------------------------------------------

    def _on_update_timer(self) -> None:
        self.update(write=False)

    def update(self, *, write: bool = True) -> Grid | None:
        """One costmap update now (the timer's job); returns the master grid, or None without a robot pose.

        ``write`` False (the timer): the master is written when it is next read (``costmap``;
        ``LayeredCostmap.update_map``'s ``defer``) and the grid returned may not be written yet: a global costmap
        updated five times a second and planned on once a second is written about twice a second."""
        pose = self.robot_pose()
        if pose is None:
            return None
        for source, msg in list(self._pending.items()):
            self._apply_scan(source, msg)
        self._pending.clear()
        self.feeds.apply()
        grid = self.layered.update_map(pose, defer=not write)
        self.updated_ns = self.node.executor.now_ns
        self.updates += 1
        return grid

    def _unwatched(self) -> bool:
        """Whether nobody subscribes to the costmap topic and no listener sees every message (the publish timer then
        parks until one does; costmap_2d's ``publishCostmap`` returns at once without subscribers)."""
        return not (self.costmap_pub.get_subscription_count() or self.node.executor.has_listeners)

    def publish(self) -> None:
        """Publish the costmap (OccupancyGrid) and the footprint polygon now."""
        now = self.node.executor.now_ns
        g = self.costmap
        occ = GridMap(self._table[g.data], g.resolution, g.origin, self.global_frame)
        self.costmap_pub.publish(occ.to_msg(now))
        if not (self.footprint_pub.get_subscription_count() or self.node.executor.has_listeners):
            return  # the polygon (not latched) only when someone reads it
        pose = self.layered.robot_pose or self.robot_pose()
        if pose is not None:
            poly = self.layered.footprint_at(pose)
            self.footprint_pub.publish(
                msgs.PolygonStamped(
                    header=msgs.header(now, self.global_frame),
                    polygon=msgs.Polygon(points=[msgs.Point32(x=float(x), y=float(y), z=0.0) for x, y in poly]),
                )
            )

    def clear(self) -> None:
        """Forget every observation (the ``clear_costmaps`` service)."""
        self.layered.reset()
        if self.layered.robot_pose is not None:
            self.layered.update_map(self.layered.robot_pose)

    def clear_outside(self, size: float) -> None:
        """ClearCostmapRecovery: obstacle layers forget what lies outside a ``size`` x ``size`` m square
        around the robot (ROS's conservative and aggressive resets)."""
        pose = self.layered.robot_pose or self.robot_pose()
        if pose is None:
            return
        for layer in self.layered.scan_layers:
            layer.clear_outside(pose[:2], size)
        for cloud_layer in self.feeds.voxel:
            cloud_layer.clear_outside(pose[:2], size)
        self.layered.update_map(pose)

    def cost_at(self, xy: tuple[float, float]) -> int:
        """The cost of the cell under ``xy`` (``global_frame``); unknown outside the grid."""
        return int(self.costmap.value_at(np.array([xy]), outside=COST_UNKNOWN)[0])

    def footprint_cost(self, pose: tuple[float, float, float]) -> int:
        """The highest cost under the robot's footprint at ``pose``."""
        g = self.costmap
        ij = self.layered.footprint.cells(g, pose)
        if len(ij) == 0:
            return COST_UNKNOWN
        return int(g.data[ij[:, 1], ij[:, 0]].max())

    def is_stale(self, max_age_s: float) -> bool:
        """Whether the last update is older than ``max_age_s`` simulated s (or never happened)."""
        if self.updated_ns is None:
            return True
        return (self.node.executor.now_ns - self.updated_ns) / 1e9 > max_age_s
