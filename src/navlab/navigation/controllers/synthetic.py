"""Hand-made costmaps and plans for the controllers' tests, benchmark and examples.

``inflated`` turns an obstacle mask into costmap_2d costs (LETHAL at obstacles, INSCRIBED within the
robot's inscribed radius, ``252 * exp(-cost_scaling_factor * (d - inscribed))`` out to
``inflation_radius``), the InflationLayer's formula. ``clutter`` scatters round obstacles from a seeded
generator; ``grid_plan`` is a small cost-aware 8-connected Dijkstra planner standing in for navfn;
``window`` crops a rolling local costmap around the robot. Units: m; grids in the ``odom`` frame.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from navlab.grid import COST_INSCRIBED, COST_LETHAL, Grid
from navlab.navigation.errors import NavigationError


def inflated(
    obstacles: np.ndarray,
    resolution: float,
    *,
    inscribed_radius: float = 0.2,
    inflation_radius: float = 0.55,
    cost_scaling_factor: float = 10.0,
) -> np.ndarray:
    """costmap_2d costs (uint8, same shape) of a boolean obstacle mask (rows = y)."""
    d = ndimage.distance_transform_edt(~obstacles) * resolution
    cost = np.zeros(obstacles.shape, dtype=np.uint8)
    ramp = (d > inscribed_radius) & (d <= inflation_radius)
    cost[ramp] = (252.0 * np.exp(-cost_scaling_factor * (d[ramp] - inscribed_radius))).astype(np.uint8)
    cost[d <= inscribed_radius] = COST_INSCRIBED
    cost[obstacles] = COST_LETHAL
    return cost


def disc_mask(
    shape: tuple[int, int],
    resolution: float,
    centres: np.ndarray,
    radii: np.ndarray,
    origin: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Boolean mask of the cells whose centres lie in any of the discs (centres (K, 2), radii (K,), m)."""
    h, w = shape
    ys, xs = (np.arange(h) + 0.5) * resolution + origin[1], (np.arange(w) + 0.5) * resolution + origin[0]
    mask = np.zeros(shape, dtype=bool)
    for (cx, cy), r in zip(np.asarray(centres).reshape(-1, 2), np.asarray(radii).reshape(-1), strict=True):
        mask |= ((xs[None, :] - cx) ** 2 + (ys[:, None] - cy) ** 2) <= r * r
    return mask


def clutter(
    rng: np.random.Generator,
    *,
    size: float = 8.0,
    resolution: float = 0.05,
    count: int = 30,
    radius: tuple[float, float] = (0.1, 0.25),
    keep_clear: tuple[tuple[float, float], ...] = (),
    clear_radius: float = 0.6,
    walls: bool = True,
) -> np.ndarray:
    """An obstacle mask (n, n) of a ``size`` m square room with ``count`` round obstacles (radii in
    ``radius``) placed from ``rng``, none within ``clear_radius`` of the ``keep_clear`` points."""
    n = round(size / resolution)
    centres: list[np.ndarray] = []
    radii: list[float] = []
    while len(centres) < count:
        c = rng.uniform(0.3, size - 0.3, 2)
        r = rng.uniform(*radius)
        if all(math.dist(c, k) > clear_radius + r for k in keep_clear):
            centres.append(c)
            radii.append(r)
    mask = disc_mask((n, n), resolution, np.array(centres), np.array(radii))
    if walls:
        mask[:2, :] = mask[-2:, :] = mask[:, :2] = mask[:, -2:] = True
    return mask


def grid_plan(
    costmap: Grid, start: tuple[float, float], goal: tuple[float, float], *, cost_factor: float = 3.0 / 252.0
) -> np.ndarray:
    """A path (N, 3) from ``start`` to ``goal`` over a costmap: 8-connected Dijkstra (no cutting corners),
    step length times (1 + cost_factor * cost), cells >= INSCRIBED forbidden; yaw along the path, the last
    one repeated.

    Raises ``NavigationError`` if the goal cannot be reached.
    """
    cost = np.asarray(costmap.data)
    h, w = cost.shape
    ok = cost < COST_INSCRIBED
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, wts = [], [], []
    for dj, di in ((0, 1), (1, 0), (1, 1), (1, -1)):
        i0, i1 = max(0, -di), w - max(0, di)
        a = (slice(0, h - dj), slice(i0, i1))
        b = (slice(dj, h), slice(i0 + di, i1 + di))
        both = ok[a] & ok[b]
        if di and dj:  # no corner cutting: a diagonal step needs both cells beside it free
            both &= ok[(a[0], b[1])] & ok[(b[0], a[1])]
        step = math.hypot(di, dj) * (1.0 + cost_factor * 0.5 * (cost[a].astype(float) + cost[b]))
        rows.append(idx[a][both])
        cols.append(idx[b][both])
        wts.append(step[both])
    g = sparse.coo_matrix((np.concatenate(wts), (np.concatenate(rows), np.concatenate(cols))), shape=(h * w,) * 2)
    s_ij, g_ij = costmap.world_to_cell(np.array([start, goal]))
    s, t = s_ij[1] * w + s_ij[0], g_ij[1] * w + g_ij[0]
    _, pred = csgraph.dijkstra(g.tocsr(), directed=False, indices=s, return_predecessors=True)
    if pred[t] < 0 and t != s:
        raise NavigationError(f"grid_plan: no path from {start} to {goal}")
    chain = [t]
    while chain[-1] != s:
        chain.append(pred[chain[-1]])
    cells = np.array([[c % w, c // w] for c in chain[::-1]])
    xy = costmap.cell_to_world(cells)
    xy[0], xy[-1] = start, goal
    d = np.diff(xy, axis=0)
    yaw = np.append(np.arctan2(d[:, 1], d[:, 0]), 0.0)
    yaw[-1] = yaw[-2] if len(yaw) > 1 else 0.0
    return np.column_stack([xy, yaw])


def window(costmap: Grid, x: float, y: float, size: float = 4.0) -> Grid:
    """The rolling local costmap: a ``size`` m square of ``costmap`` centred on (x, y) (cells outside read
    as free, as a rolling window's unseen cells with ``track_unknown_space: false``)."""
    n = round(size / costmap.resolution)
    i0, j0 = costmap.world_to_cell(np.array([[x - size / 2, y - size / 2]]))[0]
    data = np.zeros((n, n), dtype=np.uint8)
    h, w = costmap.data.shape
    si, sj = slice(max(0, i0), min(w, i0 + n)), slice(max(0, j0), min(h, j0 + n))
    data[sj.start - j0 : sj.stop - j0, si.start - i0 : si.stop - i0] = costmap.data[sj, si]
    return Grid(data, costmap.resolution, costmap.sub_origin(int(i0), int(j0)), "odom")
