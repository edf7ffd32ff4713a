"""Ray clearing and marking for the obstacle layer (Numba).

Coordinates are continuous cell coordinates: ``(x - origin_x) / resolution``, so cell ``(i, j)`` spans
``[i, i + 1) x [j, j + 1)``. ``data[j, i]`` is column ``i``, row ``j`` (``navlab.grid`` convention).
``clear_rays`` clears along given endpoints; ``observe_ranges`` takes a laser scan's ranges as they come and
does the whole observation in one call: the endpoints, clearing along every ray, then marking the returns.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.gridline import TIE_LATE, line, line_cell, line_minor, line_strides
from navlab.navigation.costmap.kernels import mark_returns


@numba.njit(cache=True)
def clear_rays(
    data: np.ndarray, x0: float, y0: float, ends: np.ndarray, max_cells: float, min_cells: float, value: np.uint8
) -> int:
    """Set to ``value`` every cell on the Bresenham line from ``(x0, y0)`` to each of ``ends`` (N, 2), endpoint
    cell included (the caller marks afterwards, as costmap_2d does). Each ray is cut to ``max_cells`` cells of
    length; cells nearer than ``min_cells`` to the origin are left alone; a ray stops where it leaves the grid.
    A ray ending in the cell of the ray before it is the same line and is not walked again. Returns the number
    of cell writes."""
    h, w = data.shape
    i0 = math.floor(x0)
    j0 = math.floor(y0)
    if i0 < 0 or j0 < 0 or i0 >= w or j0 >= h:
        return 0
    written = 0
    flat = data.flat  # the grid's cells by flat index (line_strides)
    min_sq = min_cells * min_cells
    last_i, last_j, walked = i0, j0, False
    for k in range(ends.shape[0]):
        ex = ends[k, 0]
        ey = ends[k, 1]
        dx = ex - x0
        dy = ey - y0
        length = math.sqrt(dx * dx + dy * dy)
        if not math.isfinite(length):
            continue
        if length > max_cells:
            s = max_cells / length
            ex = x0 + dx * s
            ey = y0 + dy * s
        i1 = math.floor(ex)
        j1 = math.floor(ey)
        if walked and i1 == last_i and j1 == last_j:
            continue
        last_i, last_j, walked = i1, j1, True
        ln = line(i0, j0, i1, j1, TIE_LATE)
        if min_sq <= 0.0:  # every cell from the start up to where the line leaves the grid
            last = ln[0]
            if not (0 <= i1 < w and 0 <= j1 < h):  # the cells go one way along each axis: once out, out for good
                lo, hi = 0, last  # cell lo inside (the start is), cell hi outside
                while hi - lo > 1:
                    mid = (lo + hi) // 2
                    i, j = line_cell(ln, mid)
                    if 0 <= i < w and 0 <= j < h:
                        lo = mid
                    else:
                        hi = mid
                last = lo
            start, major, minor = line_strides(ln, w)
            for n in range(last + 1):
                flat[start + n * major + line_minor(ln, n) * minor] = value
            written += last + 1
            continue
        for n in range(ln[0] + 1):
            i, j = line_cell(ln, n)
            if i < 0 or j < 0 or i >= w or j >= h:
                break
            if min_sq <= 0.0 or (i - i0) * (i - i0) + (j - j0) * (j - j0) >= min_sq:
                data[j, i] = value
                written += 1
    return written


@numba.njit(cache=True)
def observe_ranges(
    data: np.ndarray,
    ranges: np.ndarray,
    beam_cos: np.ndarray,
    beam_sin: np.ndarray,
    scan_limits: tuple[float, float, float],
    sensor: tuple[float, float, float, float],
    grid: tuple[float, float, float],
    clearing: tuple[bool, float, float, np.uint8],
    marking: tuple[bool, float, float, np.uint8],
) -> None:  # pragma: no cover - compiled
    """One laser scan into an obstacle layer's ``data`` in one call: the endpoints (the arithmetic of
    ``ScanPoints.points`` moved into the grid's frame), then ``clear_rays`` and ``mark_returns`` on them.

    ``ranges`` (N,) m along the beams (``beam_cos``, ``beam_sin`` in the sensor frame); ``scan_limits`` =
    (range_min, range_max, clear_to): a real return lies in [range_min, range_max), a ray without one (inf, at
    or over range_max) only clears, out to clear_to m; NaN readings are left out. ``sensor`` = (x, y, cos yaw,
    sin yaw) in the grid's frame; ``grid`` = (origin x, origin y, resolution) (origin yaw 0). ``clearing`` =
    (on, raytrace_range m, raytrace_min_range m, free value), ``marking`` = (on, obstacle_min_range m,
    obstacle_range m, lethal value). Clearing runs over every ray first, then marking."""
    n = ranges.shape[0]
    sx, sy, c, s = sensor
    ox, oy, res = grid
    range_min, range_max, clear_to = scan_limits
    pts = np.empty((n, 2))
    ok = np.empty(n, np.bool_)
    m = 0
    for k in range(n):
        r = float(ranges[k])
        valid = math.isfinite(r) and r >= range_min and r < range_max
        if valid:
            d = r
        elif math.isnan(r):
            continue
        else:
            d = clear_to
        if not math.isfinite(d):
            continue
        lx = d * beam_cos[k]
        ly = d * beam_sin[k]
        pts[m, 0] = sx + c * lx - s * ly
        pts[m, 1] = sy + s * lx + c * ly
        ok[m] = valid
        m += 1
    if clearing[0]:
        cells = np.empty((m, 2))
        for k in range(m):
            cells[k, 0], cells[k, 1] = (pts[k, 0] - ox) / res, (pts[k, 1] - oy) / res
        clear_rays(data, (sx - ox) / res, (sy - oy) / res, cells, clearing[1] / res, clearing[2] / res, clearing[3])
    if marking[0]:
        mark_returns(data, pts[:m], ok[:m], sx, sy, ox, oy, res, marking[1], marking[2], marking[3])
