"""What a simulated world knows for certain: its occupancy at lidar height, as a grid or as a map.

Runs score maps and trajectories against these (see ``experiments.metrics``); ``navlab localize``
serves ``true_map`` when no map file is given. (Moved from ``navlab.experiments.truth``, which stays a
deprecated alias until the next release.)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import ndimage

from navlab.grid import Grid, GridMap


def world_T_map(robot: Any, spawn_pose: tuple[float, float, float]) -> tuple[float, float, float]:
    """Where a SLAM map's frame lies in the world (x, y, yaw): SLAM starts with map = odom, and the odom
    frame is the world frame when the diff-drive plugin's odometry is the true pose (``odometrySource
    world``, Gazebo's default) but the spawn pose when it integrates the wheel encoders."""
    dd = getattr(robot, "diff_drive", None)
    if dd is not None and dd.odometry_source == "world":
        return (0.0, 0.0, 0.0)
    return (float(spawn_pose[0]), float(spawn_pose[1]), float(spawn_pose[2]))


def truth_grid(occupied: np.ndarray, resolution: float, origin_xy: tuple[float, float]) -> Grid:
    """The world's true occupancy at lidar height as a boolean ``Grid`` in the world frame."""
    return Grid(np.asarray(occupied, dtype=bool), resolution, (origin_xy[0], origin_xy[1], 0.0), "world")


def true_occupancy(world: Any, grid: Grid, margin: float = 1.0) -> Grid:
    """The world's occupancy (static models) over ``grid``'s extent plus ``margin`` m, at its resolution."""
    from navlab.world.occupancy import occupancy

    x0, y0, x1, y1 = grid.bounds()
    bounds = (x0 - margin, y0 - margin, x1 + margin, y1 + margin)
    occ = occupancy(world, grid.resolution, bounds, static_only=True)
    return truth_grid(occ, grid.resolution, (bounds[0], bounds[1]))


def true_map(world: Any, start_xy: tuple[float, float], resolution: float = 0.05) -> GridMap:
    """The world's true occupancy as a map: obstacles 100, free space reachable from ``start_xy`` 0,
    everything else (outside the walls) unknown (-1). World frame = map frame."""
    from navlab.world import occupancy, shape_footprints

    pts = np.vstack([fp.points for fp in shape_footprints(world)])
    lo, hi = pts.min(0) - 0.5, pts.max(0) + 0.5
    occ = occupancy(world, resolution, (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])))
    labels, _ = ndimage.label(~occ)
    i = int((start_xy[0] - lo[0]) / resolution)
    j = int((start_xy[1] - lo[1]) / resolution)
    data = np.full(occ.shape, -1, dtype=np.int8)
    data[occ] = 100
    if 0 <= j < occ.shape[0] and 0 <= i < occ.shape[1] and labels[j, i] > 0:
        data[labels == labels[j, i]] = 0
    else:
        data[~occ] = 0
    return GridMap(data, resolution, (float(lo[0]), float(lo[1]), 0.0))


def visible_surface(truth: Grid, start_xy: tuple[float, float]) -> np.ndarray:
    """Occupied cells that touch the free space reachable from ``start_xy``: what a lidar can see."""
    free = ~truth.data
    labels, _ = ndimage.label(free)
    i, j = truth.world_to_cell(np.array([start_xy]))[0]
    reachable = labels == labels[j, i] if labels[j, i] > 0 else np.zeros_like(free)
    near_reachable = ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 1))
    return truth.data & near_reachable


def unmapped_obstacles(world: Any, grid: GridMap, start_xy: tuple[float, float]) -> np.ndarray:
    """World points (N, 2; m) of obstacles the world has but the map ``grid`` does not (cells the map calls free
    more than two cells from any of its walls): what was added after mapping."""
    truth = true_map(world, start_xy, resolution=grid.resolution)
    jj, ii = np.nonzero(truth.data == 100)
    xy = np.stack([truth.origin[0] + (ii + 0.5) * truth.resolution, truth.origin[1] + (jj + 0.5) * truth.resolution], 1)
    walls = ndimage.binary_dilation(grid.occupied_mask(), iterations=2)
    cells = grid.world_to_cell(xy)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < grid.width) & (cells[:, 1] >= 0) & (cells[:, 1] < grid.height)
    keep = np.zeros(len(xy), dtype=bool)
    ci, cj = cells[inside, 0], cells[inside, 1]
    keep[inside] = grid.free_mask()[cj, ci] & ~walls[cj, ci]
    return xy[keep]
