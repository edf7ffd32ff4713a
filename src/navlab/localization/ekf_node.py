"""The ``ekf_node``: robot_localization's state estimator node around :mod:`navlab.localization.ekf`.

Inputs, numbered from 0 with no gaps as robot_localization reads them: ``odomN`` (nav_msgs/Odometry),
``imuN`` (sensor_msgs/Imu), ``poseN`` (PoseWithCovarianceStamped), ``twistN`` (TwistWithCovarianceStamped),
each with ``<input>_config`` (15 booleans: x y z roll pitch yaw vx vy vz vroll vpitch vyaw ax ay az),
``_differential``, ``_relative``, ``_queue_size``, Mahalanobis thresholds ``_pose_rejection_threshold``,
``_twist_rejection_threshold`` (IMU: also ``_linear_acceleration_rejection_threshold``) and, for IMUs,
``_remove_gravitational_acceleration``. Measurements are queued and fused in time order every
``1/frequency`` s; the estimate goes out on ``odometry/filtered`` in ``world_frame`` and, with
``publish_tf``, as tf ``odom_frame → base_link_frame`` (world = odom) or ``map_frame → odom_frame``
(world = map). Parameters are robot_localization's names and defaults (its ekf_template.yaml).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.geometry import matrix_from_quat, quat_from_rpy, rpy_from_quat
from navlab.localization import ekf
from navlab.localization.errors import LocalizationError

INPUT_KINDS = ("odom", "imu", "pose", "twist")
INF = float(np.finfo(np.float64).max)  # robot_localization's "no rejection" (numeric_limits<double>::max)


class EkfNode(Node):
    """robot_localization's ``ekf_localization_node`` / ``ekf_node``."""

    def __init__(
        self, executor: Executor, *, name: str = "ekf_se", parameters: dict[str, Any] | None = None, namespace: str = ""
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.listen_tf()  # a tf2 TransformListener, as in ROS: the graph shows it reading /tf
        d = self.declare_parameter
        self.frequency = float(d("frequency", 30.0))
        if not (math.isfinite(self.frequency) and self.frequency > 0):
            raise LocalizationError(f"{self.fully_qualified_name}: frequency {self.frequency!r}: expected Hz > 0")
        d("sensor_timeout", 1.0 / self.frequency)
        self.two_d_mode = bool(d("two_d_mode", False))
        self.publish_tf = bool(d("publish_tf", True))
        d("publish_acceleration", False)
        d("print_diagnostics", True)
        d("debug", False)
        d("transform_timeout", 0.0)
        self.transform_time_offset = float(d("transform_time_offset", 0.0))
        self.predict_to_current_time = bool(d("predict_to_current_time", False))
        self.map_frame = str(d("map_frame", "map"))
        self.odom_frame = str(d("odom_frame", "odom"))
        self.base_frame = str(d("base_link_frame", "base_link"))
        self.world_frame = str(d("world_frame", self.odom_frame))
        if self.world_frame not in (self.map_frame, self.odom_frame):
            raise LocalizationError(
                f"{self.fully_qualified_name}: world_frame {self.world_frame!r}: expected "
                f"map_frame {self.map_frame!r} or odom_frame {self.odom_frame!r}"
            )
        self.gravity = float(d("gravitational_acceleration", 9.80665))
        try:
            self.filter = ekf.Ekf(
                process_noise=ekf.matrix_from(
                    d("process_noise_covariance", list(ekf.DEFAULT_PROCESS_NOISE)), "process_noise_covariance"
                ),
                initial_covariance=ekf.matrix_from(
                    d("initial_estimate_covariance", list(ekf.DEFAULT_INITIAL_COVARIANCE)),
                    "initial_estimate_covariance",
                ),
                two_d_mode=self.two_d_mode,
                initial_state=d("initial_state", [0.0] * ekf.N),
            )
        except LocalizationError as exc:
            raise LocalizationError(f"{self.fully_qualified_name}: {exc}") from None
        self.inputs: list[dict[str, Any]] = []
        for kind in INPUT_KINDS:
            n = 0
            while topic := str(d(f"{kind}{n}", "")):
                self.inputs.append(self._declare_input(kind, n, topic))
                n += 1
        if not self.inputs:
            self.get_logger().warning("no inputs (odom0, imu0, pose0, twist0...): the filter only predicts")
        self.check_parameters()
        self.queue: list[tuple[int, int, dict[str, Any], Any]] = []
        self._seq = 0
        self.filter_ns: int | None = None
        self.rejected = {i["name"]: 0 for i in self.inputs}
        self.last_error: str | None = None
        self._imu_rot: dict[str, np.ndarray] = {}
        self.pub = self.create_publisher(msgs.Odometry, "odometry/filtered", 10)
        for spec in self.inputs:
            msgtype = {
                "odom": msgs.Odometry,
                "imu": msgs.Imu,
                "pose": msgs.PoseWithCovarianceStamped,
                "twist": _twist_type(),
            }[spec["kind"]]
            self.create_subscription(msgtype, spec["topic"], self._queue_for(spec), spec["queue"])
        self.create_timer(1.0 / self.frequency, self.update)

    def _declare_input(self, kind: str, n: int, topic: str) -> dict[str, Any]:
        name = f"{kind}{n}"
        d = self.declare_parameter
        mask = ekf.mask_from(d(f"{name}_config", [False] * ekf.N), f"{self.fully_qualified_name}: {name}_config")
        spec: dict[str, Any] = {
            "kind": kind,
            "name": name,
            "topic": topic,
            "mask": mask,
            "queue": int(d(f"{name}_queue_size", 10)),
            "nodelay": d(f"{name}_nodelay", False),
        }
        if kind in ("odom", "imu", "pose"):
            spec["pose"] = ekf.PoseInput(
                differential=bool(d(f"{name}_differential", False)), relative=bool(d(f"{name}_relative", False))
            )
        keys = {
            "odom": ("pose", "twist"),
            "imu": ("pose", "twist", "linear_acceleration"),
            "pose": ("pose",),
            "twist": ("twist",),
        }[kind]
        for key in keys:  # poseN/twistN: <input>_rejection_threshold
            pname = f"{name}_{key}_rejection_threshold" if kind in ("odom", "imu") else f"{name}_rejection_threshold"
            value = float(d(pname, INF))
            if not value > 0:
                raise LocalizationError(f"{self.fully_qualified_name}: {pname} {value!r}: expected a distance > 0")
            spec[f"{key}_threshold"] = value
        if kind == "imu":
            spec["imu_parts"] = (bool(mask[3:6].any()), bool(mask[9:12].any()), bool(mask[12:15].any()))
            spec["remove_gravity"] = bool(d(f"{name}_remove_gravitational_acceleration", False))
        return spec

    # --- inputs ---------------------------------------------------------------------------------

    def _queue_for(self, spec: dict[str, Any]) -> Callable[[Any], None]:
        return lambda msg: self._enqueue(spec, msg)

    def _enqueue(self, spec: dict[str, Any], msg: Any) -> None:
        self._seq += 1
        self.queue.append((msgs.stamp_ns(msg), self._seq, spec, msg))

    def _error(self, message: str) -> None:
        if message != self.last_error:
            self.get_logger().error(message)
        self.last_error = message

    def _fuse(self, z: np.ndarray, r: np.ndarray, mask: np.ndarray, threshold: float, spec: dict[str, Any]) -> None:
        if mask.any() and not self.filter.correct(z, r, mask, threshold) and self.filter.last_rejected:
            self.rejected[spec["name"]] += 1

    def _measure(self, spec: dict[str, Any], msg: Any, t: float) -> None:
        kind, mask = spec["kind"], spec["mask"]
        if kind in ("odom", "pose"):
            frame = str(msg.header.frame_id).lstrip("/")
            if frame and frame != self.world_frame:
                self._error(
                    f"{spec['name']}: pose in frame {frame!r}, expected world_frame {self.world_frame!r}; "
                    "its pose part is ignored"
                )
            else:
                self._fuse_pose(spec, msg.pose, t, mask)
        if kind in ("odom", "twist"):
            tw = msg.twist
            lin, ang = tw.twist.linear, tw.twist.angular
            twist6 = (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
            z, r = ekf.twist_measurement(twist6, np.asarray(tw.covariance))
            vmask = np.zeros(ekf.N, dtype=bool)
            vmask[6:12] = mask[6:12]
            self._fuse(z, r, vmask, spec["twist_threshold"], spec)
        if kind == "imu":
            self._measure_imu(spec, msg, t)

    def _fuse_pose(self, spec: dict[str, Any], pose_cov: Any, t: float, mask: np.ndarray) -> None:
        p, q = pose_cov.pose.position, pose_cov.pose.orientation
        pose6 = (p.x, p.y, p.z, *rpy_from_quat((q.x, q.y, q.z, q.w)))
        pmask = np.zeros(ekf.N, dtype=bool)
        pmask[:6] = mask[:6]
        if not pmask.any():
            return
        out = spec["pose"].convert(pose6, np.asarray(pose_cov.covariance), t, pmask)
        if out is not None:
            z, r, m = out
            self._fuse(z, r, m, spec["pose_threshold"], spec)

    def _imu_rotation(self, frame: str, name: str) -> np.ndarray | None:
        """base_R_imu from tf (the IMU's static mounting), cached; None with an error when tf lacks it."""
        if frame in self._imu_rot:
            return self._imu_rot[frame]
        if not frame:
            self._error(f"{name}: the IMU message has no frame_id; set the IMU plugin's frameName/bodyName")
            return None
        if frame == self.base_frame:
            rot = np.eye(3)
        else:
            try:
                tf = self.executor.tf.lookup(self.base_frame, frame)
            except TfError as exc:
                self._error(
                    f"{name}: no transform from the IMU frame {frame!r} to base_link_frame "
                    f"{self.base_frame!r} ({exc}); the IMU is ignored until there is one"
                )
                return None
            rot = matrix_from_quat(tf[3:7])
        self._imu_rot[frame] = rot
        return rot

    def _measure_imu(self, spec: dict[str, Any], msg: Any, t: float) -> None:
        rot = self._imu_rotation(str(msg.header.frame_id).lstrip("/"), spec["name"])
        if rot is None:
            return
        q = msg.orientation
        have_orientation = float(msg.orientation_covariance[0]) != -1.0 and (q.x or q.y or q.z or q.w)
        rpy = rpy_from_quat((q.x, q.y, q.z, q.w)) if have_orientation else None
        w, a = msg.angular_velocity, msg.linear_acceleration
        z, r = ekf.imu_measurement(
            rot,
            orientation_rpy=rpy,
            orientation_cov=np.asarray(msg.orientation_covariance),
            angular_velocity=(w.x, w.y, w.z),
            angular_velocity_cov=np.asarray(msg.angular_velocity_covariance),
            linear_acceleration=(a.x, a.y, a.z),
            linear_acceleration_cov=np.asarray(msg.linear_acceleration_covariance),
            remove_gravity=spec["remove_gravity"],
            gravity=self.gravity,
            parts=spec["imu_parts"],
        )
        mask = spec["mask"]
        groups = ((3, 6, "pose"), (9, 12, "twist"), (12, 15, "linear_acceleration"))
        for lo, hi, key in groups:
            m = np.zeros(ekf.N, dtype=bool)
            m[lo:hi] = mask[lo:hi]
            if key == "pose":
                if rpy is None or not m.any():
                    continue
                if spec["pose"].differential or spec["pose"].relative:
                    pose6 = (0.0, 0.0, 0.0, *(float(v) for v in z[3:6]))
                    cov6 = np.zeros((6, 6))
                    cov6[3:, 3:] = r[3:6, 3:6]
                    out = spec["pose"].convert(pose6, cov6, t, m)
                    if out is not None:
                        self._fuse(out[0], out[1], out[2], spec["twist_threshold"], spec)
                    continue
            self._fuse(z, r, m, spec[f"{key}_threshold"], spec)

    # --- the cycle ------------------------------------------------------------------------------

    def update(self) -> None:
        """Fuse the queued measurements in time order, then publish the estimate (and tf)."""
        now = self.get_clock().now_ns()
        queue, self.queue = sorted(self.queue, key=lambda e: (e[0], e[1])), []
        for t_ns, _, spec, msg in queue:
            if self.filter_ns is not None and t_ns > self.filter_ns:
                self.filter.predict((t_ns - self.filter_ns) / 1e9)
            if self.filter_ns is None or t_ns > self.filter_ns:
                self.filter_ns = t_ns
            self._measure(spec, msg, t_ns / 1e9)
        if self.filter_ns is None or not self.filter.initialized:
            return
        if self.predict_to_current_time and now > self.filter_ns:
            self.filter.predict((now - self.filter_ns) / 1e9)
            self.filter_ns = now
        self._publish(self.filter_ns)

    def _publish(self, t_ns: int) -> None:
        s, p = self.filter.state, self.filter.covariance
        q = quat_from_rpy(s[3], s[4], s[5])
        pose_cov, twist_cov = p[:6, :6].ravel().copy(), p[6:12, 6:12].ravel().copy()
        self.pub.publish(
            msgs.odometry(t_ns, self.world_frame, self.base_frame, s[0:3], q, s[6:9], s[9:12], pose_cov, twist_cov)
        )
        if not self.publish_tf:
            return
        stamp = t_ns + round(self.transform_time_offset * 1e9)
        x, y, yaw = float(s[0]), float(s[1]), float(s[5])
        if self.world_frame == self.odom_frame:
            self.send_transform(msgs.transform_stamped(stamp, self.odom_frame, self.base_frame, x, y, yaw))
            return
        try:  # world = map: publish map -> odom so that map -> base is the estimate
            ox, oy, oyaw = self.executor.tf.lookup_pose2d_or_latest(self.odom_frame, self.base_frame, t_ns)
        except TfError:
            return
        c, sn = math.cos(yaw - oyaw), math.sin(yaw - oyaw)
        mx, my = x - (c * ox - sn * oy), y - (sn * ox + c * oy)
        self.send_transform(msgs.transform_stamped(stamp, self.map_frame, self.odom_frame, mx, my, yaw - oyaw))

    @property
    def estimate(self) -> tuple[float, float, float] | None:
        """(x, y, yaw) in ``world_frame`` once initialised."""
        if not self.filter.initialized:
            return None
        s = self.filter.state
        return float(s[0]), float(s[1]), float(s[5])


def _twist_type() -> type:
    return msgs.get_type("geometry_msgs/msg/TwistWithCovarianceStamped")
