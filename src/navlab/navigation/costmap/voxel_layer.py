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
import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from navlab.grid import COST_FREE, COST_LETHAL
from navlab.navigation.costmap.layer import shifted
from navlab.navigation.costmap.obstacle_layer import ObservationLayer
from navlab.navigation.costmap.params import IGNORED, ObstacleLayerParams

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


@numba.njit(cache=True)
def _popcount(v: np.int64) -> int:
    n = 0
    while v:
        v &= v - 1
        n += 1
    return n


@numba.njit(cache=True)
def clear_voxel_rays(
    columns: np.ndarray,
    cost: np.ndarray,
    origin: np.ndarray,
    ends: np.ndarray,
    z_voxels: int,
    mark_threshold: int,
    unknown_threshold: int,
    free: np.uint8,
) -> None:
    """Clear the voxels on each segment ``origin`` -> ``ends[k]`` (continuous voxel coordinates: x, y in cells,
    z in voxels) by a 3-D DDA; each cell touched becomes ``free`` in ``cost`` when its column allows it."""
    h, w = columns.shape
    for k in range(ends.shape[0]):
        x, y, z = origin[0], origin[1], origin[2]
        dx, dy, dz = ends[k, 0] - x, ends[k, 1] - y, ends[k, 2] - z
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        if length == 0.0:
            continue
        i, j, m = math.floor(x), math.floor(y), math.floor(z)
        steps = abs(math.floor(ends[k, 0]) - i) + abs(math.floor(ends[k, 1]) - j) + abs(math.floor(ends[k, 2]) - m)
        si = 1 if dx > 0 else -1
        sj = 1 if dy > 0 else -1
        sm = 1 if dz > 0 else -1
        tdx = abs(1.0 / dx) if dx != 0 else np.inf
        tdy = abs(1.0 / dy) if dy != 0 else np.inf
        tdz = abs(1.0 / dz) if dz != 0 else np.inf
        tx = ((i + 1 - x) if dx > 0 else (x - i)) * tdx if dx != 0 else np.inf
        ty = ((j + 1 - y) if dy > 0 else (y - j)) * tdy if dy != 0 else np.inf
        tz = ((m + 1 - z) if dz > 0 else (z - m)) * tdz if dz != 0 else np.inf
        for _ in range(steps + 1):
            if i < 0 or j < 0 or i >= w or j >= h or m < 0 or m >= z_voxels:
                break
            col = np.int64(columns[j, i]) & ~np.int64((1 << m) | (1 << (m + 16)))
            columns[j, i] = col
            marked = col >> 16
            unknown = (col & 0xFFFF) ^ marked
            if _popcount(marked) <= mark_threshold and _popcount(unknown) <= unknown_threshold:
                cost[j, i] = free
            if tx <= ty and tx <= tz:
                i += si
                tx += tdx
            elif ty <= tz:
                j += sj
                ty += tdy
            else:
                m += sm
                tz += tdz


@numba.njit(cache=True)
def ray_end_voxels(
    origin: np.ndarray,
    pts: np.ndarray,
    base: np.ndarray,
    scale: np.ndarray,
    dims: np.ndarray,
    max_range: float,
    seen: np.ndarray,
) -> None:
    """Flag in ``seen`` (flat, k-major: (k h + j) w + i) the voxel where each ray ``origin`` -> ``pts[n]`` (m) ends:
    cut to ``max_range`` and to the grid (``base`` its lowest corner, ``scale`` the voxel size, ``dims`` w, h, d)."""
    w, h, nz = dims[0], dims[1], dims[2]
    lo = np.empty(3)
    hi = np.empty(3)
    for a in range(3):
        lo[a] = base[a] + 1e-6
        hi[a] = base[a] + dims[a] * scale[a] - 1e-6
    for n in range(pts.shape[0]):
        dx, dy, dz = pts[n, 0] - origin[0], pts[n, 1] - origin[1], pts[n, 2] - origin[2]
        if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(dz)):
            continue
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        t = 1.0 if d <= max_range else max_range / d
        for a, da in ((0, dx), (1, dy), (2, dz)):
            if da > 0:
                t = min(t, (hi[a] - origin[a]) / da)
            elif da < 0:
                t = min(t, (lo[a] - origin[a]) / da)
        t = max(t, 0.0)
        i = min(max(math.floor((origin[0] + t * dx - base[0]) / scale[0]), 0), w - 1)
        j = min(max(math.floor((origin[1] + t * dy - base[1]) / scale[1]), 0), h - 1)
        k = min(max(math.floor((origin[2] + t * dz - base[2]) / scale[2]), 0), nz - 1)
        seen[(k * h + j) * w + i] = True


