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
    # pass 1: per column, the distance (cells) to the nearest seed in that column, _FAR if none; row by row (the
    # nearest above, then the nearest below), so each row's columns go in one vectorised sweep
    g = np.empty((rows, cols), dtype=np.int64)
    for c in range(cols):
        g[0, c] = 0 if seeds[o0, p0 + c] else _FAR
    for r in range(1, rows):
        for c in range(cols):
            g[r, c] = 0 if seeds[o0 + r, p0 + c] else min(g[r - 1, c] + 1, _FAR)
    for r in range(rows - 2, -1, -1):
        for c in range(cols):
            g[r, c] = min(g[r, c], g[r + 1, c] + 1)
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
def fill_circle(
    data: np.ndarray, x: float, y: float, radius: float, origin_x: float, origin_y: float, resolution: float, value: int
) -> None:  # pragma: no cover - compiled
    """``data`` = ``value`` at the ``circle_cells`` of (x, y, ``radius``) (a round footprint's cells cleared)."""
    cells = circle_cells(x, y, radius, origin_x, origin_y, resolution, data.shape[1], data.shape[0])
    for k in range(cells.shape[0]):
        data[cells[k, 1], cells[k, 0]] = value


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
def lethal_diff(
    data: np.ndarray, lethal: np.uint8, seeds: np.ndarray, previous: np.ndarray, di: int, dj: int, changes: np.ndarray
) -> tuple[int, int, int]:  # pragma: no cover - compiled
    """``seeds`` = ``data == lethal`` (uint8 0/1), compared with ``previous`` (the last update's seeds; its cell
    (i + di, j + dj) is cell (i, j) now, a rolling window having moved; shape (0, 0): no previous seeds). Returns
    (how many seeds, appeared, vanished); ``changes`` (twice the grid's cell count, 2) gets the appeared cells
    (i, j) from its start and the vanished ones from its end (the last row first), the window's new coordinates:
    a seed the window left behind is a vanished cell outside the grid."""
    h, w = data.shape
    m = changes.shape[0]
    flat, out = data.ravel(), seeds.ravel()
    n = 0
    for k in range(flat.size):  # vectorised: the seeds and their count
        s = flat[k] == lethal
        out[k] = s
        n += s
    na = nv = 0
    if previous.shape[0] == 0:
        return n, na, nv
    if di == 0 and dj == 0:  # a fixed grid: compare eight cells at a time, look closer where they differ
        a, b = out, previous.ravel()
        words = a.size // 8
        aw, bw = a[: words * 8].view(np.uint64), b[: words * 8].view(np.uint64)
        for k in range(words + 1):
            if k < words and aw[k] == bw[k]:
                continue
            for c in range(k * 8, min(k * 8 + 8, a.size)):
                if a[c] != b[c]:
                    i, j = c % w, c // w
                    if a[c]:
                        changes[na, 0], changes[na, 1] = i, j
                        na += 1
                    else:
                        nv += 1
                        changes[m - nv, 0], changes[m - nv, 1] = i, j
        return n, na, nv
    for pj in range(h):  # a moved window: the old seeds by their new cells (outside the grid: left behind)
        for pi in range(w):
            if previous[pj, pi]:
                i, j = pi - di, pj - dj
                if not (0 <= i < w and 0 <= j < h and seeds[j, i]):
                    nv += 1
                    changes[m - nv, 0], changes[m - nv, 1] = i, j
    for j in range(h):
        for i in range(w):
            if seeds[j, i]:
                pi, pj = i + di, j + dj
                if not (0 <= pi < w and 0 <= pj < h and previous[pj, pi]):
                    changes[na, 0], changes[na, 1] = i, j
                    na += 1
    return n, na, nv


