"""The rollout controllers' per-cycle scene set-up and finish as compiled kernels.

``path_scene`` does in one call what ``RolloutController._scene`` did in some twenty numpy steps: the global
plan into grid-local coordinates (``LocalFrame.points_in``), ``transformGlobalPlan``'s stretch around the robot
(``crop_plan``), the plan's cells (``mapgrid.plan_cells``), the cells under the robot that never block the
wave (``rollout.footprint_cells``, TrajectoryPlanner's ``within_robot``) and the path distance map
(``mapgrid.wave_start``: seeded, grown only as far as lookups need). ``moved_length`` is ``_finish``'s cut of
the chosen rollout where it stops moving. Same float operations in the same order as the numpy steps they
replace, so the same results bit for bit. Poses are grid-local (m, rad) unless said otherwise; cells are
(i, j) = (column, row). Numba keys ``path_scene``'s cache on this file only: it holds compiled copies of
``mapgrid``'s and ``rollout.cells_under``'s code (each row's edge crossings worked out once), so after changing
those, change this file too (or clear the caches).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.navigation.controllers.common import crop_span
from navlab.navigation.controllers.mapgrid import cells_along, wave_start
from navlab.navigation.controllers.rollout import cells_under


@numba.njit(cache=True)
def path_scene(
    cost: np.ndarray,
    plan: np.ndarray,
    ox: float,
    oy: float,
    oyaw: float,
    res: float,
    pose: tuple[float, float, float],
    reach: float,
    free_mode: int,
    polygon: np.ndarray,
    edges: np.ndarray,
) -> tuple[
    np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
]:  # pragma: no cover - compiled
    """(cropped grid-local plan (M, 2), its cells (K, 2), the path distances' wave (``mapgrid.wave_start``; read
    with ``mapgrid.wave_to``)) for the costmap-frame
    ``plan`` (N, >= 2) on the grid ``cost`` whose origin is (ox, oy, oyaw), the robot at grid-local ``pose``.

    ``reach``: the crop radius (m); ``free_mode``: 0 no cells are kept free of obstacles, 1 the robot's centre
    cell, 2 the cells under ``polygon`` (base frame, m) with its ``edges`` (``footprint_outline``). An empty plan
    (no pose within ``reach``) or no plan cell in the grid gives empty arrays (and an empty wave)."""
    h, w = cost.shape
    n = plan.shape[0]
    local = np.empty((n, 2))
    c, s = math.cos(oyaw), math.sin(oyaw)
    for k in range(n):
        dx, dy = plan[k, 0] - ox, plan[k, 1] - oy
        if oyaw == 0.0:
            local[k, 0], local[k, 1] = dx, dy
        else:
            local[k, 0], local[k, 1] = c * dx + s * dy, -s * dx + c * dy
    x, y, th = pose
    first, end = crop_span(local, x, y, reach)
    cropped = local[first:end].copy()
    empty_cells = np.zeros((0, 2), dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    if cropped.shape[0] == 0:
        return cropped, empty_cells, wave_start(np.zeros((0, 0), dtype=cost.dtype), none, none, none, none)
    m = cropped.shape[0]
    steps = np.zeros(max(m - 1, 0), dtype=np.int64)
    for k in range(m - 1):
        d = math.hypot(cropped[k + 1, 0] - cropped[k, 0], cropped[k + 1, 1] - cropped[k, 1])
        steps[k] = max(1, math.ceil(d / res))
    cells = cells_along(cost, cropped, steps, res)
    if cells.shape[0] == 0:
        return cropped, cells, wave_start(np.zeros((0, 0), dtype=cost.dtype), none, none, none, none)
    if free_mode == 2:
        ct, st = math.cos(th), math.sin(th)
        poly = np.empty(polygon.shape)
        for k in range(polygon.shape[0]):
            poly[k, 0] = x + ct * polygon[k, 0] - st * polygon[k, 1]
            poly[k, 1] = y + st * polygon[k, 0] + ct * polygon[k, 1]
        ex = np.empty(edges.shape[0])
        ey = np.empty(edges.shape[0])
        for k in range(edges.shape[0]):
            ex[k] = x + ct * edges[k, 0] - st * edges[k, 1]
            ey[k] = y + st * edges[k, 0] + ct * edges[k, 1]
        free = cells_under(h, w, res, x, y, poly, ex, ey)
    elif free_mode == 1:
        i, j = math.floor(x / res), math.floor(y / res)
        free = np.zeros((1 if 0 <= i < w and 0 <= j < h else 0, 2), dtype=np.int64)
        if free.shape[0]:
            free[0, 0], free[0, 1] = i, j
    else:
        free = empty_cells
    return (
        cropped,
        cells,
        wave_start(cost, cells[:, 0].copy(), cells[:, 1].copy(), free[:, 0].copy(), free[:, 1].copy()),
    )


@numba.njit(cache=True)
def moved_length(path: np.ndarray) -> int:  # pragma: no cover - compiled
    """How many poses of a rollout (n, 3) to keep as the local plan: up to one past its last moving step (1 if it
    never moves): ``_finish``'s ``np.nonzero(np.any(path[1:] != path[:-1], axis=1))``."""
    for k in range(path.shape[0] - 2, -1, -1):
        if path[k + 1, 0] != path[k, 0] or path[k + 1, 1] != path[k, 1] or path[k + 1, 2] != path[k, 2]:
            return k + 2
    return 1


@numba.njit(cache=True)
def poses_out(
    poses: np.ndarray, count: int, ox: float, oy: float, oyaw: float, c: float, s: float
) -> np.ndarray:  # pragma: no cover - compiled
    """The first ``count`` grid-local poses (n, 3) in the costmap frame (``LocalFrame.poses_out``: the grid's
    origin (ox, oy, oyaw), ``c``/``s`` its yaw's cosine and sine; yaw wrapped to [-pi, pi) as ``wrap_angle``)."""
    out = np.empty((count, 3))
    for k in range(count):
        x, y = poses[k, 0], poses[k, 1]
        out[k, 0] = ox + c * x - s * y
        out[k, 1] = oy + s * x + c * y
        out[k, 2] = (poses[k, 2] + oyaw + math.pi) % (2.0 * math.pi) - math.pi
    return out
