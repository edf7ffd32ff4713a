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
from dataclasses import dataclass
from typing import Any

import numpy as np

from navlab.grid import COST_FREE, COST_LETHAL
from navlab.navigation.costmap.layer import shifted
from navlab.navigation.costmap.obstacle_layer import ObservationLayer
from navlab.navigation.costmap.params import IGNORED, ObstacleLayerParams
from navlab.navigation.costmap.voxel_kernels import observe
from navlab.navigation.errors import NavigationError

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
        """The obstacle layer's checks (ranges, combination_method) come from the spec; the obstacle layer's prices
        for hidden cells (``costmap.hidden_cells``) are not the voxel layer's: refused by name."""
        for key in ("occluded_unknown_cost", "unknown_near_obstacle_cost"):
            if getattr(self, key):
                raise NavigationError(
                    f"voxel_layer: {key} is an obstacle_layer parameter (costmap_2d::ObstacleLayer); the voxel layer "
                    "does not price hidden cells: set it on an obstacle_layer or remove it"
                )


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


class VoxelLayer(ObservationLayer):
    """``costmap_2d::VoxelLayer`` (see the module docstring). ``sources``: its observation sources by name."""

    params: VoxelLayerParams
    params_class = VoxelLayerParams

    @property
    def z_top(self) -> float:
        """Height (m) of the top of the voxel columns."""
        return self.params.origin_z + self.params.z_voxels * self.params.z_resolution

    def _new_cells(self, shape: tuple[int, ...]) -> None:
        self.columns = np.full(shape, UNKNOWN_COLUMN, np.uint32)
        self._seen = np.zeros(int(np.prod(shape)), np.uint32)  # observe()'s scratch
        self._clear = np.zeros(int(np.prod(shape)), np.uint32)

    def _shift(self, di: int, dj: int) -> None:
        self.columns = shifted(self.columns, di, dj, UNKNOWN_COLUMN)

    def _reset_cells(self, where: Any) -> None:
        self.columns[where] = UNKNOWN_COLUMN

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
        g = self._need_grid("add_cloud")
        src = self._source_settings(source)
        o = np.asarray(origin_xyz, dtype=np.float64).reshape(3)
        pts = np.asarray(points)
        pts = pts.reshape(-1, 3) if pts.ndim != 2 else pts
        if pts.dtype not in (np.float32, np.float64):
            pts = pts.astype(np.float64)
        place = np.zeros((4, 3))
        place[:3] = rotation
        if moved:
            place[3] = o
        p = self.params
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
            p.z_voxels,
            self._seen,
            self._clear,
        )

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
