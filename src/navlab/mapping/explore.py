"""Frontier-based exploration (Yamauchi 1997), pure: frontiers, a grid planner, a safe path follower.

Everything here works on a ``GridMap`` and numpy arrays in the map frame (metres, radians); the
node in ``explore_node.py`` feeds it ``/map``, tf and the scan and publishes ``cmd_vel``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse.csgraph import dijkstra

from navlab.grid import GridMap

_NEIGHBOURS = ((0, 1, 1.0), (1, 0, 1.0), (1, 1, math.sqrt(2.0)), (1, -1, math.sqrt(2.0)))


@dataclass(frozen=True)
class Frontier:
    """A connected set of frontier cells: free cells next to unknown space."""

    cells: np.ndarray  # (N, 2) int (col i, row j)
    centroid: np.ndarray  # (2,) metres, map frame

    @property
    def size(self) -> int:
        """Number of cells."""
        return len(self.cells)


def find_frontiers(
    grid: GridMap, *, min_cells: int = 5, free_threshold: int = 25, occupied_threshold: int = 65
) -> list[Frontier]:
    """Clusters (8-connected) of free cells with an unknown 4-neighbour, largest first.

    Cells between the free and occupied thresholds (seen too little to decide, as map_saver's trinary
    mode would write them) count as unknown, so probabilistic maps explore like trinary ones.
    """
    d = grid.data
    free = (d >= 0) & (d < free_threshold)
    unknown = (d < 0) | ((d >= free_threshold) & (d < occupied_threshold))
    near_unknown = ndimage.binary_dilation(unknown, structure=ndimage.generate_binary_structure(2, 1))
    labels, n = ndimage.label(free & near_unknown, structure=np.ones((3, 3), bool))
    jj, ii = np.nonzero(labels)
    lab = labels[jj, ii]
    order = np.argsort(lab, kind="stable")
    bounds = np.searchsorted(lab[order], np.arange(1, n + 2))
    out = []
    for k in range(n):
        idx = order[bounds[k] : bounds[k + 1]]
        if len(idx) < min_cells:
            continue
        cells = np.stack([ii[idx], jj[idx]], axis=1)
        out.append(Frontier(cells, grid.cell_to_world(cells).mean(axis=0)))
    return sorted(out, key=lambda f: -f.size)


def traversable(
    grid: GridMap, robot_radius: float, *, occupied_threshold: int = 65, clearance_m: np.ndarray | None = None
) -> np.ndarray:
    """Cells whose centre is farther than ``robot_radius`` from every occupied cell and that are not unknown.

    Unknown cells count as not traversable, so plans stay in mapped free space. ``clearance_m`` may
    pass in :func:`clearance` when the caller has it already.
    """
    dist = clearance(grid, occupied_threshold=occupied_threshold) if clearance_m is None else clearance_m
    return (dist > robot_radius) & (grid.data >= 0) & (grid.data < occupied_threshold)


def clearance(grid: GridMap, *, occupied_threshold: int = 65) -> np.ndarray:
    """Distance (m) from each cell centre to the nearest occupied cell (inf if there is none)."""
    occ = grid.data >= occupied_threshold
    if not occ.any():
        return np.full(occ.shape, np.inf)
    return ndimage.distance_transform_edt(~occ) * grid.resolution


def clearance_cost(dist: np.ndarray, robot_radius: float, *, comfort: float = 0.4, weight: float = 4.0) -> np.ndarray:
    """Per-cell cost factor ≥ 1 that grows as clearance falls from ``robot_radius + comfort`` to the radius,
    so paths keep to the middle of free space (a costmap inflation layer's role)."""
    excess = np.clip((robot_radius + comfort - dist) / comfort, 0.0, 1.0)
    return 1.0 + weight * excess**2


def grid_distances(
    mask: np.ndarray, start: tuple[int, int], cell_cost: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Dijkstra over 8-connected cells of ``mask`` from ``start`` (col i, row j).

    A step's cost is its length in cells times the mean of ``cell_cost`` (default 1) at both ends.

    Returns (distance in cells, shape of mask, inf where unreachable; predecessor flat index, -9999 if none).
    """
    h, w = mask.shape
    jj, ii = np.nonzero(mask)
    rows, cols, costs = [], [], []
    for dj, di, cost in _NEIGHBOURS:
        j2, i2 = jj + dj, ii + di
        ok = (j2 >= 0) & (j2 < h) & (i2 >= 0) & (i2 < w)
        ok[ok] = mask[j2[ok], i2[ok]]
        a, b = jj[ok] * w + ii[ok], j2[ok] * w + i2[ok]
        c = np.full(len(a), cost) if cell_cost is None else cost * 0.5 * (cell_cost.flat[a] + cell_cost.flat[b])
        rows += [a, b]
        cols += [b, a]
        costs += [c, c]
    graph = sparse.csr_matrix(
        (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))), shape=(h * w, h * w)
    )
    s = start[1] * w + start[0]
    dist, pred = dijkstra(graph, directed=True, indices=s, return_predecessors=True)
    return dist.reshape(h, w), pred


def extract_path(pred: np.ndarray, width: int, goal: tuple[int, int]) -> np.ndarray:
    """Cells (col i, row j) from the Dijkstra start to ``goal``, following predecessors."""
    cur = goal[1] * width + goal[0]
    out = [cur]
    while pred[cur] >= 0:
        cur = int(pred[cur])
        out.append(cur)
    out.reverse()
    flat = np.array(out)
    return np.stack([flat % width, flat // width], axis=1)


def nearest_traversable(mask: np.ndarray, cell: tuple[int, int], max_cells: int = 10) -> tuple[int, int] | None:
    """The traversable cell closest to ``cell`` within ``max_cells`` (the robot may sit in inflation)."""
    i, j = cell
    h, w = mask.shape
    if 0 <= j < h and 0 <= i < w and mask[j, i]:
        return i, j
    j0, j1, i0, i1 = max(0, j - max_cells), min(h, j + max_cells + 1), max(0, i - max_cells), min(w, i + max_cells + 1)
    jj, ii = np.nonzero(mask[j0:j1, i0:i1])
    if len(ii) == 0:
        return None
    k = np.argmin((ii + i0 - i) ** 2 + (jj + j0 - j) ** 2)
    return int(ii[k] + i0), int(jj[k] + j0)


def plan_to_frontier(
    grid: GridMap,
    robot_xy: tuple[float, float],
    *,
    robot_radius: float = 0.3,
    min_frontier_cells: int = 5,
    blacklist: list[np.ndarray] | None = None,
) -> np.ndarray | None:
    """A path (N, 2) in metres from the robot to the cheapest reachable frontier, or None if none is left.

    The cost of a frontier is its path length minus a small bonus for its size (explore_lite's idea).
    Frontiers whose centroid lies within 0.5 m of a blacklisted point are skipped.
    """
    grid = grid.crop_to_known()
    dist_m = clearance(grid)
    mask = traversable(grid, robot_radius, clearance_m=dist_m)
    start_cell = tuple(int(v) for v in grid.world_to_cell(np.array([robot_xy]))[0])
    start = nearest_traversable(mask, start_cell)  # type: ignore[arg-type]
    if start is None:
        return None
    mask[start[1], start[0]] = True
    dist, pred = grid_distances(mask, start, clearance_cost(dist_m, robot_radius))
    best, best_cost = None, math.inf
    banned = np.array(blacklist).reshape(-1, 2) if blacklist else np.zeros((0, 2))
    for f in find_frontiers(grid, min_cells=min_frontier_cells):
        # Go to the frontier cell that is cheapest to reach (cells inside the inflation are unreachable),
        # skipping cells near goals that were reached or given up on before.
        d = dist[f.cells[:, 1], f.cells[:, 0]]
        if len(banned):
            xy = grid.cell_to_world(f.cells)
            near = np.hypot(xy[:, None, 0] - banned[None, :, 0], xy[:, None, 1] - banned[None, :, 1]).min(axis=1)
            d = np.where(near < 0.5, np.inf, d)
        reach = np.isfinite(d)
        if not reach.any():
            continue
        k = int(np.argmin(d))
        cost = d[k] * grid.resolution - 0.02 * f.size * grid.resolution
        if cost < best_cost:
            best, best_cost = (int(f.cells[k, 0]), int(f.cells[k, 1])), cost
    if best is None:
        return None
    cells = extract_path(pred, grid.width, best)
    return grid.cell_to_world(cells)


def follow_path(
    pose: tuple[float, float, float],
    path: np.ndarray,
    *,
    lookahead: float = 0.4,
    max_v: float = 0.35,
    max_w: float = 1.2,
    min_front_range: float = float("inf"),
    stop_distance: float = 0.35,
) -> tuple[float, float, int]:
    """Pure pursuit toward the point ``lookahead`` ahead on ``path``; returns (v m/s, w rad/s, index reached).

    Turns in place when the target is more than ~60° off the heading; stops forward motion when the
    closest scan return ahead (``min_front_range``) is under ``stop_distance``.
    """
    x, y, yaw = pose
    d = np.hypot(path[:, 0] - x, path[:, 1] - y)
    nearest = int(np.argmin(d))
    ahead = np.nonzero(d[nearest:] >= lookahead)[0]
    k = nearest + int(ahead[0]) if len(ahead) else len(path) - 1
    tx, ty = path[k]
    dx, dy = tx - x, ty - y
    c, s = math.cos(yaw), math.sin(yaw)
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    heading_err = math.atan2(ly, lx)
    w = float(np.clip(2.0 * heading_err, -max_w, max_w))
    if abs(heading_err) > 1.0:
        return 0.0, w, nearest
    v = max_v * max(0.0, math.cos(heading_err))
    v = min(v, 0.8 * math.hypot(dx, dy) + 0.05)
    if min_front_range < stop_distance:
        v = 0.0
    return float(v), w, nearest
