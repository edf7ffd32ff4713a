"""Scoring a SLAM map against the world's true occupancy, and a trajectory against ground truth.

The map frame of a SLAM run is the robot's start pose; the evaluator knows that pose
(``world_T_map``), so no alignment is searched. A match counts within ``tolerance_cells`` cells.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from navlab.geometry import inverse_transform_points2, transform_points2, wrap_angle
from navlab.grid import Grid, GridMap


def truth_grid(occupied: np.ndarray, resolution: float, origin_xy: tuple[float, float]) -> Grid:
    """The world's true occupancy at lidar height as a boolean ``Grid`` in the world frame."""
    return Grid(np.asarray(occupied, dtype=bool), resolution, (origin_xy[0], origin_xy[1], 0.0), "world")


def visible_surface(truth: Grid, start_xy: tuple[float, float]) -> np.ndarray:
    """Occupied cells that touch the free space reachable from ``start_xy``: what a lidar can see."""
    free = ~truth.data
    labels, _ = ndimage.label(free)
    i, j = truth.world_to_cell(np.array([start_xy]))[0]
    reachable = labels == labels[j, i] if labels[j, i] > 0 else np.zeros_like(free)
    near_reachable = ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 1))
    return truth.data & near_reachable


def score_map(
    grid: GridMap,
    truth: Grid,
    *,
    world_T_map: tuple[float, float, float] = (0.0, 0.0, 0.0),
    tolerance_cells: int = 1,
    occupied_threshold: int = 65,
) -> dict[str, float | int]:
    """Occupied-cell precision and recall of ``grid`` against ``truth``.

    Precision: map-occupied cells with a true occupied cell within the tolerance. Recall: true visible
    wall cells (see :func:`visible_surface`) with a map-occupied cell within the tolerance. Also the
    mean distance (m) from each map-occupied cell to the nearest true occupied cell.
    """
    jj, ii = np.nonzero(grid.data >= occupied_threshold)
    if len(ii) == 0:
        return {"occupied_cells": 0, "precision": 0.0, "recall": 0.0, "mean_wall_error_m": math.inf}
    pts = transform_points2(world_T_map, grid.cell_to_world(np.stack([ii, jj], axis=1)))
    tol_m = tolerance_cells * max(grid.resolution, truth.resolution)
    dist_to_truth = ndimage.distance_transform_edt(~truth.data) * truth.resolution
    cells = truth.world_to_cell(pts)
    inside = truth.in_bounds(cells)
    d = np.full(len(pts), np.inf)
    d[inside] = dist_to_truth[cells[inside, 1], cells[inside, 0]]
    # distance from a map cell centre to the nearest true cell *edge* is at most half a truth cell less.
    precision = float(np.mean(d <= tol_m + 0.5 * truth.resolution))

    spts = truth.centers(visible_surface(truth, (world_T_map[0], world_T_map[1])))
    in_map = grid.world_to_cell(inverse_transform_points2(world_T_map, spts))
    map_occ = grid.data >= occupied_threshold
    dist_to_map = ndimage.distance_transform_edt(~map_occ) * grid.resolution
    ok = grid.in_bounds(in_map)
    ds = np.full(len(spts), np.inf)
    ds[ok] = dist_to_map[in_map[ok, 1], in_map[ok, 0]]
    recall = float(np.mean(ds <= tol_m + 0.5 * grid.resolution)) if len(ds) else 0.0
    finite = d[np.isfinite(d)]
    return {
        "occupied_cells": len(pts),
        "precision": round(precision, 4),
        "recall": round(recall, 4),
        "mean_wall_error_m": round(float(finite.mean()), 4) if len(finite) else math.inf,
    }


def free_coverage(
    grid: GridMap,
    truth: Grid,
    *,
    world_T_map: tuple[float, float, float] = (0.0, 0.0, 0.0),
    robot_radius: float = 0.2,
) -> float:
    """Fraction of the true free space reachable by a robot of ``robot_radius`` from the start
    (``world_T_map``'s position) that the map marks known (free or occupied)."""
    start_xy = (world_T_map[0], world_T_map[1])
    free = ~truth.data
    clearance = ndimage.distance_transform_edt(free) * truth.resolution
    drivable = clearance > robot_radius
    labels, _ = ndimage.label(drivable)
    i, j = truth.world_to_cell(np.array([start_xy]))[0]
    reach = labels == labels[j, i]
    # The reachable region grown by the robot radius is the space the robot's sensor footprint can reach.
    reach = reach | (ndimage.binary_dilation(reach, iterations=max(1, round(robot_radius / truth.resolution))) & free)
    pts = truth.centers(reach)
    cells = grid.world_to_cell(inverse_transform_points2(world_T_map, pts))
    ok = grid.in_bounds(cells)
    known = np.zeros(len(pts), bool)
    known[ok] = grid.data[cells[ok, 1], cells[ok, 0]] >= 0
    return float(known.mean()) if len(known) else 0.0


def trajectory_error(est: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """Absolute errors between matched poses (N, 3) (x, y, yaw): mean/max position (m) and mean yaw (deg)."""
    dpos = np.hypot(est[:, 0] - truth[:, 0], est[:, 1] - truth[:, 1])
    dyaw = np.abs(wrap_angle(est[:, 2] - truth[:, 2]))
    return {
        "poses": len(est),
        "position_error_mean_m": round(float(dpos.mean()), 4),
        "position_error_max_m": round(float(dpos.max()), 4),
        "yaw_error_mean_deg": round(float(np.degrees(dyaw).mean()), 3),
    }
