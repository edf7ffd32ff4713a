"""Bresenham ray clearing for the obstacle layer (Numba).

Coordinates are continuous cell coordinates: ``(x - origin_x) / resolution``, so cell ``(i, j)`` spans
``[i, i + 1) x [j, j + 1)``. ``data[j, i]`` is column ``i``, row ``j`` (``navlab.grid`` convention).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.gridline import TIE_LATE, line, line_cell


@numba.njit(cache=True)
def clear_rays(
    data: np.ndarray, x0: float, y0: float, ends: np.ndarray, max_cells: float, min_cells: float, value: np.uint8
) -> int:
    """Set to ``value`` every cell on the Bresenham line from ``(x0, y0)`` to each of ``ends`` (N, 2), endpoint
    cell included (the caller marks afterwards, as costmap_2d does). Each ray is cut to ``max_cells`` cells of
    length; cells nearer than ``min_cells`` to the origin are left alone; a ray stops where it leaves the grid.
    Returns the number of cells written."""
    h, w = data.shape
    i0 = math.floor(x0)
    j0 = math.floor(y0)
    if i0 < 0 or j0 < 0 or i0 >= w or j0 >= h:
        return 0
    written = 0
    min_sq = min_cells * min_cells
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
        ln = line(i0, j0, i1, j1, TIE_LATE)
        for n in range(ln[0] + 1):
            i, j = line_cell(ln, n)
            if i < 0 or j < 0 or i >= w or j >= h:
                break
            if min_sq <= 0.0 or (i - i0) * (i - i0) + (j - j0) * (j - j0) >= min_sq:
                data[j, i] = value
                written += 1
    return written
