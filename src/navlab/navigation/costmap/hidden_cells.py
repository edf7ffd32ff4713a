"""Never-observed cells that are likely closed: the obstacle layer's opt-in prices for them (navlab's, not
costmap_2d's).

A rolling global costmap without ``track_unknown_space`` plans through every never-observed cell as through free
ground. In clutter (BARN's cylinders grow in clusters) two kinds of never-observed cell are likelier than the rest
to be closed:

- *occluded* cells: inside a scan's range, on a ray behind that ray's return, yet never observed (neither cleared
  nor marked by any scan): they lie in an obstacle's laser shadow (:func:`mark_shadows` keeps where the shadows
  fell; ``occluded_unknown_cost``);
- cells near a marked obstacle: an obstacle's hidden side is likely more obstacle
  (``unknown_near_obstacle_cost``, falling linearly to 0 at ``unknown_near_obstacle_distance`` m).

:func:`hidden_costs` writes those costs (between free and inscribed: the planner prices them above free ground,
they are no obstacle) into the master where the layer's cell is still unknown; cells never inside any scan's
range stay as the master holds them. Cell coordinates as in ``raytrace``: ``(x - origin_x) / resolution``,
``data[j, i]`` is column ``i``, row ``j``.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.ndimage import distance_transform_edt

from navlab.grid import COST_LETHAL, COST_UNKNOWN

SHADOW_STEP = 0.5  # cells: the march behind a return samples the ray every half cell


@numba.njit(cache=True)
def mark_shadows(
    shadow: np.ndarray, x0: float, y0: float, ends: np.ndarray, valid: np.ndarray, reach: float, depth: float
) -> int:  # pragma: no cover - compiled
    """Set ``shadow`` (H, W, uint8) to 1 in the cells behind each real return: along the ray from the sensor at
    (``x0``, ``y0``) through each of ``ends`` (N, 2) whose ``valid`` is true, from past the return's own cell out
    to ``reach`` from the sensor and at most ``depth`` past the return (``depth`` <= 0: no such limit; all in
    cells). A ray stops where it leaves the grid. Returns the cells set."""
    h, w = shadow.shape
    written = 0
    for k in range(ends.shape[0]):
        if not valid[k]:
            continue
        dx = ends[k, 0] - x0
        dy = ends[k, 1] - y0
        length = math.sqrt(dx * dx + dy * dy)
        if not math.isfinite(length) or length <= 0.0 or length >= reach:
            continue
        ux, uy = dx / length, dy / length
        ei, ej = math.floor(ends[k, 0]), math.floor(ends[k, 1])
        t = length + SHADOW_STEP
        end = reach if depth <= 0.0 else min(reach, length + depth)
        while t <= end:
            i = math.floor(x0 + ux * t)
            j = math.floor(y0 + uy * t)
            if i < 0 or j < 0 or i >= w or j >= h:
                break
            if (i != ei or j != ej) and shadow[j, i] == 0:
                shadow[j, i] = 1
                written += 1
            t += SHADOW_STEP
    return written


def near_obstacle_costs(data: np.ndarray, cost: int, distance_cells: float) -> np.ndarray:
    """Per cell (H, W, uint8) ``cost`` falling linearly with the distance (cells, centre to centre) to the nearest
    lethal cell of ``data``: ``cost`` next to one, 0 at ``distance_cells`` and beyond (0 everywhere without any)."""
    lethal = data == COST_LETHAL
    if not lethal.any() or cost <= 0 or distance_cells <= 0:
        return np.zeros(data.shape, np.uint8)
    dist = distance_transform_edt(~lethal)
    ramp = cost * np.clip(1.0 - (dist - 1.0) / distance_cells, 0.0, 1.0)
    return np.asarray(np.floor(ramp + 1e-9), dtype=np.uint8)


def hidden_costs(
    data: np.ndarray,
    shadow: np.ndarray | None,
    *,
    occluded_cost: int = 0,
    near_cost: int = 0,
    near_cells: float = 0.0,
) -> np.ndarray:
    """The costs (H, W, uint8; 0 = none) of a layer's never-observed cells (``data`` == unknown): the occluded ones
    (``shadow`` set) cost ``occluded_cost``, those near a lethal cell of ``data`` up to ``near_cost`` (see
    :func:`near_obstacle_costs`, ``near_cells`` cells); a cell both costs the higher."""
    unknown = data == COST_UNKNOWN
    out = np.zeros(data.shape, np.uint8)
    if occluded_cost > 0 and shadow is not None:
        out[unknown & (shadow != 0)] = occluded_cost
    if near_cost > 0 and near_cells > 0:
        near = near_obstacle_costs(data, near_cost, near_cells)
        np.maximum(out, np.where(unknown, near, 0).astype(np.uint8), out=out)
    return out


def write_hidden(master: np.ndarray, costs: np.ndarray) -> None:
    """``costs`` into ``master`` (same shape) where they are higher than the master's or the master's is unknown
    (a cell with no hidden cost is left alone)."""
    take = (costs > 0) & ((master == COST_UNKNOWN) | (master < costs))
    master[take] = costs[take]