@numba.njit(cache=True)
def mark_voxels(
    columns: np.ndarray,
    cost: np.ndarray,
    origin: np.ndarray,
    pts: np.ndarray,
    base: np.ndarray,
    scale: np.ndarray,
    z_voxels: int,
    max_range: float,
    min_z: float,
    max_z: float,
    mark_threshold: int,
    lethal: np.uint8,
) -> None:
    """Mark the voxel of each point (m) nearer than ``max_range`` with its height in [``min_z``, ``max_z``]; its cell
    turns ``lethal`` when its column holds more than ``mark_threshold`` marked voxels."""
    h, w = columns.shape
    r2 = max_range * max_range
    for n in range(pts.shape[0]):
        x, y, z = pts[n, 0], pts[n, 1], pts[n, 2]
        dx, dy, dz = x - origin[0], y - origin[1], z - origin[2]
        if not (dx * dx + dy * dy + dz * dz < r2 and min_z <= z <= max_z):
            continue  # NaN fails too
        i = math.floor((x - base[0]) / scale[0])
        j = math.floor((y - base[1]) / scale[1])
        k = math.floor((z - base[2]) / scale[2])
        if i < 0 or j < 0 or k < 0 or i >= w or j >= h or k >= z_voxels:
            continue
        col = np.int64(columns[j, i]) | np.int64((1 << k) | (1 << (k + 16)))
        columns[j, i] = col
        if _popcount(col >> 16) > mark_threshold:
            cost[j, i] = lethal


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

    def _shift(self, di: int, dj: int) -> None:
        self.columns = shifted(self.columns, di, dj, UNKNOWN_COLUMN)

    def _reset_cells(self, where: Any) -> None:
        self.columns[where] = UNKNOWN_COLUMN

    def add_cloud(self, origin_xyz: Any, points_xyz: np.ndarray, *, source: str | None = None) -> None:
        """One observation in the costmap frame: the sensor at ``origin_xyz`` and its points (N, 3), m; NaN points
        are skipped. ``source``: one of :attr:`sources` (its marking, clearing, ranges and heights apply)."""
        g = self._need_grid("add_cloud")
        src = self._source_settings(source)
        o = np.asarray(origin_xyz, dtype=np.float64).reshape(3)
        pts = np.asarray(points_xyz).reshape(-1, 3)
        pts = np.ascontiguousarray(pts if pts.dtype in (np.float32, np.float64) else pts.astype(np.float64))
        p = self.params
        scale = np.array([g.resolution, g.resolution, p.z_resolution])
        base = np.array([g.origin[0], g.origin[1], p.origin_z])
        h, w = g.data.shape
        if src.clearing and len(pts):
            # each voxel where rays end traced once (rays ending in the same voxel trace the same cells)
            seen = np.zeros(h * w * p.z_voxels, dtype=bool)
            ray_end_voxels(o, pts, base, scale, np.array([w, h, p.z_voxels]), src.raytrace_range, seen)
            key = np.flatnonzero(seen)
            vox = np.stack([key % w, (key // w) % h, key // (w * h)], axis=1)
            clear_voxel_rays(
                self.columns,
                g.data,
                (o - base) / scale,
                vox + 0.5,
                p.z_voxels,
                p.mark_threshold,
                p.unknown_threshold,
                np.uint8(COST_FREE),
            )
        if src.marking and len(pts):
            mark_voxels(
                self.columns,
                g.data,
                o,
                pts,
                base,
                scale,
                p.z_voxels,
                src.obstacle_range,
                src.min_obstacle_height,
                src.max_obstacle_height,
                p.mark_threshold,
                np.uint8(COST_LETHAL),
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
