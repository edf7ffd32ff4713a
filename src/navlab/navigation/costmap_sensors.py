"""The 3-D and range inputs of a ``Costmap2DROS``: PointCloud2 and LaserScan observation sources of its voxel
layers, and the ``sensor_msgs/Range`` topics of its range sensor layers.

Each source keeps its newest message (``observation_persistence`` 0, ROS's default); range readings are all
applied, in order, at the next update (range_sensor_layer buffers them). Points are moved into the costmap's
frame with the full 3-D tf at the message's stamp (else the latest).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any, Protocol, cast, runtime_checkable

import numpy as np

from navlab import msgs
from navlab.core import Node, TfError
from navlab.geometry import matrix_from_quat
from navlab.io import move_points, read_xyz
from navlab.navigation.costmap.params import ObservationSource


@runtime_checkable
class CloudLayer(Protocol):
    """A layer that takes 3-D observations (a capability; ``costmap_2d::VoxelLayer``): ``sources`` by name, each
    LaserScan or PointCloud2 with its ``topic``; ``params.publish_voxel_map``; ``voxel_grid_msg``."""

    name: str
    sources: Mapping[str, ObservationSource]
    params: Any

    def add_cloud(self, origin_xyz: Any, points_xyz: np.ndarray, *, source: str | None = None) -> None: ...

    def voxel_grid_msg(self, stamp_ns: int) -> Any: ...

    def clear_outside(self, xy: tuple[float, float], size: float) -> None: ...


@runtime_checkable
class SensorFrameCloudLayer(Protocol):
    """A cloud layer that also takes the points in the sensor's frame with the sensor's pose (no moved copy)."""

    def add_sensor_cloud(
        self, origin_xyz: Any, rotation: np.ndarray, points: np.ndarray, *, source: str | None = None
    ) -> None: ...


@runtime_checkable
class RangeLayer(Protocol):
    """A layer that takes ``sensor_msgs/Range`` readings (a capability; ``range_sensor_layer``) on ``topics``."""

    @property
    def topics(self) -> list[str]: ...

    def add_range(
        self,
        sensor_pose: tuple[float, float, float],
        reading: float,
        *,
        field_of_view: float,
        min_range: float,
        max_range: float,
    ) -> None: ...


Beams = dict[tuple[int, float, float], tuple[np.ndarray, np.ndarray]]  # (count, angle_min, increment) -> cos, sin


def scan_points(msg: Any, trig: Beams | None = None) -> np.ndarray:
    """A LaserScan's returns (N, 3) in its own frame (finite ranges in [range_min, range_max)). ``trig``: a cache of
    the beams' cosines and sines by (beam count, angle_min, angle_increment), kept for the scan's geometry."""
    r = np.asarray(msg.ranges, dtype=np.float64)
    key = (len(r), float(msg.angle_min), float(msg.angle_increment))
    beams = trig.get(key) if trig is not None else None
    if beams is None:
        a = key[1] + key[2] * np.arange(key[0])
        beams = (np.cos(a), np.sin(a))
        if trig is not None:
            trig.clear()
            trig[key] = beams
    ok = (r >= float(msg.range_min)) & (r < float(msg.range_max))  # NaN and inf fail one of them
    hit = r[ok]
    out = np.zeros((len(hit), 3))
    out[:, 0] = hit * beams[0][ok]
    out[:, 1] = hit * beams[1][ok]
    return out


class CostmapSensorFeeds:
    """Subscriptions and updates for ``layers``' 3-D and range inputs, in ``node``, for a costmap in ``frame``."""

    def __init__(self, node: Node, name: str, frame: str, layers: list[Any], *, prefix: str | None = None) -> None:
        self.node, self.name, self.frame = node, name, frame
        self.voxel: list[CloudLayer] = [x for x in layers if isinstance(x, CloudLayer)]
        self._in_place = [isinstance(x, SensorFrameCloudLayer) for x in self.voxel]  # (a protocol check is slow)
        self.range: list[RangeLayer] = [x for x in layers if isinstance(x, RangeLayer)]
        self.pending: dict[tuple[int, str], Any] = {}
        self.readings: list[Any] = []
        self.sources: set[str] = set()
        self._trig: Beams = {}  # scan_points' beams
        # publish_voxel_map: <costmap>/<layer>/voxel_grid (costmap_2d/VoxelGrid), after each update's observations
        self.voxel_pubs = {
            k: node.create_publisher(msgs.VoxelGrid, f"{prefix or name}/{layer.name}/voxel_grid", 1)
            for k, layer in enumerate(self.voxel)
            if layer.params.publish_voxel_map
        }
        for k, layer in enumerate(self.voxel):
            for src_name, src in layer.sources.items():
                kind = msgs.LaserScan if src.data_type == "LaserScan" else msgs.PointCloud2
                node.create_subscription(kind, src.topic or src_name, functools.partial(self._keep, (k, src_name)), 5)
                self.sources.add(src_name)
        topics = sorted({t for layer in self.range for t in layer.topics})
        for topic in topics:
            node.create_subscription(msgs.Range, topic, self.readings.append, 50)

    def _keep(self, key: tuple[int, str], msg: Any) -> None:
        self.pending[key] = msg

    def _in_costmap(self, frame: str, stamp: int) -> tuple[np.ndarray, np.ndarray] | None:
        """(translation, rotation) of ``frame`` in the costmap frame at ``stamp`` (else the latest), or None."""
        tf = self.node.executor.tf
        try:
            try:
                t = tf.lookup(self.frame, frame, stamp)
            except TfError:
                t = tf.lookup(self.frame, frame)
        except TfError as exc:
            self.node.get_logger().warning(f"{self.name}: no transform {self.frame} -> {frame}: {exc}")
            return None
        return np.array(t[:3]), matrix_from_quat(t[3:])

    def apply(self) -> None:
        """Give the newest observations to the layers (called before each costmap update)."""
        for (k, src_name), msg in self.pending.items():
            frame = str(msg.header.frame_id).lstrip("/")
            place = self._in_costmap(frame, msgs.stamp_ns(msg))
            if place is None:
                continue
            scan = msgs.type_name(msg).endswith("LaserScan")
            pts = scan_points(msg, self._trig) if scan else read_xyz(msg, copy=False)
            origin, rot = place
            cloud_layer = self.voxel[k]
            if self._in_place[k]:  # moved point by point as the layer reads them
                cast(SensorFrameCloudLayer, cloud_layer).add_sensor_cloud(origin, rot, pts, source=src_name)
            else:  # NaNs: skipped there
                cloud_layer.add_cloud(origin, move_points(pts, rot, origin), source=src_name)
        self.pending.clear()
        for k, pub in self.voxel_pubs.items():
            grid = self.voxel[k].voxel_grid_msg(self.node.executor.now_ns)
            if grid is not None:
                pub.publish(grid)
        for msg in self.readings:
            place = self._in_costmap(str(msg.header.frame_id).lstrip("/"), msgs.stamp_ns(msg))
            if place is None:
                continue
            origin, rot = place
            yaw = float(np.arctan2(rot[1, 0], rot[0, 0]))
            for layer in self.range:
                layer.add_range(
                    (float(origin[0]), float(origin[1]), yaw),
                    float(msg.range),
                    field_of_view=float(msg.field_of_view),
                    min_range=float(msg.min_range),
                    max_range=float(msg.max_range),
                )
        self.readings.clear()
