"""Compiled whole-grid steps of the costmap layers (Numba): combining a layer into the master, and the
inflation layer's distance step.

``inflate_box``: exact squared cell distances to the nearest lethal cell (Felzenszwalb & Huttenlocher's
separable distance transform, "Distance Transforms of Sampled Functions", 2012) turned into costs through
the layer's table, for one box of the grid. The squared distances are integers computed exactly, so the
costs equal those of a Euclidean distance transform of the same seeds (scipy's ``distance_transform_edt``),
bit for bit, without its feature arrays. Cells are ``data[j, i]`` (row ``j``, column ``i``), as everywhere
in ``navlab.grid``; costs are uint8 (255 unknown).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.grid import COST_UNKNOWN

_FAR = 1 << 40  # "no seed in this column": beyond any real squared distance of a grid


@numba.njit(cache=True)
def inflate_box(
    seeds: np.ndarray,
    region: tuple[int, int, int, int],
    box: tuple[int, int, int, int],
    table: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """``out`` (the box's shape) = ``table[d2]`` for each cell of ``box`` = (j0, j1, i0, i1), ``d2`` its squared
    distance in cells to the nearest true cell of ``seeds`` inside ``region`` = (o0, o1, p0, p1) (which holds the
    box), the table's last entry from its end on (and where the region has no seed)."""
    o0, o1, p0, p1 = region
    j0, j1, i0, i1 = box
    rows, cols = o1 - o0, p1 - p0
    last = table.size - 1
    # pass 1: per column, the distance (cells) to the nearest seed in that column, _FAR if none
    g = np.empty((rows, cols), dtype=np.int64)
    for c in range(cols):
        d = _FAR
        for r in range(rows):
            if seeds[o0 + r, p0 + c]:
                d = 0
            elif d != _FAR:
                d += 1
            g[r, c] = d
        d = _FAR
        for r in range(rows - 1, -1, -1):
            if seeds[o0 + r, p0 + c]:
                d = 0
            elif d != _FAR:
                d += 1
            if d < g[r, c]:
                g[r, c] = d
    # pass 2: per row of the box, the lower envelope of the parabolas (i - q)^2 + g[q]^2 over the columns q
    v = np.empty(cols, dtype=np.int64)
    z = np.empty(cols + 1, dtype=np.float64)
    for r in range(j0 - o0, j1 - o0):
        k = -1
        for q in range(cols):
            if g[r, q] == _FAR:
                continue
            fq = g[r, q] * g[r, q] + q * q
            s = 0.0
            while k >= 0:
                p = v[k]
                s = (fq - (g[r, p] * g[r, p] + p * p)) / (2.0 * (q - p))
                if s <= z[k]:
                    k -= 1
                else:
                    break
            k += 1
            v[k] = q
            z[k] = -math.inf if k == 0 else s
            z[k + 1] = math.inf
        m = 0
        for i in range(i0 - p0, i1 - p0):
            if k < 0:
                out[r - (j0 - o0), i - (i0 - p0)] = table[last]
                continue
            while z[m + 1] < i:
                m += 1
            q = v[m]
            d2 = (i - q) * (i - q) + g[r, q] * g[r, q]
            out[r - (j0 - o0), i - (i0 - p0)] = table[d2 if d2 < last else last]


@numba.njit(cache=True)
def combine(master: np.ndarray, layer: np.ndarray, maximum: bool) -> None:  # pragma: no cover - compiled
    """A layer's known cells into ``master`` (same shape): with ``maximum`` where the layer's cost is higher or
    the master's unknown (costmap_2d's ``updateWithMax``), else every known cell (``updateWithOverwrite``)."""
    for j in range(master.shape[0]):
        for i in range(master.shape[1]):
            c = layer[j, i]
            if c == COST_UNKNOWN:
                continue
            if not maximum or master[j, i] == COST_UNKNOWN or master[j, i] < c:
                master[j, i] = c


@numba.njit(cache=True)
def circle_cells(
    x: float, y: float, radius: float, origin_x: float, origin_y: float, resolution: float, width: int, height: int
) -> np.ndarray:  # pragma: no cover - compiled
    """Cells (i, j) (K, 2), row by row, of a ``width`` x ``height`` grid (origin yaw 0) whose centres lie within
    ``radius`` m of (x, y), plus the cell under (x, y) itself; off-grid cells left out (``Footprint.cells`` of a
    round robot, in the same float operations)."""
    i_lo, j_lo = math.floor(((x - radius) - origin_x) / resolution), math.floor(((y - radius) - origin_y) / resolution)
    i_hi, j_hi = math.floor(((x + radius) - origin_x) / resolution), math.floor(((y + radius) - origin_y) / resolution)
    ci, cj = math.floor((x - origin_x) / resolution), math.floor((y - origin_y) / resolution)
    out = np.empty(((j_hi - j_lo + 1) * (i_hi - i_lo + 1), 2), dtype=np.int64)
    n = 0
    for j in range(j_lo, j_hi + 1):
        for i in range(i_lo, i_hi + 1):
            cx = (i + 0.5) * resolution + origin_x
            cy = (j + 0.5) * resolution + origin_y
            inside = math.hypot(cx - x, cy - y) <= radius or (i == ci and j == cj)
            if inside and 0 <= i < width and 0 <= j < height:
                out[n, 0], out[n, 1] = i, j
                n += 1
    return out[:n].copy()


@numba.njit(cache=True)
def mark_returns(
    data: np.ndarray,
    pts: np.ndarray,
    ok: np.ndarray,
    sensor_x: float,
    sensor_y: float,
    origin_x: float,
    origin_y: float,
    resolution: float,
    min_range: float,
    max_range: float,
    value: np.uint8,
) -> None:  # pragma: no cover - compiled
    """``data`` = ``value`` at the cells of the points (N, 2) (m, the grid's frame, origin yaw 0) marked ``ok``
    whose distance from the sensor lies in [min_range, max_range) (the obstacle layer's marking)."""
    h, w = data.shape
    for k in range(pts.shape[0]):
        px, py = pts[k, 0], pts[k, 1]
        if not (ok[k] and math.isfinite(px) and math.isfinite(py)):
            continue
        d = math.hypot(px - sensor_x, py - sensor_y)
        if not (d < max_range and d >= min_range):
            continue
        i, j = math.floor((px - origin_x) / resolution), math.floor((py - origin_y) / resolution)
        if 0 <= i < w and 0 <= j < h:
            data[j, i] = value


@numba.njit(cache=True)
def lethal_changes(
    data: np.ndarray, lethal: np.uint8, seeds: np.ndarray, previous: np.ndarray
) -> tuple[int, int, int, int, int]:  # pragma: no cover - compiled
    """``seeds`` = ``data == lethal``; returns (how many seeds, then the bounding rows and columns j0, j1, i0, i1,
    ends exclusive, of the cells where ``seeds`` differs from ``previous``: all 0 where nothing changed).
    ``previous`` of another shape: every seed counts as changed."""
    same_shape = previous.shape == seeds.shape
    n = 0
    j0, j1, i0, i1 = data.shape[0], -1, data.shape[1], -1
    for j in range(data.shape[0]):
        for i in range(data.shape[1]):
            s = data[j, i] == lethal
            seeds[j, i] = s
            n += s
            if (previous[j, i] != s) if same_shape else s:
                j0, j1, i0, i1 = min(j0, j), max(j1, j), min(i0, i), max(i1, i)
    if j1 < 0:
        return n, 0, 0, 0, 0
    return n, j0, j1 + 1, i0, i1 + 1
