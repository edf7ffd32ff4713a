"""base_local_planner's MapGrid: cell distances (4-connected steps) to the plan or to the local goal.

A breadth-first wave grows from seed cells over the local costmap; cells with cost LETHAL, INSCRIBED or
NO_INFORMATION stop it and read ``obstacle_value`` (= cells in the grid), cells it never reaches read
``unreachable_value`` (= cells + 1). Both mark a trajectory end as hopeless. Distances are in cells.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.grid import COST_INSCRIBED, COST_UNKNOWN

Wave = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # wave_start's (dist, mark, free, queue, ends)


@numba.njit(cache=True)
def wave_start(
    cost: np.ndarray, seeds_i: np.ndarray, seeds_j: np.ndarray, free_i: np.ndarray, free_j: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """A :func:`distance_map` wave from the seed cells (columns ``seeds_i``, rows ``seeds_j``), the cells
    (``free_i``, ``free_j``) never obstacles, seeded but not grown: (distances (H, W), reached (H, W), free (H, W),
    the queue (2, H * W), its (head, tail)). :func:`wave_to` grows it as far as a lookup needs; a cell's distance is
    final once it is reached, the same whenever the wave stops, so a wave grown in part reads as the whole."""
    h, w = cost.shape
    out = np.full((h, w), float(h * w) + 1.0)
    mark = np.zeros((h, w), dtype=np.bool_)
    free = np.zeros((h, w), dtype=np.bool_)
    for k in range(free_i.size):
        free[free_j[k], free_i[k]] = True
    queue = np.empty((2, h * w), dtype=np.int64)
    tail = 0
    for k in range(seeds_i.size):
        i, j = seeds_i[k], seeds_j[k]
        if not mark[j, i]:
            mark[j, i] = True
            out[j, i] = 0.0
            queue[0, tail], queue[1, tail] = i, j
            tail += 1
    return out, mark, free, queue, np.array([0, tail], dtype=np.int64)


@numba.njit(cache=True)
def wave_to(
    cost: np.ndarray, wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray], i: int, j: int
) -> float:  # pragma: no cover - compiled
    """The wave's distance at cell (i, j) (inside the grid), grown (breadth first, 4-connected, LETHAL/INSCRIBED/
    unknown cells stop it) until it reaches that cell or can grow no further; ``i`` < 0: grow it to the end."""
    out, mark, free, queue, ends = wave
    return grow(cost, out, mark, free, queue, ends, i, j)


@numba.njit(cache=True)
def grow(
    cost: np.ndarray,
    out: np.ndarray,
    mark: np.ndarray,
    free: np.ndarray,
    queue: np.ndarray,
    ends: np.ndarray,
    i: int,
    j: int,
) -> float:  # pragma: no cover - compiled
    """:func:`wave_to` on the wave's arrays."""
    if i >= 0 and mark[j, i]:
        return out[j, i]
    h, w = cost.shape
    obstacle = float(h * w)
    head, tail = ends[0], ends[1]
    di = (-1, 1, 0, 0)
    dj = (0, 0, -1, 1)
    while head < tail and (i < 0 or not mark[j, i]):
        ci, cj = queue[0, head], queue[1, head]
        head += 1
        for n in range(4):
            ni, nj = ci + di[n], cj + dj[n]
            if ni < 0 or nj < 0 or ni >= w or nj >= h or mark[nj, ni]:
                continue
            mark[nj, ni] = True
            if cost[nj, ni] >= COST_INSCRIBED and not free[nj, ni]:
                out[nj, ni] = obstacle
                continue
            out[nj, ni] = out[cj, ci] + 1.0
            queue[0, tail], queue[1, tail] = ni, nj
            tail += 1
    ends[0], ends[1] = head, tail
    return out[j, i] if i >= 0 else 0.0


@numba.njit(cache=True)
def wave(
    cost: np.ndarray, seeds_i: np.ndarray, seeds_j: np.ndarray, free_i: np.ndarray, free_j: np.ndarray, out: np.ndarray
) -> None:  # pragma: no cover - compiled
    """:func:`distance_map` into ``out`` from the seed cells (columns ``seeds_i``, rows ``seeds_j``), the cells
    (``free_i``, ``free_j``) never obstacles."""
    grown = wave_start(cost, seeds_i, seeds_j, free_i, free_j)
    wave_to(cost, grown, -1, -1)
    out[:, :] = grown[0]


def plan_cells(cost: np.ndarray, plan_xy: np.ndarray, resolution: float) -> np.ndarray:
    """Cells (K, 2) as (i, j) of the plan's first stretch inside the grid (grid-local plan points, m).

    The plan is densified to the resolution (``common.densify``'s points); cells of unknown cost break it
    (ROS's ``setTargetCells``).
    """
    xy = np.ascontiguousarray(np.asarray(plan_xy, dtype=np.float64)[:, :2])
    if len(xy) >= 2:
        seg = np.diff(xy, axis=0)
        n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / resolution).astype(np.int64))
    else:
        n = np.zeros(0, dtype=np.int64)
    return cells_along(np.ascontiguousarray(cost), xy, n, float(resolution))


@numba.njit(cache=True)
def cells_along(cost: np.ndarray, xy: np.ndarray, n: np.ndarray, res: float) -> np.ndarray:  # pragma: no cover
    """:func:`plan_cells` of the grid-local points ``xy`` (N, 2) whose segments are cut in ``n`` (N - 1,) steps."""
    h, w = cost.shape
    total = n.sum() + 1 if xy.shape[0] >= 2 else xy.shape[0]
    out = np.empty((total, 2), dtype=np.int64)
    count = 0
    s, q = 0, 0  # the point: segment s, step q of n[s] (densify's order), then the plan's last point
    for _ in range(total):
        if s < n.size:
            frac = q / n[s]
            px = xy[s, 0] + (xy[s + 1, 0] - xy[s, 0]) * frac
            py = xy[s, 1] + (xy[s + 1, 1] - xy[s, 1]) * frac
            q += 1
            if q == n[s]:
                s, q = s + 1, 0
        else:
            px, py = xy[xy.shape[0] - 1, 0], xy[xy.shape[0] - 1, 1]
        i, j = math.floor(px / res), math.floor(py / res)
        inside = 0 <= i < w and 0 <= j < h and cost[j, i] != COST_UNKNOWN
        if not inside:
            if count > 0:
                break
            continue
        if count == 0 or out[count - 1, 0] != i or out[count - 1, 1] != j:
            out[count, 0], out[count, 1] = i, j
            count += 1
    return out[:count].copy()


def distance_map(cost: np.ndarray, seeds: np.ndarray, free: np.ndarray | None = None) -> np.ndarray:
    """Cell distances (float, same shape as ``cost``) from the ``seeds`` cells (K, 2) as (i, j).

    ``free`` cells (K', 2) are never obstacles (base_local_planner's cells "within the robot").
    """
    out = np.empty(cost.shape, dtype=np.float64)
    seeds = np.asarray(seeds, dtype=np.int64).reshape(-1, 2)
    free = np.zeros((0, 2), dtype=np.int64) if free is None else np.asarray(free, dtype=np.int64).reshape(-1, 2)
    wave(np.ascontiguousarray(cost), seeds[:, 0].copy(), seeds[:, 1].copy(), free[:, 0].copy(), free[:, 1].copy(), out)
    return out
