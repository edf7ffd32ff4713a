"""Frontier-based exploration (Yamauchi 1997), pure: frontiers of a SLAM map and the plan to the cheapest one.

Everything here works on a ``GridMap`` and numpy arrays in the map frame (metres, radians). The plan runs on
navigation's costmap layers (``costmap_2d::StaticLayer`` over the map, unknown space tracked, then
``costmap_2d::InflationLayer``) and a Dijkstra over the cells on navigation's indexed heap, stopped once no
frontier left can be cheaper. The node in ``drivers/explore.py`` feeds it ``/map``, tf and the scan, follows
the plan with ``navigation.controllers.pure_pursuit.PurePursuit`` and publishes ``cmd_vel``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy import ndimage

from navlab.grid import COST_INSCRIBED, Grid, GridMap
from navlab.navigation import Footprint, InflationLayer, StaticLayer, iheap_pop, iheap_update

OCCUPIED_THRESHOLD = 65  # occupancy (%) from which a cell is an obstacle (map_server's occupied_thresh 0.65)
COMFORT = 0.4  # m beyond the robot radius over which the costs fall to 0 (plans keep to the middle)
COST_SCALING = 7.5  # 1/m: the inflation's decay over COMFORT (3 / COMFORT: as costly on average as a quadratic)
WEIGHT = 4.0  # a step costs its length times 1 + WEIGHT * cost / 252 (mean of its two cells)
START_SEARCH_CELLS = 10  # the robot may sit in the inflation: the nearest traversable cell this near is used


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
    near_unknown = unknown.copy()  # binary dilation by the 4-neighbourhood, as four shifted ORs
    near_unknown[1:] |= unknown[:-1]
    near_unknown[:-1] |= unknown[1:]
    near_unknown[:, 1:] |= unknown[:, :-1]
    near_unknown[:, :-1] |= unknown[:, 1:]
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


def exploration_costmap(
    grid: GridMap, robot_radius: float, *, comfort: float = COMFORT, cost_scaling_factor: float | None = None
) -> Grid:
    """costmap_2d costs (uint8) of an occupancy map, from navigation's layers: a ``StaticLayer`` (trinary at
    ``OCCUPIED_THRESHOLD``, unknown cells 255) and an ``InflationLayer`` for a round robot of ``robot_radius``
    (253 within it of an obstacle, then falling off over ``comfort`` m at ``cost_scaling_factor``, by default
    ``3 / comfort``)."""
    master = Grid(np.zeros(grid.data.shape, dtype=np.uint8), grid.resolution, grid.origin, grid.frame_id)
    static = StaticLayer({"track_unknown_space": True, "lethal_cost_threshold": OCCUPIED_THRESHOLD})
    static.set_map(grid)
    static.update_costs(master)
    scaling = 3.0 / comfort if cost_scaling_factor is None else cost_scaling_factor
    inflation = InflationLayer(
        {"inflation_radius": robot_radius + comfort, "cost_scaling_factor": scaling},
        footprint=Footprint(float(robot_radius), None),
    )
    inflation.update_costs(master)
    return master


def traversable(costmap: Grid) -> np.ndarray:
    """Cells a plan may cross: known and farther than the robot radius from every obstacle."""
    return costmap.data < COST_INSCRIBED


def nearest_traversable(
    mask: np.ndarray, cell: tuple[int, int], max_cells: int = START_SEARCH_CELLS
) -> tuple[int, int] | None:
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


@numba.njit(cache=True)
def _frontier_dijkstra(
    mask: np.ndarray, cell_cost: np.ndarray, start: int, bonus: np.ndarray, resolution: float, max_bonus: float
) -> tuple[np.ndarray, np.ndarray]:
    """Dijkstra over the 8-connected cells of ``mask`` from flat cell ``start`` (a step costs its length in
    cells times the mean of ``cell_cost`` at its two ends), stopped once no unsettled cell can be a cheaper
    frontier goal than one already settled.

    ``bonus`` (flat) is the size bonus (m) of each goal cell (NaN: not a goal); a goal at distance d
    (cells) costs ``d * resolution - bonus``; ``max_bonus`` is the largest bonus (inf: a full search).
    Returns (distance in cells, inf where not settled; predecessor flat index, -9999 if none), as exact as
    a full search for every settled cell.
    """
    h, w = mask.shape
    n = h * w
    dist = np.full(n, np.inf)
    pred = np.full(n, -9999, dtype=np.int32)
    pos = np.full(n, -1, dtype=np.int64)  # heap slot; -1 never queued, -2 settled
    keys = np.empty(n)
    vals = np.empty(n, dtype=np.int64)
    dist[start] = 0.0
    size = iheap_update(keys, vals, pos, 0, 0.0, start)
    best = np.inf
    diag = math.sqrt(2.0)
    while size > 0:
        d = keys[0]
        a = vals[0]
        if d * resolution - max_bonus > best:
            break  # every unsettled goal costs more than the best settled one
        size = iheap_pop(keys, vals, pos, size)
        if not math.isnan(bonus[a]):
            best = min(best, d * resolution - bonus[a])
        j, i = a // w, a % w
        for dj in range(-1, 2):
            for di in range(-1, 2):
                j2, i2 = j + dj, i + di
                if (dj or di) and 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                    b = j2 * w + i2
                    if pos[b] == -2:
                        continue
                    length = diag if dj and di else 1.0
                    nd = d + length * 0.5 * (cell_cost[a] + cell_cost[b])
                    if nd < dist[b]:
                        dist[b] = nd
                        pred[b] = a
                        size = iheap_update(keys, vals, pos, size, nd, b)
    for a in range(n):
        if pos[a] != -2:
            dist[a] = np.inf
    return dist, pred


@dataclass(frozen=True)
class FrontierSearch:
    """What a frontier plan needs from one map, whatever the robot's pose: the map cropped to its known
    part, the planner's costmap, its traversable cells, step costs and the frontiers (largest first)."""

    grid: GridMap
    costmap: Grid
    mask: np.ndarray  # (H, W) bool, cells a plan may cross
    cell_cost: np.ndarray  # (H * W,) step cost factor per cell
    frontiers: list[Frontier]

    def start_cell(self, robot_xy: tuple[float, float]) -> tuple[int, int] | None:
        """The traversable cell the search starts from (the robot's, or the nearest one)."""
        ci, cj = self.costmap.world_to_cell(np.array([robot_xy]))[0]
        return nearest_traversable(self.mask, (int(ci), int(cj)))

    def distances(
        self, robot_xy: tuple[float, float], bonus: np.ndarray | None = None, max_bonus: float = np.inf
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """(step-cost distance in cells (H, W), flat predecessors) from the robot: every reachable cell, or
        with ``bonus`` the bounded search of :func:`plan_to_frontier`; None if no cell near the robot is free."""
        start = self.start_cell(robot_xy)
        if start is None:
            return None
        mask = self.mask.copy()
        mask[start[1], start[0]] = True
        g = self.grid
        goals = np.full(g.width * g.height, np.nan) if bonus is None else bonus
        flat, pred = _frontier_dijkstra(
            mask, self.cell_cost, start[1] * g.width + start[0], goals, float(g.resolution), float(max_bonus)
        )
        return flat.reshape(g.height, g.width), pred


def prepare_frontier_search(grid: GridMap, *, robot_radius: float = 0.3, min_frontier_cells: int = 5) -> FrontierSearch:
    """The pose-independent part of :func:`plan_to_frontier` (reusable while the map does not change)."""
    grid = grid.crop_to_known()
    costmap = exploration_costmap(grid, robot_radius)
    cost = np.where(costmap.data < COST_INSCRIBED, costmap.data, 0).astype(np.float64)
    cell_cost = (1.0 + WEIGHT * cost / 252.0).ravel()
    return FrontierSearch(
        grid,
        costmap,
        traversable(costmap),
        cell_cost,
        find_frontiers(grid, min_cells=min_frontier_cells, occupied_threshold=OCCUPIED_THRESHOLD),
    )


def plan_to_frontier(
    grid: GridMap,
    robot_xy: tuple[float, float],
    *,
    robot_radius: float = 0.3,
    min_frontier_cells: int = 5,
    blacklist: list[np.ndarray] | None = None,
    prepared: FrontierSearch | None = None,
) -> np.ndarray | None:
    """A path (N, 2) in metres from the robot to the cheapest reachable frontier, or None if none is left.

    The cost of a frontier is its path length minus a small bonus for its size (explore_lite's idea).
    Frontier cells within 0.5 m of a blacklisted point are skipped. The Dijkstra from the robot stops once
    no cell left can be a cheaper goal (a bounded search, exact for the chosen goal).
    ``prepared``: :func:`prepare_frontier_search` of this ``grid`` with these parameters, if the caller has it.
    """
    if prepared is None:
        prepared = prepare_frontier_search(grid, robot_radius=robot_radius, min_frontier_cells=min_frontier_cells)
    grid, frontiers = prepared.grid, prepared.frontiers
    banned = np.array(blacklist).reshape(-1, 2) if blacklist else np.zeros((0, 2))
    # the goal cells (not near a banned point) and their size bonus, for the bounded search
    goal_cells = []
    for f in frontiers:
        ok = np.ones(len(f.cells), dtype=bool)
        if len(banned):
            xy = grid.cell_to_world(f.cells)
            near = np.hypot(xy[:, None, 0] - banned[None, :, 0], xy[:, None, 1] - banned[None, :, 1]).min(axis=1)
            ok = near >= 0.5
        goal_cells.append(ok)
    bonus = np.full(grid.width * grid.height, np.nan)
    max_bonus = -np.inf
    for f, ok in zip(frontiers, goal_cells, strict=True):
        if ok.any():
            b = 0.02 * f.size * grid.resolution
            bonus[f.cells[ok, 1] * grid.width + f.cells[ok, 0]] = b
            max_bonus = max(max_bonus, b)
    if max_bonus == -np.inf:
        return None
    found = prepared.distances(robot_xy, bonus, max_bonus)
    if found is None:
        return None
    dist, pred = found
    best, best_cost = None, math.inf
    for f, ok in zip(frontiers, goal_cells, strict=True):
        # Go to the frontier cell that is cheapest to reach (cells inside the inflation are unreachable),
        # skipping cells near goals that were reached or given up on before.
        d = np.where(ok, dist[f.cells[:, 1], f.cells[:, 0]], np.inf)
        reach = np.isfinite(d)
        if not reach.any():
            continue
        k = int(np.argmin(d))
        cost_f = d[k] * grid.resolution - 0.02 * f.size * grid.resolution
        if cost_f < best_cost:
            best, best_cost = (int(f.cells[k, 0]), int(f.cells[k, 1])), cost_f
    if best is None:
        return None
    return grid.cell_to_world(extract_path(pred, grid.width, best))
