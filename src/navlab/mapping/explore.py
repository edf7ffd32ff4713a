"""Frontier-based exploration (Yamauchi 1997), pure: frontiers, a clearance costmap layer and a grid planner.

Everything here works on a ``GridMap`` and numpy arrays in the map frame (metres, radians); the
node in ``explore_node.py`` feeds it ``/map``, tf and the scan, follows the plan with
``mapping.follow.PurePursuit`` and publishes ``cmd_vel``. ``ClearanceLayer`` and ``GridDijkstraPlanner``
sit behind the ``plugins.CostmapLayer`` / ``plugins.GlobalPlanner`` seams.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy import ndimage, sparse
from scipy.sparse.csgraph import dijkstra

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid, GridMap
from navlab.mapping.errors import MappingError


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
    return np.sqrt(_squared_edt(occ).astype(np.float64)) * grid.resolution


@numba.njit(cache=True)
def _squared_edt(occ: np.ndarray) -> np.ndarray:
    """Squared Euclidean distance (in cells², exact integers) from each cell to the nearest True cell of
    ``occ`` (at least one): Meijster, Roerdink & Hesselink's two-pass algorithm (as ``distance_transform_edt``
    of ``~occ``, squared)."""
    h, w = occ.shape
    far = h + w  # farther than any cell (a column without a True cell)
    g = np.empty((h, w), dtype=np.int64)
    for i in range(w):  # per column: distance to the nearest True cell in it
        g[0, i] = 0 if occ[0, i] else far
        for j in range(1, h):
            g[j, i] = 0 if occ[j, i] else g[j - 1, i] + 1
        for j in range(h - 2, -1, -1):
            if g[j + 1, i] < g[j, i]:
                g[j, i] = g[j + 1, i] + 1
    out = np.empty((h, w), dtype=np.int64)
    s = np.zeros(w, dtype=np.int64)  # per row: the lower envelope of the parabolas (x - i)² + g[i]²
    t = np.zeros(w, dtype=np.int64)
    f = np.empty(w, dtype=np.int64)
    for j in range(h):
        for i in range(w):
            f[i] = g[j, i] * g[j, i]
        q = 0
        s[0] = 0
        t[0] = 0
        for u in range(1, w):
            while q >= 0 and (t[q] - s[q]) * (t[q] - s[q]) + f[s[q]] > (t[q] - u) * (t[q] - u) + f[u]:
                q -= 1
            if q < 0:
                q = 0
                s[0] = u
            else:
                i = s[q]
                sep = 1 + (u * u - i * i + f[u] - f[i]) // (2 * (u - i))
                if sep < w:
                    q += 1
                    s[q] = u
                    t[q] = sep
        for u in range(w - 1, -1, -1):
            out[j, u] = (u - s[q]) * (u - s[q]) + f[s[q]]
            if u == t[q]:
                q -= 1
    return out


def clearance_costmap(
    grid: GridMap, robot_radius: float, *, comfort: float = 0.4, occupied_threshold: int = 65
) -> Grid:
    """costmap_2d-style costs (uint8) from an occupancy map: 254 on occupied cells, 253 within
    ``robot_radius`` of one, 255 on unknown cells, and 0..252 growing as clearance falls from
    ``robot_radius + comfort`` to the radius (quadratically), so plans keep to the middle of free space."""
    dist = clearance(grid, occupied_threshold=occupied_threshold)
    cost = np.empty(dist.shape, dtype=np.uint8)
    _clearance_costs(dist, grid.data, float(robot_radius), float(comfort), int(occupied_threshold), cost)
    return Grid(cost, grid.resolution, grid.origin, grid.frame_id)


@numba.njit(cache=True)
def _clearance_costs(dist: np.ndarray, data: np.ndarray, robot_radius: float, comfort: float,
                     occupied_threshold: int, out: np.ndarray) -> None:
    """:func:`clearance_costmap`'s costs, cell by cell: ``rint(252 clip((r + comfort - dist) / comfort, 0, 1)²)``,
    then 253 within the radius, 255 unknown, 254 occupied."""
    reach = robot_radius + comfort
    for j in range(dist.shape[0]):
        for i in range(dist.shape[1]):
            d = dist[j, i]
            v = data[j, i]
            if v >= occupied_threshold:
                out[j, i] = COST_LETHAL
            elif v < 0:
                out[j, i] = COST_UNKNOWN
            elif d <= robot_radius:
                out[j, i] = COST_INSCRIBED
            else:
                e = min(max((reach - d) / comfort, 0.0), 1.0)
                out[j, i] = np.uint8(np.rint(252.0 * (e * e)))


class ClearanceLayer:
    """``navlab::ClearanceLayer`` (a ``plugins.CostmapLayer``): the exploration planner's costs from an
    occupancy map of the same geometry as the master grid (see :func:`clearance_costmap`)."""

    def __init__(self, robot_radius: float = 0.3, comfort: float = 0.4, occupied_threshold: int = 65) -> None:
        self.robot_radius, self.comfort, self.occupied_threshold = robot_radius, comfort, occupied_threshold
        self.map: GridMap | None = None

    def set_map(self, grid: GridMap) -> None:
        """The occupancy map the costs come from."""
        self.map = grid

    def update_costs(self, master: Grid) -> None:
        """Write this layer's costs into ``master`` (the max of both, as costmap_2d combines layers)."""
        if self.map is None:
            return
        if master.data.shape != self.map.data.shape:
            raise MappingError(f"ClearanceLayer: master grid {master.data.shape} and map {self.map.data.shape} differ")
        cost = clearance_costmap(self.map, self.robot_radius, comfort=self.comfort,
                                 occupied_threshold=self.occupied_threshold).data  # fmt: skip
        np.maximum(master.data, cost, out=master.data)


