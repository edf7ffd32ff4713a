"""The exploration node (explore_lite's role): drive to frontiers of ``/map`` until none is reachable."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.drivers.frontiers import FrontierSearch, plan_to_frontier, prepare_frontier_search
from navlab.grid import GridMap
from navlab.navigation import PurePursuit


class Explore(Node):
    """Frontier exploration on the SLAM map, with a pure-pursuit follower that stops for obstacles.

    Subscribes ``map`` and ``scan``; tf ``global_frame``→``robot_base_frame``. Publishes ``cmd_vel``
    and the current plan on ``explore/plan``. ``done`` is True once no reachable frontier remains
    (checked ``done_checks`` times in a row, so a map still being updated is not mistaken for done).
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "explore",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.listen_tf()  # a tf2 TransformListener, as in ROS: the graph shows it reading /tf
        self.global_frame = self.declare_parameter("global_frame", "map")
        self.base_frame = self.declare_parameter("robot_base_frame", "chassis")
        self.robot_radius = self.declare_parameter("robot_radius", 0.3)
        # explore_lite's min_frontier_size is in metres (0.75); frontiers shorter than that are ignored
        self.min_frontier_size = self.declare_parameter("min_frontier_size", 0.75)
        self.planner_frequency = self.declare_parameter("planner_frequency", 0.5)
        self.max_v = self.declare_parameter("max_vel_x", 0.35)
        self.max_w = self.declare_parameter("max_vel_theta", 1.2)
        self.progress_timeout = self.declare_parameter("progress_timeout", 20.0)
        self.done_checks = self.declare_parameter("done_checks", 3)
        self.follower = PurePursuit(max_vel_x=self.max_v, max_vel_theta=self.max_w, xy_goal_tolerance=0.0)
        self.done = False
        self.grid: GridMap | None = None
        self.path: np.ndarray | None = None
        self.blacklist: list[np.ndarray] = []
        self._front_range = math.inf
        self._sectors: tuple[tuple[float, float, int], np.ndarray, np.ndarray] | None = None  # beam indices
        self._rear_range = math.inf
        self._scan: Any = None  # the latest scan, and the one the ranges above come from
        self._ranges_of: Any = None
        self._no_frontier = 0
        self._search: tuple[GridMap, FrontierSearch] | None = None  # the last map's pose-independent planning
        self._last_progress = (0, math.inf)  # (time ns, distance to goal)
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self.plan_pub = self.create_publisher(msgs.Path, "explore/plan", 1)
        self.create_subscription(msgs.OccupancyGrid, "map", self._on_map, 1)
        self.create_subscription(msgs.LaserScan, "scan", self._on_scan, 1)
        self.create_timer(1.0 / self.planner_frequency, self._replan)
        self.create_timer(0.1, self._control)

    def _on_map(self, msg: Any) -> None:
        self.grid = GridMap.from_msg(msg)

    def _on_scan(self, msg: Any) -> None:
        self._scan = msg  # read by the next control cycle (10 Hz), not at the scan rate (40 Hz)

    def _update_ranges(self) -> None:
        """Nearest readings ahead and behind, from the latest scan (once per scan)."""
        msg = self._scan
        if msg is None or msg is self._ranges_of:
            return
        self._ranges_of = msg
        key = (float(msg.angle_min), float(msg.angle_increment), len(msg.ranges))
        if self._sectors is None or self._sectors[0] != key:  # the beams ahead and behind, once per scan layout
            a = msg.angle_min + msg.angle_increment * np.arange(len(msg.ranges))
            rel = np.abs(np.arctan2(np.sin(a), np.cos(a)))
            self._sectors = (key, np.flatnonzero(rel < 0.5), np.flatnonzero(rel > math.pi - 0.6))
        self._front_range = self._nearest(msg, self._sectors[1])
        self._rear_range = self._nearest(msg, self._sectors[2])

    @staticmethod
    def _nearest(msg: Any, beams: np.ndarray) -> float:
        """The nearest valid reading (m) among ``beams`` of a scan, inf if none."""
        r = np.asarray(msg.ranges)[beams].astype(np.float64)
        r = r[np.isfinite(r) & (r >= msg.range_min)]
        return float(r.min()) if len(r) else math.inf

    def _pose(self) -> tuple[float, float, float] | None:
        try:
            return self.executor.tf.lookup_pose2d(self.global_frame, self.base_frame)
        except TfError:
            return None

    def _replan(self) -> None:
        pose = self._pose()
        if self.grid is None or pose is None or self.done:
            return
        min_cells = max(1, round(self.min_frontier_size / self.grid.resolution))
        if self._search is None or self._search[0] is not self.grid:  # a new map since the last plan
            search = prepare_frontier_search(self.grid, robot_radius=self.robot_radius, min_frontier_cells=min_cells)
            self._search = (self.grid, search)
        path = plan_to_frontier(
            self.grid,
            pose[:2],
            robot_radius=self.robot_radius,
            min_frontier_cells=min_cells,
            blacklist=self.blacklist,
            prepared=self._search[1],
        )
        if path is None:
            self._no_frontier += 1
            self.path = None
            if self._no_frontier >= self.done_checks:
                self.done = True
                self.pub.publish(msgs.twist(0.0, 0.0))
                self.get_logger().info("exploration finished: no reachable frontier left")
            return
        self._no_frontier = 0
        goal_changed = self.path is None or np.hypot(*(self.path[-1] - path[-1])) > 0.3
        self.path = path
        self.follower.set_plan(path)
        if goal_changed:
            self._last_progress = (self.executor.now_ns, math.inf)
        if self.plan_pub.get_subscription_count() or self.executor.has_listeners:  # built only for a reader
            now = self.executor.now_ns
            self.plan_pub.publish(msgs.path(now, self.global_frame, path[::4]))

    def _control(self) -> None:
        if self.done or self.path is None:
            if not self.done:
                self.pub.publish(msgs.twist(0.0, 0.0))
            return
        pose = self._pose()
        if pose is None:
            return
        remaining = float(np.hypot(*(self.path[-1] - pose[:2])))
        now = self.executor.now_ns
        t_best, d_best = self._last_progress
        if remaining < d_best - 0.05:
            self._last_progress = (now, remaining)
        elif now - t_best > self.progress_timeout * 1e9:  # stuck: give up on this frontier
            self.blacklist.append(self.path[-1].copy())
            self.path = None
            return
        if remaining < 0.15:
            # Reached: what is left of this frontier could not be seen from here; look elsewhere next.
            self.blacklist.append(self.path[-1].copy())
            self.path = None
            self.pub.publish(msgs.twist(0.0, 0.0))
            return
        self._update_ranges()
        self.follower.min_front_range = self._front_range
        v, w = self.follower.compute_velocity(pose)
        if v == 0.0 and self._front_range < 0.35 and self._rear_range > 0.4:
            v = -0.1  # blocked ahead: back off while turning toward the path
        self.pub.publish(msgs.twist(v, w))
