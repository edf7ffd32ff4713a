"""The reference path of a BARN-style clutter world (:mod:`navlab.world.clutter`): the shortest collision-free path
for a disc, and the bottleneck of the widest route, searched on a 0.05 m grid of exact clearances (m, world frame).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from navlab.world.barn_grid import CELL, FIELD

if TYPE_CHECKING:
    from navlab.world.clutter import Box
    from navlab.world.clutter_geometry import Clearance

_REF_RES = 0.05  # m: grid of the reference-path search and the corridor check
WALL_THICKNESS = CELL  # m: a containment wall is a row of touching cylinders


# ------------------------------------------------------------------------------------ grid search
def _grid_dijkstra(
    passable: np.ndarray, enter_cost: np.ndarray, step: float, source: int, target: int
) -> list[int] | None:
    """Cheapest 8-connected path of flat cell indices from ``source`` to ``target``, or None.

    A move costs its length (``step`` or ``step`` sqrt 2) times ``1 + enter_cost`` of the cell entered.
    """
    ny, nx = passable.shape
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, weights = [], [], []
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = idx[: ny - di, max(0, -dj) : nx - max(0, dj)]  # (i, j) -> (i + di, j + dj), di >= 0
        b = idx[di:, max(0, dj) : nx - max(0, -dj)]
        a, b = a.ravel(), b.ravel()
        ok = passable.ravel()[a] & passable.ravel()[b]
        a, b = a[ok], b[ok]
        length = step * math.hypot(di, dj)
        cost = enter_cost.ravel()
        rows += [a, b]
        cols += [b, a]
        weights += [length * (1.0 + cost[b]), length * (1.0 + cost[a])]
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(ny * nx, ny * nx)
    ).tocsr()
    dist, pred = dijkstra(graph, indices=source, return_predecessors=True)
    if not np.isfinite(dist[target]):
        return None
    path = [target]
    while path[-1] != source:
        path.append(int(pred[path[-1]]))
    return path[::-1]


# ------------------------------------------------------------------------------- reference path
def _search_grid(walls: list[Box], goal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centre x and y (m) of the 0.05 m grid the reference path is searched on."""
    x0 = min(w.x - w.sx / 2 for w in walls) - 0.25
    x1 = goal[0] + 1.0
    y1 = FIELD / 2 + WALL_THICKNESS + 0.5
    xs = np.arange(x0 + _REF_RES / 2, x1, _REF_RES)
    ys = np.arange(-y1 + _REF_RES / 2, y1, _REF_RES)
    return xs, ys


Grid = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # x, y, points (n, 2), clearance (len(y), len(x))


def clearance_grid(clearance: Clearance, walls: list[Box], goal: np.ndarray) -> Grid:
    """The search grid's cell centres and their exact clearances (m), for :func:`reference_path` and
    :func:`bottleneck` (compute once, pass to both)."""
    xs, ys = _search_grid(walls, goal)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.c_[gx.ravel(), gy.ravel()]
    return xs, ys, pts, clearance(pts).reshape(gx.shape)


def cell_of(xs: np.ndarray, ys: np.ndarray, p: np.ndarray) -> int:
    return int(np.argmin(np.abs(ys - p[1])) * len(xs) + np.argmin(np.abs(xs - p[0])))


def reference_path(
    clearance: Clearance,
    walls: list[Box],
    start: np.ndarray,
    goal: np.ndarray,
    radius: float,
    *,
    grid: Grid | None = None,
) -> np.ndarray | None:
    """Shortest collision-free path (n, 2) for a disc of ``radius`` from start to goal, or None.

    8-connected Dijkstra over the 0.05 m grid cells whose exact clearance is >= ``radius``, then
    shortened by line of sight: from each vertex, on to the farthest grid-path point it sees (exact
    segment tests against the cylinders and walls). ``grid``: :func:`clearance_grid`'s, if the caller has it.
    """
    xs, ys, pts, clear = clearance_grid(clearance, walls, goal) if grid is None else grid
    free = clear >= radius
    s, g = cell_of(xs, ys, start), cell_of(xs, ys, goal)
    if not (free.ravel()[s] and free.ravel()[g]):
        return None
    cells = _grid_dijkstra(free, np.zeros(free.shape), _REF_RES, s, g)
    if cells is None:
        return None
    raw = np.vstack([start, pts[cells[1:-1]], goal])
    out, i = [raw[0]], 0
    while i < len(raw) - 1:
        seen = np.flatnonzero(clearance.segments_clear(raw[i], raw[i + 2 :], radius))
        i = i + 2 + int(seen[-1]) if len(seen) else i + 1
        out.append(raw[i])
    return np.array(out)


def connected(free: np.ndarray, a: int, b: int) -> bool:
    labels, _ = ndimage.label(free, structure=np.ones((3, 3)))
    la, lb = labels.ravel()[a], labels.ravel()[b]
    return bool(la and la == lb)


def bottleneck(
    clearance: Clearance,
    walls: list[Box],
    start: np.ndarray,
    goal: np.ndarray,
    tol: float = 0.005,
    *,
    grid: Grid | None = None,
) -> float:
    """Half-width (m) of the narrowest passage on the widest route: the largest clearance c for which
    start and goal connect through 0.05 m cells with clearance >= c (bisection to ``tol``). ``grid``:
    :func:`clearance_grid`'s, if the caller has it."""
    xs, ys, _, clear = clearance_grid(clearance, walls, goal) if grid is None else grid
    a, b = cell_of(xs, ys, start), cell_of(xs, ys, goal)
    lo, hi = 0.0, float(min(clear.ravel()[a], clear.ravel()[b]))
    if connected(clear >= hi, a, b):
        return hi
    while hi - lo > tol:
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if connected(clear >= mid, a, b) else (lo, mid)
    return lo