class GridDijkstraPlanner:
    """``navlab/GridDijkstra`` (a ``plugins.GlobalPlanner``): 8-connected Dijkstra over costmap cells below
    ``COST_INSCRIBED`` (unknown cells only with ``allow_unknown``); a step costs its length times
    ``1 + weight * cost / 252`` averaged over its two cells. The robot may start inside the inflation:
    the nearest traversable cell within ``start_search_cells`` is used."""

    def __init__(self, *, weight: float = 4.0, allow_unknown: bool = False, start_search_cells: int = 10) -> None:
        self.weight, self.allow_unknown, self.start_search_cells = weight, allow_unknown, start_search_cells

    def traversable(self, costmap: Grid) -> np.ndarray:
        """Cells a plan may cross."""
        c = costmap.data
        return (c < COST_INSCRIBED) | ((c == COST_UNKNOWN) & self.allow_unknown)

    def distances(self, costmap: Grid, start_xy: tuple[float, float]) -> tuple[np.ndarray, np.ndarray] | None:
        """(distance in cells (H, W), predecessors) of a Dijkstra from the robot, or None if it has no
        traversable cell nearby."""
        mask = self.traversable(costmap)
        ci, cj = costmap.world_to_cell(np.array([start_xy]))[0]
        start = nearest_traversable(mask, (int(ci), int(cj)), self.start_search_cells)
        if start is None:
            return None
        mask[start[1], start[0]] = True
        cost = np.where(costmap.data < COST_INSCRIBED, costmap.data, 0).astype(np.float64)
        return grid_distances(mask, start, 1.0 + self.weight * cost / 252.0)

    def make_plan(
        self, costmap: Grid, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> np.ndarray | None:
        """A path (N, 2) in the costmap's frame from ``start`` to ``goal``, or None when none exists."""
        found = self.distances(costmap, (start[0], start[1]))
        if found is None:
            return None
        dist, pred = found
        gi, gj = (int(v) for v in costmap.world_to_cell(np.array([goal[:2]]))[0])
        if not (0 <= gi < costmap.width and 0 <= gj < costmap.height) or not np.isfinite(dist[gj, gi]):
            return None
        return costmap.cell_to_world(extract_path(pred, costmap.width, (gi, gj)))


@numba.njit(cache=True)
def _grid_graph(mask: np.ndarray, cell_cost: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CSR arrays (indptr, indices, data) of the 8-connected graph over ``mask``'s cells, columns sorted
    in each row (as scipy builds it from the edge list): a step costs its length in cells times the
    mean of ``cell_cost`` at both ends."""
    h, w = mask.shape
    n_edges = 0
    for j in range(h):
        for i in range(w):
            if mask[j, i]:
                for dj in range(-1, 2):
                    for di in range(-1, 2):
                        j2, i2 = j + dj, i + di
                        if (dj or di) and 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                            n_edges += 1
    indptr = np.zeros(h * w + 1, dtype=np.int32)
    indices = np.empty(n_edges, dtype=np.int32)
    data = np.empty(n_edges)
    diag = math.sqrt(2.0)
    e = 0
    for j in range(h):
        for i in range(w):
            a = j * w + i
            if mask[j, i]:
                for dj in range(-1, 2):  # flat index order: rows above, this row, rows below
                    for di in range(-1, 2):
                        j2, i2 = j + dj, i + di
                        if (dj or di) and 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                            b = j2 * w + i2
                            length = diag if dj and di else 1.0
                            indices[e] = b
                            data[e] = length * 0.5 * (cell_cost[a] + cell_cost[b])
                            e += 1
            indptr[a + 1] = e
    return indptr, indices, data


def grid_distances(
    mask: np.ndarray, start: tuple[int, int], cell_cost: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Dijkstra over 8-connected cells of ``mask`` from ``start`` (col i, row j).

    A step's cost is its length in cells times the mean of ``cell_cost`` (default 1) at both ends.

    Returns (distance in cells, shape of mask, inf where unreachable; predecessor flat index, -9999 if none).
    """
    h, w = mask.shape
    cost = np.ones(h * w) if cell_cost is None else np.ascontiguousarray(cell_cost, dtype=np.float64).ravel()
    indptr, indices, data = _grid_graph(np.ascontiguousarray(mask, dtype=np.bool_), cost)
    graph = sparse.csr_matrix((data, indices, indptr), shape=(h * w, h * w))
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


@numba.njit(cache=True)
def _heap_push(keys: np.ndarray, nodes: np.ndarray, size: int, key: float, node: int) -> int:
    """Push onto a binary min-heap held in ``keys``/``nodes`` (``size`` entries); returns the new size."""
    k = size
    while k > 0:
        parent = (k - 1) >> 1
        if keys[parent] <= key:
            break
        keys[k] = keys[parent]
        nodes[k] = nodes[parent]
        k = parent
    keys[k] = key
    nodes[k] = node
    return size + 1


@numba.njit(cache=True)
def _heap_pop(keys: np.ndarray, nodes: np.ndarray, size: int) -> int:
    """Remove the root of the heap (read it before); returns the new size."""
    size -= 1
    key, node = keys[size], nodes[size]
    k = 0
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= key:
            break
        keys[k] = keys[child]
        nodes[k] = nodes[child]
        k = child
    keys[k] = key
    nodes[k] = node
    return size


@numba.njit(cache=True)
def _frontier_dijkstra(
    mask: np.ndarray, cell_cost: np.ndarray, start: int, bonus: np.ndarray, resolution: float, max_bonus: float
) -> tuple[np.ndarray, np.ndarray]:
    """Dijkstra over the 8-connected cells of ``mask`` (steps cost as in :func:`grid_distances`) from flat
    cell ``start``, stopped once no unsettled cell can be a cheaper frontier goal than one already settled.

    ``bonus`` (flat) is the size bonus (m) of each goal cell (NaN: not a goal); a goal at distance d
    (cells) costs ``d * resolution - bonus``; ``max_bonus`` is the largest bonus. Returns (distance in
    cells, inf where not settled; predecessor flat index, -9999 if none), as exact as a full search
    for every settled cell.
    """
    h, w = mask.shape
    n = h * w
    dist = np.full(n, np.inf)
    pred = np.full(n, -9999, dtype=np.int32)
    done = np.zeros(n, dtype=np.bool_)
    cap = 8 * n + 1
    keys = np.empty(cap)
    nodes = np.empty(cap, dtype=np.int32)
    dist[start] = 0.0
    size = _heap_push(keys, nodes, 0, 0.0, start)
    best = np.inf
    diag = math.sqrt(2.0)
    while size > 0:
        d = keys[0]
        a = nodes[0]
        size = _heap_pop(keys, nodes, size)
        if done[a]:
            continue
        if d * resolution - max_bonus > best:
            break  # every unsettled goal costs more than the best settled one
        done[a] = True
        if not math.isnan(bonus[a]):
            best = min(best, d * resolution - bonus[a])
        j, i = a // w, a % w
        for dj in range(-1, 2):
            for di in range(-1, 2):
                j2, i2 = j + dj, i + di
                if (dj or di) and 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                    b = j2 * w + i2
                    if done[b]:
                        continue
                    length = diag if dj and di else 1.0
                    nd = d + length * 0.5 * (cell_cost[a] + cell_cost[b])
                    if nd < dist[b]:
                        dist[b] = nd
                        pred[b] = a
                        size = _heap_push(keys, nodes, size, nd, b)
    for a in range(n):
        if not done[a]:
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


def prepare_frontier_search(grid: GridMap, *, robot_radius: float = 0.3, min_frontier_cells: int = 5) -> FrontierSearch:
    """The pose-independent part of :func:`plan_to_frontier` (reusable while the map does not change)."""
    grid = grid.crop_to_known()
    planner = GridDijkstraPlanner()
    costmap = clearance_costmap(grid, robot_radius)
    cost = np.where(costmap.data < COST_INSCRIBED, costmap.data, 0).astype(np.float64)
    cell_cost = (1.0 + planner.weight * cost / 252.0).ravel()
    return FrontierSearch(grid, costmap, planner.traversable(costmap), cell_cost,
                          find_frontiers(grid, min_cells=min_frontier_cells))  # fmt: skip


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
    Frontiers whose centroid lies within 0.5 m of a blacklisted point are skipped. The Dijkstra from the
    robot stops once no cell left can be a cheaper goal (a bounded search, exact for the chosen goal).
    ``prepared``: :func:`prepare_frontier_search` of this ``grid`` with these parameters, if the caller has it.
    """
    if prepared is None:
        prepared = prepare_frontier_search(grid, robot_radius=robot_radius, min_frontier_cells=min_frontier_cells)
    grid, frontiers = prepared.grid, prepared.frontiers
    ci, cj = prepared.costmap.world_to_cell(np.array([robot_xy]))[0]
    start = nearest_traversable(prepared.mask, (int(ci), int(cj)), GridDijkstraPlanner().start_search_cells)
    if start is None:
        return None
    mask = prepared.mask.copy()
    mask[start[1], start[0]] = True
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
    flat_dist, pred = _frontier_dijkstra(mask, prepared.cell_cost, start[1] * grid.width + start[0], bonus,
                                         float(grid.resolution), float(max_bonus))  # fmt: skip
    dist = flat_dist.reshape(grid.height, grid.width)
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
    cells = extract_path(pred, grid.width, best)
    return grid.cell_to_world(cells)
