"""``costmap_2d::VoxelLayer``: an obstacle layer that marks and clears in 3-D (point clouds and laser scans).

Each cell of the layer holds a column of ``z_voxels`` voxels (at most 16) of ``z_resolution`` m from ``origin_z``
up, packed as costmap_2d's ``voxel_grid`` packs them: bit ``z`` (low half) and bit ``z + 16`` (high half) of a
uint32 — both set: marked; only the low one: unknown (every voxel at the start); none: free. An observation
(sensor origin and points in the costmap frame, m) first clears the voxels along each ray (3-D DDA, up to
``raytrace_range``, cut where the ray leaves the voxel column's height), setting the cell free when its column
then has at most ``mark_threshold`` marked and at most ``unknown_threshold`` unknown voxels; then marks the
voxel of each point nearer than ``obstacle_range`` whose height lies in the source's
[``min_obstacle_height``, ``max_obstacle_height``], the cell lethal when its column has more than
``mark_threshold`` marked voxels. Rays ending in the same voxel are traced once (to that voxel's centre).
The costs combine into the master as the obstacle layer's do (``combination_method``; footprint clearing).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from navlab.core.params import read_params
from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.layer import Layer
from navlab.navigation.costmap.obstacle_layer import observation_layer_args
from navlab.navigation.costmap.params import IGNORED, ObservationSource, ObstacleLayerParams
from navlab.navigation.costmap.voxel_kernels import observe
from navlab.navigation.errors import NavigationError
from navlab.plugins import PluginContext

UNKNOWN_COLUMN = np.uint32(0xFFFF)  # every voxel unknown (voxel_grid's reset)


@dataclass
class VoxelLayerParams(ObstacleLayerParams):
    """``costmap_2d::VoxelLayer``'s parameters: the obstacle layer's and the voxel grid's (ROS 1 names, defaults; m)."""

    origin_z: float = 0.0
    z_resolution: float = 0.2
    z_voxels: int = 10
    unknown_threshold: int = 15
    mark_threshold: int = 0
    publish_voxel_map: bool = False

    def validate(self) -> None:
        """The obstacle layer's checks (ranges, combination_method) come from the spec; nothing spans fields."""


VOXEL_KEYS = frozenset(
    {"origin_z", "z_resolution", "z_voxels", "unknown_threshold", "mark_threshold", "publish_voxel_map"}
)
# the obstacle layer's spec, with the voxel keys read (the costmap level ignores them) and their ranges
VoxelLayerParams.PARAMS = dataclasses.replace(
    ObstacleLayerParams.PARAMS,
    what="voxel_layer",
    ignored=IGNORED - VOXEL_KEYS,
    above={**ObstacleLayerParams.PARAMS.above, "z_resolution": 0.0},
    at_least={**ObstacleLayerParams.PARAMS.at_least, "z_voxels": 1, "unknown_threshold": 0, "mark_threshold": 0},
    at_most={**ObstacleLayerParams.PARAMS.at_most, "z_voxels": 16},
)  # costmap_2d's voxel grid: 16 per column


