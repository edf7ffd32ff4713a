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

from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.geometry import compose2, inverse2
from navlab.grid import GridMap
from navlab.mapping.errors import MappingError
from navlab.plugins import PluginContext, PluginError, SlamBackend, load_plugin

# slam_gmapping parameters that must be > 0 or >= 0, and (min, max) pairs (refused, not run with)
_POSITIVE = (
    "transform_publish_period",
    "throttle_scans",
    "maxUrange",
    "sigma",
    "lstep",
    "astep",
    "lsigma",
    "ogain",
    "particles",
    "delta",
    "llsamplerange",
    "llsamplestep",
    "lasamplerange",
    "lasamplestep",
    "occ_thresh",
    "resampleThreshold",
)
_NON_NEGATIVE = (
    "map_update_interval",
    "maxRange",
    "kernelSize",
    "iterations",
    "lskip",
    "minimumScore",
    "srr",
    "srt",
    "str",
    "stt",
    "linearUpdate",
    "angularUpdate",
    "wideScore",
    "wideStep",
    "wideTurn",
    "wideSkip",
    "refineSigma",
)


INVALID_LOG_PERIOD_NS = 10_000_000_000  # at most one "scans without readings" warning per 10 simulated s


def _check_values(node: str, values: dict[str, Any]) -> None:
    """Refuse non-finite numbers, non-positive sizes and rates, negative gates and xmin >= xmax / ymin >= ymax."""
    for key, v in values.items():
        if isinstance(v, float) and not np.isfinite(v):
            raise MappingError(f"node {node}: parameter {key!r}: expected a finite number, got {v!r}")
        if isinstance(v, int | float) and not isinstance(v, bool):
            if key in _POSITIVE and v <= 0:
                raise MappingError(f"node {node}: parameter {key!r}: expected > 0, got {v!r}")
            if key in _NON_NEGATIVE and v < 0:
                raise MappingError(f"node {node}: parameter {key!r}: expected >= 0, got {v!r}")
    for lo, hi in (("xmin", "xmax"), ("ymin", "ymax")):
        if lo in values and hi in values and not values[lo] < values[hi]:
            raise MappingError(f"node {node}: parameters {lo}={values[lo]}, {hi}={values[hi]}: expected {lo} < {hi}")


class SlamGMapping(Node):
    """slam_gmapping: the ``mode``'s SLAM backend (a ``SlamBackend`` plugin) driven by scans and tf odometry."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "slam_gmapping",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.listen_tf()  # a tf2 TransformListener, as in ROS: the graph shows it reading /tf
        self.base_frame = self.declare_parameter("base_frame", "base_link")
        self.odom_frame = self.declare_parameter("odom_frame", "odom")
        self.map_frame = self.declare_parameter("map_frame", "map")
        self.map_update_interval = float(self.declare_parameter("map_update_interval", 5.0))
        self.transform_publish_period = float(self.declare_parameter("transform_publish_period", 0.05))
        self.throttle_scans = int(self.declare_parameter("throttle_scans", 1))
        self.scan_topic = self.declare_parameter("scan_topic", "scan")
        self.mode = self.declare_parameter("mode", "gmapping")
        try:
            backend = load_plugin("slam_backend", self.mode, param="mode")
        except PluginError as exc:
            raise MappingError(f"node {self.fully_qualified_name}: {exc}") from None
        values = self.declare_parameters(backend.parameters())
        _check_values(
            self.fully_qualified_name,
            {
                "map_update_interval": self.map_update_interval,
                "transform_publish_period": self.transform_publish_period,
                "throttle_scans": self.throttle_scans,
                **values,
            },
        )
        self.slam: SlamBackend = backend.from_params(values, context=PluginContext(name=self.mode, rng=self.rng))
        inner: Any = getattr(self.slam, "slam", None)
        if inner is not None and hasattr(inner, "keep_history"):  # a live node never calls finish(): no per-scan
            inner.keep_history = False  # history (it grew the process by ~45 MB per simulated hour)
        self.params = self.slam.params
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
        self.scans_invalid = 0  # scans without one reading in [range_min, range_max) (all inf/NaN: sees nothing)
        self._invalid_logged_ns: int | None = None
        self._stamps: list[int] = []  # stamp (ns) of each processed scan
        self._last_map_ns: int | None = None

    # --- inputs ---------------------------------------------------------------------------------

    def _odom_laser(self, msg: Any) -> np.ndarray | None:
        """The laser's pose in the odom frame at the scan's stamp, or the latest one (tf odom→base ∘ base→laser),
        or None."""
        laser = self.scan_sensor_pose(self.base_frame, msg)
        if laser is None:
            return None
        stamp = msgs.stamp_ns(msg)
        # A scan stamped now (as live) is level with or ahead of the newest odometry, where the lookup at its
        # stamp gives the latest transform or fails over to it: ask for the latest at once, not via a TfError.
        at = None if stamp >= self.get_clock().now_ns() else stamp
        try:
            odom = self.pose_at(self.odom_frame, self.base_frame, at)
        except TfError as exc:
            # Before the first processed scan this is the start-up order (a scan ahead of the first odometry),
            # which slam_gmapping's tf message filter drops silently.
            log = self.get_logger().warning if self.scans_processed else self.get_logger().debug
            log(f"no odometry {self.odom_frame} → {self.base_frame}: {exc}")
            return None
        return compose2(odom, laser)

    def _count_invalid(self, t_ns: int) -> None:
        """Count a scan without one reading in [range_min, range_max) and say so, at most every 10 s."""
        self.scans_invalid += 1
        if self._invalid_logged_ns is None or t_ns - self._invalid_logged_ns >= INVALID_LOG_PERIOD_NS:
            self._invalid_logged_ns = t_ns
            self.get_logger().warning(
                f"scan on {self.resolve_topic_name(self.scan_topic)} has no valid reading (all beyond range or "
                f"not finite): {self.scans_invalid} of {self.scans_received} scans so far; the map stays empty "
                "where the lidar sees nothing"
            )

    def _on_scan(self, msg: Any) -> None:
        self.scans_received += 1
        t_ns = msgs.stamp_ns(msg)
        ranges = np.asarray(msg.ranges, dtype=np.float64)
        returned = ranges >= float(msg.range_min)  # False for NaN and -inf (numpy compares NaN without a warning)
        if not np.count_nonzero(returned & (ranges < float(msg.range_max))):  # (np.any costs 3x as much)
            self._count_invalid(t_ns)
        if (self.scans_received - 1) % max(self.throttle_scans, 1):
            return
        odom_laser = self._odom_laser(msg)
        if odom_laser is None or not self.slam.due(odom_laser, t_ns):
            return
        # slam_gmapping: readings below range_min count as no return, like non-finite ones (+inf stays inf)
        r = np.where(returned, ranges, np.inf)
        pose = self.slam.add_scan(
            r,
            float(msg.angle_min),
            float(msg.angle_increment),
            odom_laser,
            range_max=float(msg.range_max),
            stamp_ns=t_ns,
        )
        if pose is None:
            return
        self._stamps.append(t_ns)
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
        """The map now (the backend's: gmapping's best particle's, or one built at the graph's poses)."""
        return self.slam.current_map(frame_id=self.map_frame)

    def trajectory(self) -> list[tuple[int, np.ndarray]]:
        """(stamp ns, laser pose in the map frame) of every processed scan along the best trajectory."""
        return list(zip(self._stamps, self.slam.trajectory(), strict=False))

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
