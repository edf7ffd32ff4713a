"""Scoring a SLAM map against the world's true occupancy, and a trajectory against ground truth.

The map frame of a SLAM run is the robot's start pose; the evaluator knows that pose
(``world_T_map``), so no alignment is searched. A match counts within ``tolerance_cells`` cells.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from navlab.mapping.grid import GridMap
from navlab.msgs import normalize_angle


@dataclass(frozen=True)
class TruthGrid:
    """The world's true occupancy at lidar height: ``occupied[j, i]`` for the cell whose lower-left corner
    is ``origin + (i, j) * resolution`` (world frame, metres)."""

    occupied: np.ndarray
    resolution: float
    origin: tuple[float, float]

    def cells_of(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) int (col i, row j) of world points."""
        return np.floor((xy - np.asarray(self.origin)) / self.resolution).astype(int)

    def centers(self, mask: np.ndarray) -> np.ndarray:
        """World (N, 2) centres of the cells where ``mask`` is true."""
        jj, ii = np.nonzero(mask)
        o = np.asarray(self.origin)
        return o + (np.stack([ii, jj], axis=1) + 0.5) * self.resolution

    def inside(self, ij: np.ndarray) -> np.ndarray:
        """Which cells lie inside the grid."""
        h, w = self.occupied.shape
        return (ij[:, 0] >= 0) & (ij[:, 0] < w) & (ij[:, 1] >= 0) & (ij[:, 1] < h)


def visible_surface(truth: TruthGrid, start_xy: tuple[float, float]) -> np.ndarray:
    """Occupied cells that touch the free space reachable from ``start_xy``: what a lidar can see."""
    free = ~truth.occupied
    labels, _ = ndimage.label(free)
    i, j = truth.cells_of(np.array([start_xy]))[0]
    reachable = labels == labels[j, i] if labels[j, i] > 0 else np.zeros_like(free)
    near_reachable = ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 1))
    return truth.occupied & near_reachable


def to_world(xy_map: np.ndarray, world_T_map: tuple[float, float, float]) -> np.ndarray:
    """Map-frame points (N, 2) into the world frame."""
    x, y, yaw = world_T_map
    c, s = math.cos(yaw), math.sin(yaw)
    return np.stack([x + c * xy_map[:, 0] - s * xy_map[:, 1], y + s * xy_map[:, 0] + c * xy_map[:, 1]], axis=1)


def to_map(xy_world: np.ndarray, world_T_map: tuple[float, float, float]) -> np.ndarray:
    """World-frame points (N, 2) into the map frame."""
    x, y, yaw = world_T_map
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = xy_world[:, 0] - x, xy_world[:, 1] - y
    return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=1)


def score_map(
    grid: GridMap,
    truth: TruthGrid,
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
    pts = to_world(grid.cell_to_world(np.stack([ii, jj], axis=1)), world_T_map)
    tol_m = tolerance_cells * max(grid.resolution, truth.resolution)
    dist_to_truth = ndimage.distance_transform_edt(~truth.occupied) * truth.resolution
    cells = truth.cells_of(pts)
    inside = truth.inside(cells)
    d = np.full(len(pts), np.inf)
    d[inside] = dist_to_truth[cells[inside, 1], cells[inside, 0]]
    # distance from a map cell centre to the nearest true cell *edge* is at most half a truth cell less.
    precision = float(np.mean(d <= tol_m + 0.5 * truth.resolution))

    spts = truth.centers(visible_surface(truth, (world_T_map[0], world_T_map[1])))
    in_map = grid.world_to_cell(to_map(spts, world_T_map))
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
    truth: TruthGrid,
    *,
    world_T_map: tuple[float, float, float] = (0.0, 0.0, 0.0),
    robot_radius: float = 0.2,
) -> float:
    """Fraction of the true free space reachable by a robot of ``robot_radius`` from the start
    (``world_T_map``'s position) that the map marks known (free or occupied)."""
    start_xy = (world_T_map[0], world_T_map[1])
    free = ~truth.occupied
    clearance = ndimage.distance_transform_edt(free) * truth.resolution
    drivable = clearance > robot_radius
    labels, _ = ndimage.label(drivable)
    i, j = truth.cells_of(np.array([start_xy]))[0]
    reach = labels == labels[j, i]
    # The reachable region grown by the robot radius is the space the robot's sensor footprint can reach.
    reach = reach | (ndimage.binary_dilation(reach, iterations=max(1, round(robot_radius / truth.resolution))) & free)
    pts = truth.centers(reach)
    cells = grid.world_to_cell(to_map(pts, world_T_map))
    ok = grid.in_bounds(cells)
    known = np.zeros(len(pts), bool)
    known[ok] = grid.data[cells[ok, 1], cells[ok, 0]] >= 0
    return float(known.mean()) if len(known) else 0.0


def trajectory_error(est: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """Absolute errors between matched poses (N, 3) (x, y, yaw): mean/max position (m) and mean yaw (deg)."""
    dpos = np.hypot(est[:, 0] - truth[:, 0], est[:, 1] - truth[:, 1])
    dyaw = np.abs(normalize_angle(est[:, 2] - truth[:, 2]))
    return {
        "poses": len(est),
        "position_error_mean_m": round(float(dpos.mean()), 4),
        "position_error_max_m": round(float(dpos.max()), 4),
        "yaw_error_mean_deg": round(float(np.degrees(dyaw).mean()), 3),
    }