class VoxelLayer(Layer):
    """``costmap_2d::VoxelLayer`` (see the module docstring). ``sources``: its observation sources by name."""

    def __init__(
        self,
        params: VoxelLayerParams | dict[str, Any] | None = None,
        *,
        name: str = "obstacle_layer",
        sources: dict[str, ObservationSource] | None = None,
        footprint: Footprint | None = None,
    ) -> None:
        self.params: VoxelLayerParams = read_params(VoxelLayerParams, params, what=name)
        self.name = name
        self.enabled = self.params.enabled
        self.sources: Mapping[str, ObservationSource] = dict(sources or {})
        self.footprint = footprint or make_footprint()
        self.grid: Grid | None = None
        self.columns = np.zeros((0, 0), dtype=np.uint32)
        self._flags = np.zeros(0, dtype=np.uint8)  # observe()'s scratch: one per voxel
        self.robot_pose: tuple[float, float, float] | None = None

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """The layer named ``context.name`` (its ``plugins:`` name) from its namespace ``params`` (ROS names), in the
        costmap ``context.costmap`` (its observation sources) with the padded ``context.footprint``."""
        return cls(**observation_layer_args(params, context, VoxelLayerParams))

    @property
    def default_value(self) -> int:
        """A never-observed cell: unknown with ``track_unknown_space``, else free."""
        return COST_UNKNOWN if self.params.track_unknown_space else COST_FREE

    @property
    def z_top(self) -> float:
        """Height (m) of the top of the voxel columns."""
        return self.params.origin_z + self.params.z_voxels * self.params.z_resolution

    def on_footprint_changed(self, footprint: Footprint) -> None:
        self.footprint = footprint

    def match_size(self, master: Grid) -> None:
        self.grid = Grid(
            np.full(master.data.shape, self.default_value, np.uint8), master.resolution, master.origin, master.frame_id
        )
        self.columns = np.full(master.data.shape, UNKNOWN_COLUMN, np.uint32)

    def update_origin(self, master: Grid) -> None:
        old = self.grid
        if old is None or old.data.shape != master.data.shape or old.resolution != master.resolution:
            self.match_size(master)
            return
        di, dj = np.rint((np.array(master.origin[:2]) - np.array(old.origin[:2])) / master.resolution).astype(int)
        h, w = old.data.shape
        cost = np.full((h, w), self.default_value, np.uint8)
        cols = np.full((h, w), UNKNOWN_COLUMN, np.uint32)
        i0, i1, j0, j1 = max(0, -di), min(w, w - di), max(0, -dj), min(h, h - dj)
        if i0 < i1 and j0 < j1:
            cost[j0:j1, i0:i1] = old.data[j0 + dj : j1 + dj, i0 + di : i1 + di]
            cols[j0:j1, i0:i1] = self.columns[j0 + dj : j1 + dj, i0 + di : i1 + di]
        self.grid = Grid(cost, master.resolution, master.origin, master.frame_id)
        self.columns = cols

    def add_cloud(self, origin_xyz: Any, points_xyz: np.ndarray, *, source: str | None = None) -> None:
        """One observation in the costmap frame: the sensor at ``origin_xyz`` and its points (N, 3), m; NaN points
        are skipped. ``source``: one of :attr:`sources` (its marking, clearing, ranges and heights apply)."""
        self.add_sensor_cloud(origin_xyz, np.eye(3), points_xyz, source=source, moved=False)

    def add_sensor_cloud(
        self,
        origin_xyz: Any,
        rotation: np.ndarray,
        points: np.ndarray,
        *,
        source: str | None = None,
        moved: bool = True,
    ) -> None:
        """One observation with its points (N x 3 or wider, any strides: only x y z are read) in the sensor's
        frame, which sits at ``origin_xyz`` turned by ``rotation`` (3 x 3) in the costmap frame; ``moved=False``:
        the points are in the costmap frame already. Each point is moved as it is read (no copy of the cloud)."""
        if self.grid is None:
            raise NavigationError(f"{self.name}: no grid yet; call match_size(master) before add_cloud")
        src = self._source(source)
        o = np.asarray(origin_xyz, dtype=np.float64).reshape(3)
        pts = np.asarray(points)
        pts = pts.reshape(-1, 3) if pts.ndim != 2 else pts
        if pts.dtype not in (np.float32, np.float64):
            pts = pts.astype(np.float64)
        place = np.zeros((4, 3))
        place[:3] = rotation
        if moved:
            place[3] = o
        g, p = self.grid, self.params
        h, w = g.data.shape
        if self._flags.shape[0] != h * w * p.z_voxels:
            self._flags = np.zeros(h * w * p.z_voxels, dtype=np.uint8)
        observe(
            self.columns,
            g.data,
            o,
            pts,
            place,
            np.array([g.origin[0], g.origin[1], p.origin_z]),
            np.array([g.resolution, g.resolution, p.z_resolution]),
            bool(src.clearing),
            float(src.raytrace_range),
            bool(src.marking),
            float(src.obstacle_range),
            float(src.min_obstacle_height),
            float(src.max_obstacle_height),
            p.mark_threshold,
            p.unknown_threshold,
            np.uint8(COST_FREE),
            np.uint8(COST_LETHAL),
            self._flags,
        )

    def _source(self, source: str | None) -> ObservationSource:
        p = self.params
        if source is None:
            return ObservationSource(
                marking=True,
                clearing=True,
                obstacle_range=p.obstacle_range,
                raytrace_range=p.raytrace_range,
                max_obstacle_height=p.max_obstacle_height,
            )
        if source not in self.sources:
            raise NavigationError(
                f"{self.name}: unknown observation source {source!r} (sources: {', '.join(self.sources) or 'none'})"
            )
        return self.sources[source]

    def update_bounds(self, robot_pose: tuple[float, float, float]) -> None:
        self.robot_pose = (float(robot_pose[0]), float(robot_pose[1]), float(robot_pose[2]))

    def update_costs(self, master: Grid) -> None:
        if self.grid is None:
            return
        if self.grid.data.shape != master.data.shape or self.grid.origin != master.origin:
            self.update_origin(master)
        g = self.grid
        if self.params.footprint_clearing_enabled and self.robot_pose is not None:
            ij = self.footprint.cells(g, self.robot_pose)
            g.data[ij[:, 1], ij[:, 0]] = COST_FREE
        known = g.data != COST_UNKNOWN
        if self.params.combination_method == 0:
            master.data[known] = g.data[known]
        else:
            take = known & ((master.data == COST_UNKNOWN) | (master.data < g.data))
            master.data[take] = g.data[take]

    def reset(self) -> None:
        if self.grid is not None:
            self.grid.data[:] = self.default_value
            self.columns[:] = UNKNOWN_COLUMN

    def clear_outside(self, xy: tuple[float, float], size: float) -> None:
        """Forget what lies outside the ``size`` x ``size`` m square centred on ``xy`` (clear_costmap_recovery)."""
        if self.grid is None:
            return
        g = self.grid
        cx = g.origin[0] + (np.arange(g.width) + 0.5) * g.resolution
        cy = g.origin[1] + (np.arange(g.height) + 0.5) * g.resolution
        out = (np.abs(cx[None, :] - xy[0]) > size / 2) | (np.abs(cy[:, None] - xy[1]) > size / 2)
        g.data[out] = self.default_value
        self.columns[out] = UNKNOWN_COLUMN

    def voxel_grid_msg(self, stamp_ns: int) -> Any:
        """``costmap_2d/VoxelGrid`` of the layer (what ``publish_voxel_map`` publishes), or None before a grid."""
        from navlab import msgs

        if self.grid is None:
            return None
        g, p = self.grid, self.params
        return msgs.VoxelGrid(
            header=msgs.header(stamp_ns, g.frame_id),
            data=self.columns.reshape(-1).astype(np.uint32),
            origin=msgs.Point32(x=float(g.origin[0]), y=float(g.origin[1]), z=float(p.origin_z)),
            resolutions=msgs.Vector3(x=g.resolution, y=g.resolution, z=p.z_resolution),
            size_x=g.width,
            size_y=g.height,
            size_z=p.z_voxels,
        )

    def marked_voxels(self) -> np.ndarray:
        """Centres (N, 3) in the costmap frame (m) of the marked voxels (what ``publish_voxel_map`` shows)."""
        if self.grid is None:
            return np.zeros((0, 3))
        g, p = self.grid, self.params
        marked = (self.columns >> 16)[..., None] & (np.uint32(1) << np.arange(p.z_voxels, dtype=np.uint32))
        j, i, k = np.nonzero(marked)
        return np.stack(
            [
                g.origin[0] + (i + 0.5) * g.resolution,
                g.origin[1] + (j + 0.5) * g.resolution,
                p.origin_z + (k + 0.5) * p.z_resolution,
            ],
            axis=1,
        )
