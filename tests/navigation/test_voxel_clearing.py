"""The voxel layer's clearing (rays sharing their walk per end column, every ray's voxels cleared at once) gives
the grids of clearing ray by ray with a plain 3-D DDA, then marking, as costmap_2d's voxel layer does."""

from __future__ import annotations

import math

import numpy as np

from navlab.grid import COST_FREE, COST_LETHAL, Grid
from navlab.navigation.costmap.params import ObservationSource
from navlab.navigation.costmap.voxel_layer import VoxelLayer

RES, ZRES, NZ, ORIGIN_Z, SIZE = 0.05, 0.05, 8, -0.1, 40


def _ray_by_ray(columns, cost, origin, points, mark_threshold, unknown_threshold) -> None:
    """Reference: each end voxel's ray (origin -> that voxel's centre) cleared voxel by voxel, then the marks."""
    base = np.array([-1.0, -1.0, ORIGIN_Z])
    scale = np.array([RES, RES, ZRES])
    g = (origin - base) / scale
    ends = {tuple(int(v) for v in np.floor((p - base) / scale)) for p in points}
    for end in sorted(ends):
        d = np.array(end) + 0.5 - g
        cell = [math.floor(v) for v in g]
        steps = sum(abs(end[a] - cell[a]) for a in range(3))
        step = [1 if v > 0 else -1 for v in d]
        delta = [abs(1.0 / v) if v != 0 else math.inf for v in d]
        t = [
            ((cell[a] + 1 - g[a]) if d[a] > 0 else (g[a] - cell[a])) * delta[a] if d[a] != 0 else math.inf
            for a in range(3)
        ]
        for _ in range(steps + 1):
            i, j, m = cell
            col = int(columns[j, i]) & ~((1 << m) | (1 << (m + 16)))
            columns[j, i] = col
            marked, unknown = bin(col >> 16).count("1"), bin((col & 0xFFFF) ^ (col >> 16)).count("1")
            if marked <= mark_threshold and unknown <= unknown_threshold:
                cost[j, i] = COST_FREE
            a = 0 if t[0] <= t[1] and t[0] <= t[2] else (1 if t[1] <= t[2] else 2)
            cell[a] += step[a]
            t[a] += delta[a]
    for i, j, m in ends:
        columns[j, i] |= (1 << m) | (1 << (m + 16))
        if bin(int(columns[j, i]) >> 16).count("1") > mark_threshold:
            cost[j, i] = COST_LETHAL


def test_clearing_per_column_equals_clearing_ray_by_ray() -> None:
    rng = np.random.default_rng(28)
    for mark_threshold, unknown_threshold in ((0, 15), (1, 4), (0, 2)):
        origin = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.1])
        # floor points, walls (many heights in one column), boxes; all inside the grid and the ranges
        n = 600
        pts = np.column_stack([rng.uniform(-0.95, 0.95, n), rng.uniform(-0.95, 0.95, n), rng.uniform(-0.09, 0.29, n)])
        pts[:200, 2] = -0.08
        pts[200:350, 0] = 0.73
        pts[350:400, :2] = np.round(pts[350:400, :2] / RES) * RES + 1e-9  # on cell faces
        source = ObservationSource(
            data_type="PointCloud2",
            clearing=True,
            obstacle_range=5.0,
            raytrace_range=5.0,
            min_obstacle_height=-1.0,
            max_obstacle_height=1.0,
        )
        layer = VoxelLayer(
            {
                "z_resolution": ZRES,
                "z_voxels": NZ,
                "origin_z": ORIGIN_Z,
                "mark_threshold": mark_threshold,
                "unknown_threshold": unknown_threshold,
            },
            name="voxel",
            sources={"cam": source},
        )
        layer.match_size(Grid(np.zeros((SIZE, SIZE), np.uint8), RES, (-1.0, -1.0, 0.0), "odom"))
        layer.columns[:] = rng.integers(0, 2, (SIZE, SIZE)) * np.uint32(0xFFFF)  # known and unknown columns
        layer.columns[5:9] |= np.uint32(0b11 << 16 | 0b11)  # marked voxels to clear
        layer.grid.data[:] = rng.choice(np.array([COST_FREE, COST_LETHAL, 255], np.uint8), (SIZE, SIZE))
        columns, cost = layer.columns.copy(), layer.grid.data.copy()
        layer.add_cloud(origin, pts, source="cam")
        _ray_by_ray(columns, cost, origin, pts, mark_threshold, unknown_threshold)
        assert (layer.columns != columns).sum() == 0 and (layer.grid.data != cost).sum() == 0
        assert (cost == COST_FREE).sum() > 100 and (cost == COST_LETHAL).sum() > 20  # both at work