@numba.njit(cache=True)
def _merge_boxes(boxes: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """Merge overlapping boxes (K, 4) = (j0, j1, i0, i1), ends exclusive, in place into their bounding box where that
    is no larger than the two together, until no such pair is left; returns which rows are still boxes (they may
    still overlap). Over 64 boxes: one bounding box of them all."""
    k = boxes.shape[0]
    alive = np.ones(k, np.bool_)
    if k > 64:
        for t in range(1, k):
            boxes[0, 0], boxes[0, 1] = min(boxes[0, 0], boxes[t, 0]), max(boxes[0, 1], boxes[t, 1])
            boxes[0, 2], boxes[0, 3] = min(boxes[0, 2], boxes[t, 2]), max(boxes[0, 3], boxes[t, 3])
            alive[t] = False
        return alive
    again = True
    while again:
        again = False
        for a in range(k):
            if not alive[a]:
                continue
            for b in range(a + 1, k):
                if not (alive[b] and boxes[a, 0] < boxes[b, 1] and boxes[b, 0] < boxes[a, 1]):
                    continue
                if not (boxes[a, 2] < boxes[b, 3] and boxes[b, 2] < boxes[a, 3]):
                    continue
                j0, j1 = min(boxes[a, 0], boxes[b, 0]), max(boxes[a, 1], boxes[b, 1])
                i0, i1 = min(boxes[a, 2], boxes[b, 2]), max(boxes[a, 3], boxes[b, 3])
                size_a = (boxes[a, 1] - boxes[a, 0]) * (boxes[a, 3] - boxes[a, 2])
                size_b = (boxes[b, 1] - boxes[b, 0]) * (boxes[b, 3] - boxes[b, 2])
                if (j1 - j0) * (i1 - i0) <= size_a + size_b:  # one box costs no more than the two
                    boxes[a, 0], boxes[a, 1], boxes[a, 2], boxes[a, 3] = j0, j1, i0, i1
                    alive[b] = False
                    again = True
    return alive


@numba.njit(cache=True)
def reinflate(
    seeds: np.ndarray,
    cost: np.ndarray,
    table: np.ndarray,
    reach: int,
    changes: np.ndarray,
    appeared: int,
    vanished: int,
    boxes: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Bring ``cost`` (the inflation of the last seeds) up to date with ``seeds`` after ``lethal_diff``'s changes.

    A cell's cost is ``table[d2]`` of its nearest seed, the largest ``table`` value over the seeds (the table
    falls with distance), and only seeds within ``reach`` cells count. So the cells within ``reach`` of a
    vanished seed whose cost equals that seed's own there (the others owe their cost to another seed), and the
    extra ``boxes`` (K, 4) = (j0, j1, i0, i1) (what a rolling window newly covers), are recomputed from the seeds
    around them (``inflate_box`` over the bounding box of each, clustered: overlapping boxes merged); then every
    appeared seed raises the cells within reach to its own cost. The result equals an
    inflation of ``seeds`` from scratch, cell for cell."""
    h, w = seeds.shape
    m = changes.shape[0]
    last = table.size - 1
    k = vanished + boxes.shape[0]
    todo = np.empty((k, 4), np.int64)
    r1 = reach - 1
    stencil = np.empty((2 * r1 + 1, 2 * r1 + 1), table.dtype)  # a seed's own cost around it: table[d2], capped
    for dj in range(-r1, r1 + 1):
        for di in range(-r1, r1 + 1):
            d2 = dj * dj + di * di
            stencil[dj + r1, di + r1] = table[d2 if d2 < last else last]
    for t in range(vanished):  # the cells whose cost may have come from this seed: it equals the seed's own there
        i, j = changes[m - 1 - t, 0], changes[m - 1 - t, 1]
        j0, j1, i0, i1 = h, -1, w, -1
        for jj in range(max(0, j - r1), min(h, j + reach)):
            srow = stencil[jj - j + r1]
            for ii in range(max(0, i - r1), min(w, i + reach)):
                c = cost[jj, ii]
                if c > 0 and c == srow[ii - i + r1]:
                    j0, j1, i0, i1 = min(j0, jj), max(j1, jj), min(i0, ii), max(i1, ii)
        todo[t, 0], todo[t, 1], todo[t, 2], todo[t, 3] = j0, j1 + 1, i0, i1 + 1  # empty when there is none
    todo[vanished:] = boxes
    alive = _merge_boxes(todo)
    for t in range(k):
        j0, j1, i0, i1 = todo[t, 0], todo[t, 1], todo[t, 2], todo[t, 3]
        if alive[t] and j0 < j1 and i0 < i1:
            region = (max(0, j0 - reach), min(h, j1 + reach), max(0, i0 - reach), min(w, i1 + reach))
            inflate_box(seeds, region, (j0, j1, i0, i1), table, cost[j0:j1, i0:i1])
    for t in range(appeared):  # raise the cells around to the seed's own cost (branch-free: vectorised rows)
        i, j = changes[t, 0], changes[t, 1]
        a0, a1 = max(0, i - r1), min(w, i + reach)
        for jj in range(max(0, j - r1), min(h, j + reach)):
            srow = stencil[jj - j + r1, a0 - i + r1 : a1 - i + r1]
            crow = cost[jj, a0:a1]
            for q in range(a1 - a0):
                crow[q] = max(crow[q], srow[q])
