"""The ``amcl`` node: ROS 1 amcl's topics, frames, parameters and services around ``localization.amcl``.

Subscribes ``scan`` (sensor_msgs/LaserScan), ``map`` (nav_msgs/OccupancyGrid, latched) and
``initialpose`` (PoseWithCovarianceStamped); reads odometry from tf ``odom_frame_id → base_frame_id``
at each scan's stamp. Publishes tf ``global_frame_id → odom_frame_id`` stamped scan time +
``transform_tolerance``, ``amcl_pose`` (PoseWithCovarianceStamped) and ``particlecloud`` (PoseArray).
Services: ``global_localization`` and ``request_nomotion_update`` (std_srvs/Empty: request ignored).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError, dataclass_parameters
from navlab.geometry import Tf
from navlab.grid import GridError, GridMap
from navlab.localization import amcl as pf
from navlab.localization.errors import LocalizationError
from navlab.localization.field import field_from_map

# Nav2's spellings of ROS 1 amcl's parameters (the names and defaults themselves are AmclParams' fields).
NAV2_ALIASES: dict[str, tuple[str, ...]] = {
    "kld_err": ("pf_err",),
    "kld_z": ("pf_z",),
    "laser_max_beams": ("max_beams",),
    "laser_z_hit": ("z_hit",),
    "laser_z_short": ("z_short",),
    "laser_z_max": ("z_max",),
    "laser_z_rand": ("z_rand",),
    "laser_sigma_hit": ("sigma_hit",),
    "laser_lambda_short": ("lambda_short",),
    "odom_model_type": ("robot_model_type",),
    "odom_alpha1": ("alpha1",),
    "odom_alpha2": ("alpha2",),
    "odom_alpha3": ("alpha3",),
    "odom_alpha4": ("alpha4",),
}


class Amcl(Node):
    """Adaptive Monte Carlo localization on the map from ``map``, with ROS 1 amcl's interface."""

    def __init__(
        self, executor: Executor, *, name: str = "amcl", parameters: dict[str, Any] | None = None, namespace: str = ""
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.listen_tf()  # a tf2 TransformListener, as in ROS: the graph shows it reading /tf
        values = self.declare_parameters(dataclass_parameters(pf.AmclParams), aliases=NAV2_ALIASES)
        self.params = pf.AmclParams(**values)
        self.params.validate()
        self.odom_alpha5 = self.declare_parameter("odom_alpha5", 0.2, aliases=("alpha5",))  # omni model only
        self.transform_tolerance = self.declare_parameter("transform_tolerance", 0.1)
        for pname, value in (("odom_alpha5", self.odom_alpha5), ("transform_tolerance", self.transform_tolerance)):
            if not 0 <= value < float("inf"):
                raise LocalizationError(
                    f"node {self.fully_qualified_name}: parameter {pname}: expected a finite number >= 0, got {value!r}"
                )
        self.initial_pose = (
            self.declare_parameter("initial_pose_x", 0.0),
            self.declare_parameter("initial_pose_y", 0.0),
            self.declare_parameter("initial_pose_a", 0.0),
        )
        self.odom_frame = self.declare_parameter("odom_frame_id", "odom")
        self.base_frame = self.declare_parameter("base_frame_id", "base_link")
        self.global_frame = self.declare_parameter("global_frame_id", "map")
        self.tf_broadcast = self.declare_parameter("tf_broadcast", True)
        self.first_map_only = self.declare_parameter("first_map_only", False)
        # navlab always reads the latched map topic (what map_server's static_map service would return).
        self.declare_parameter("use_map_topic", False)
        for pname, default in (("gui_publish_rate", -1.0), ("save_pose_rate", 0.5)):  # read, not used
            if not abs(self.declare_parameter(pname, default)) < float("inf"):
                raise LocalizationError(
                    f"node {self.fully_qualified_name}: parameter {pname}: expected a finite number (<= 0: off)"
                )
        self.check_parameters()

        self.filter: pf.Amcl | None = None
        self.scans_received = 0
        self.scans_invalid = 0  # scans without one reading in [range_min, range_max)
        self._invalid_logged_ns: int | None = None
        self.last_error: str | None = None
        self._map_to_odom: tuple[float, float, float] | None = None
        self._tf_body: tuple[tuple[float, float, float], Tf] | None = None  # (map->odom, as its Transform message)
        self._pending_global = False
        self._odom_failures = 0
        self.pose_pub = self.create_publisher(msgs.PoseWithCovarianceStamped, "amcl_pose", 2)
        self.cloud_pub = self.create_publisher(msgs.PoseArray, "particlecloud", 2)
        self.create_subscription(msgs.OccupancyGrid, "map", self._on_map, 1)
        self.create_subscription(msgs.LaserScan, "scan", self._on_scan, 100)
        self.create_subscription(msgs.PoseWithCovarianceStamped, "initialpose", self._on_initial_pose, 2)
        self.create_service("global_localization", self._srv_global)
        self.create_service("request_nomotion_update", self._srv_nomotion)

    # --- inputs ---------------------------------------------------------------------------------

    def _refuse(self, message: str) -> None:
        self.last_error = message
        self.get_logger().error(message)

    def _on_map(self, msg: Any) -> None:
        if self.filter is not None and self.first_map_only:
            return
        topic = self.resolve_topic_name("map")
        try:  # a malformed OccupancyGrid (cells vs width x height, resolution, origin, values) is refused
            grid = GridMap.from_msg(msg)
            field = field_from_map(grid, max_dist=self.params.laser_likelihood_max_dist, name=f"map on {topic}")
        except GridError as exc:
            self._refuse(f"ignoring map on {topic}: {exc}")
            return
        except LocalizationError as exc:
            self._refuse(f"ignoring map: {exc}")
            return
        previous = self.filter
        self.filter = pf.Amcl(field, self.params, rng=self.rng)
        self._map_to_odom = None
        if self._pending_global:
            self.filter.global_localization()
            self._pending_global = False
            return
        # ROS amcl keeps its last estimate across maps; otherwise it starts from initial_pose_*.
        x, y, a = previous.estimate if previous is not None and previous.n_particles else self.initial_pose
        try:
            self.filter.set_initial_pose(x, y, a)
        except LocalizationError as exc:
            self._refuse(f"initial pose refused: {exc}; waiting for initialpose or global_localization")

    def _on_initial_pose(self, msg: Any) -> None:
        frame = str(msg.header.frame_id).lstrip("/")
        if frame and frame != self.global_frame:
            self._refuse(f"ignoring initialpose in frame {frame!r}: expected {self.global_frame!r}")
            return
        if self.filter is None:
            self._refuse("ignoring initialpose: no map received yet")
            return
        x, y, yaw = msgs.pose2d(msg.pose.pose)
        c = np.asarray(msg.pose.covariance, dtype=np.float64).reshape(6, 6)
        cov = np.array([[c[0, 0], c[0, 1], 0.0], [c[1, 0], c[1, 1], 0.0], [0.0, 0.0, c[5, 5]]])
        try:
            self.filter.set_initial_pose(x, y, yaw, cov)
        except LocalizationError as exc:
            self._refuse(f"ignoring initialpose: {exc}")
            return
        self._map_to_odom = None
        self.get_logger().info(f"initial pose set to ({x:.3f}, {y:.3f}, {yaw:.3f})")

    def _srv_global(self, request: Any = None) -> dict[str, Any]:
        if self.filter is None:
            self._pending_global = True
        else:
            self.filter.global_localization()
            self._map_to_odom = None
        return {}

    def _srv_nomotion(self, request: Any = None) -> dict[str, Any]:
        if self.filter is not None:
            self.filter.request_nomotion_update()
        return {}

    def _poses(self, msg: Any, t_ns: int) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
        """(odometry pose at the scan's stamp ``t_ns``, laser pose in the base frame), or None (logged) if tf lacks
        one."""
        laser = self.scan_sensor_pose(self.base_frame, msg)
        if laser is None:
            return None
        try:  # Node.pose_at without its listen_tf (this node listens from the start)
            odom = self.executor.tf.lookup_pose2d_or_latest(self.odom_frame, self.base_frame, t_ns)
        except TfError as exc:
            # Expected for the first scans before odometry arrives (debug); a warning when it persists.
            self._odom_failures += 1
            log = self.get_logger().warning if self._odom_failures % 200 == 20 else self.get_logger().debug
            log(f"no odometry {self.odom_frame} → {self.base_frame} yet, skipping the scan: {exc}")
            return None
        self._odom_failures = 0
        return odom, laser

    def _count_invalid(self, msg: Any, t_ns: int) -> None:
        """Count a scan without one reading in [range_min, range_max) and say so, at most every 10 s."""
        ranges, lo, hi = np.asarray(msg.ranges), float(msg.range_min), float(msg.range_max)
        if (ranges.size and lo <= ranges[0] < hi) or pf.any_in_range(ranges, lo, hi):  # the first beam: most scans
            return
        self.scans_invalid += 1
        if self._invalid_logged_ns is None or t_ns - self._invalid_logged_ns >= 10_000_000_000:
            self._invalid_logged_ns = t_ns
            self.get_logger().warning(
                f"scan has no valid reading (all beyond range or not finite): {self.scans_invalid} of "
                f"{self.scans_received} scans so far; the laser cannot correct the pose, only odometry moves it"
            )

    def _on_scan(self, msg: Any) -> None:
        self.scans_received += 1
        t_ns = msgs.stamp_ns(msg)
        self._count_invalid(msg, t_ns)
        f = self.filter
        if f is None or f.n_particles == 0:
            return
        poses = self._poses(msg, t_ns)
        if poses is None:
            return
        odom, laser = poses
        if f.wants_update(odom):  # the scan is built only for an update (most scans come before enough motion)
            scan = pf.Scan(
                ranges=np.asarray(msg.ranges, dtype=np.float64),
                angle_min=float(msg.angle_min),
                angle_increment=float(msg.angle_increment),
                range_min=float(msg.range_min),
                range_max=float(msg.range_max),
            )
            if f.update(odom, scan, laser):
                self._map_to_odom = f.map_to_odom()
                self._publish_estimate(t_ns)
        if self._map_to_odom is not None and self.tf_broadcast:
            self._send_map_to_odom(t_ns + round(self.transform_tolerance * 1e9))

    def _send_map_to_odom(self, stamp_ns: int) -> None:
        """tf ``global_frame -> odom_frame`` (the latest map->odom) stamped ``stamp_ns``: ROS amcl sends it with
        every scan, so its transform part is built once per new estimate and shared by the messages."""
        assert self._map_to_odom is not None
        cached = self._tf_body
        if cached is None or cached[0] != self._map_to_odom:
            x, y, yaw = self._map_to_odom
            body = msgs.transform_stamped(0, self.global_frame, self.odom_frame, x, y, yaw).transform
            t, r = body.translation, body.rotation  # what tf reads from the message (core.tf.tf_from_msg)
            cached = self._tf_body = (self._map_to_odom, (t.x, t.y, t.z, r.x, r.y, r.z, r.w))
        self.send_transform_tuples(stamp_ns, ((self.global_frame, self.odom_frame, cached[1]),))

    # --- outputs --------------------------------------------------------------------------------

    def _publish_estimate(self, t_ns: int) -> None:
        f = self.filter
        assert f is not None
        cov = msgs.covariance()
        cov[[0, 1, 6, 7]] = f.covariance[:2, :2].ravel()
        cov[35] = f.covariance[2, 2]
        self.pose_pub.publish(
            msgs.PoseWithCovarianceStamped(
                header=msgs.header(t_ns, self.global_frame),
                pose=msgs.PoseWithCovariance(pose=msgs.pose_from_2d(*f.estimate), covariance=cov),
            )
        )
        # Building thousands of Pose messages is costly: only when someone listens (a subscriber or a recorder).
        if not (self.cloud_pub.get_subscription_count() or self.executor.has_listeners):
            return
        self.cloud_pub.publish(
            msgs.PoseArray(
                header=msgs.header(t_ns, self.global_frame),
                poses=[msgs.pose_from_2d(*p) for p in f.particles],
            )
        )

    @property
    def estimate(self) -> tuple[float, float, float] | None:
        """The latest pose estimate (map frame) or None before the first update."""
        return None if self.filter is None or self._map_to_odom is None else self.filter.estimate
