"""Theta* (Nav2's ``nav2_theta_star_planner/ThetaStarPlanner``): any-angle A* over the costmap.

A* on the 4- or 8-connected grid (``how_many_corners``); each expansion also tries to join the new cell
straight to its parent's parent, and keeps that when it is cheaper and the segment between the cell
centres has line of sight: every cell it touches (an exact traversal, both cells at a corner crossing)
costs below 253 (inscribed) and, unless ``allow_unknown``, is not unknown. A segment of length ``L``
(cells) costs ``L * (w_euc_cost + w_traversal_cost * mean((c / 252)^2))`` over the cells it touches, so
paths bend around costly cells (unknown cells count as 252); the heuristic is ``w_heuristic_cost *
w_euc_cost`` times the straight distance. Diagonal steps do not cut obstacle corners. The corner path is
resampled at the costmap resolution and returned start to goal, in metres, in the costmap frame. Paths
are shorter and straighter than navfn's through open space.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from navlab.core import ParamSpec
from navlab.grid import COST_INSCRIBED, COST_UNKNOWN, Grid
from navlab.navigation.errors import NavigationError
from navlab.navigation.planners.common import GridPlanner, check_request, dedupe, iheap_pop, iheap_update, to_world

MAX_NON_OBSTACLE = 252.0


@dataclass
class ThetaStarParams:
    """Nav2 ThetaStarPlanner's parameters (names and defaults)."""

    how_many_corners: int = 8
    w_euc_cost: float = 1.0
    w_traversal_cost: float = 2.0
    w_heuristic_cost: float = 1.0
    allow_unknown: bool = True
    use_final_approach_orientation: bool = False
    terminal_checking_interval: int = 5000
    PARAMS: ClassVar[ParamSpec] = ParamSpec(
        "theta_star",
        NavigationError,
        above={"w_euc_cost": 0.0},
        at_least={"w_traversal_cost": 0.0, "w_heuristic_cost": 0.0},
    )

    def validate(self) -> None:
        """Refuse a bad value naming the key."""
        if self.how_many_corners not in (4, 8):
            raise NavigationError(
                f"theta_star parameter how_many_corners: expected 4 or 8, got {self.how_many_corners}"
            )


@numba.njit(cache=True)
def _line(blocked: np.ndarray, trav: np.ndarray, a: int, b: int, w: int) -> float:
    """Sum of ``trav`` over the cells the segment between the centres of cells ``a`` and ``b`` touches,
    divided by their count (the mean); -1 if one of them is blocked."""
    ai, aj = a % w, a // w
    bi, bj = b % w, b // w
    di, dj = bi - ai, bj - aj
    si = 1 if di > 0 else -1
    sj = 1 if dj > 0 else -1
    adi, adj = abs(di), abs(dj)
    tdx = 1.0 / adi if adi else np.inf
    tdy = 1.0 / adj if adj else np.inf
    tmx = 0.5 * tdx
    tmy = 0.5 * tdy
    i, j = ai, aj
    if blocked[j, i]:
        return -1.0
    total = trav[j, i]
    count = 1
    while i != bi or j != bj:
        if tmx < tmy - 1e-12:
            i += si
            tmx += tdx
        elif tmy < tmx - 1e-12:
            j += sj
            tmy += tdy
        else:  # through a corner: both side cells must be free
            if blocked[j, i + si] or blocked[j + sj, i]:
                return -1.0
            i += si
            j += sj
            tmx += tdx
            tmy += tdy
        if blocked[j, i]:
            return -1.0
        total += trav[j, i]
        count += 1
    return total / count


@numba.njit(cache=True)
def _theta_star(
    blocked: np.ndarray,
    trav: np.ndarray,
    start: int,
    goal: int,
    corners: int,
    w_euc: float,
    w_trav: float,
    w_heur: float,
) -> tuple[np.ndarray, int]:
    """Parents (flat, -1 unreached) of the Theta* search from ``start`` and the number of expanded cells."""
    h, w = blocked.shape
    n = h * w
    g = np.full(n, np.inf)
    parent = np.full(n, -1, np.int64)
    pos = np.full(n, -1, np.int64)  # heap slot, -1 never queued, -2 closed
    keys = np.empty(n)
    vals = np.empty(n, np.int64)
    gi, gj = goal % w, goal // w
    g[start] = 0.0
    parent[start] = start
    size = iheap_update(keys, vals, pos, 0, 0.0, start)
    expanded = 0
    di8 = (1, -1, 0, 0, 1, 1, -1, -1)
    dj8 = (0, 0, 1, -1, 1, -1, 1, -1)
    while size > 0:
        s = vals[0]
        size = iheap_pop(keys, vals, pos, size)
        expanded += 1
        if s == goal:
            break
        si, sj = s % w, s // w
        p = parent[s]
        for d in range(corners):
            ni = si + di8[d]
            nj = sj + dj8[d]
            if ni < 0 or nj < 0 or ni >= w or nj >= h or blocked[nj, ni]:
                continue
            if d >= 4 and (blocked[sj, ni] or blocked[nj, si]):
                continue  # no corner cutting
            m = nj * w + ni
            if pos[m] == -2:
                continue
            # path 1: from s; path 2: straight from s's parent when it has line of sight (the cheaper wins,
            # since a straight line through costly cells can cost more than the bend around them)
            length = math.sqrt(di8[d] ** 2 + dj8[d] ** 2)
            best = g[s] + length * (w_euc + w_trav * 0.5 * (trav[sj, si] + trav[nj, ni]))
            best_par = s
            if p != s:
                mean = _line(blocked, trav, p, m, w)
                if mean >= 0.0:
                    pi, pj = p % w, p // w
                    via = g[p] + math.sqrt((ni - pi) ** 2 + (nj - pj) ** 2) * (w_euc + w_trav * mean)
                    if via <= best * (1.0 + 1e-9):  # ties (collinear cells) go to the older parent
                        best = via
                        best_par = p
            if best < g[m]:
                g[m] = best
                parent[m] = best_par
                hx = ni - gi
                hy = nj - gj
                size = iheap_update(keys, vals, pos, size, best + w_heur * w_euc * math.sqrt(hx * hx + hy * hy), m)
    return parent, expanded


class ThetaStarPlanner(GridPlanner):
    """``nav2_theta_star_planner/ThetaStarPlanner`` as a pure planner over a costmap ``Grid`` (uint8 costs).

    After a call, ``last_failure`` says why there was no path ("" on success) and ``stats`` holds the
    expanded-cell count and the number of corners.
    """

    params_class = ThetaStarParams
    params: ThetaStarParams
    name = "theta_star"

    def _grids(self, data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        blocked = (data >= COST_INSCRIBED) & (data != COST_UNKNOWN)
        unknown = data == COST_UNKNOWN
        if not self.params.allow_unknown:
            blocked |= unknown
        c = np.where(unknown, MAX_NON_OBSTACLE, np.minimum(data, MAX_NON_OBSTACLE)).astype(np.float64)
        return blocked, (c / MAX_NON_OBSTACLE) ** 2

    def make_plan(
        self, costmap: Grid, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> np.ndarray | None:
        """A path (N, 2) in metres from ``start`` to ``goal`` (both included), points at most one cell apart, or
        None when the goal is in an obstacle or cut off (``last_failure`` says which). A start outside the map
        or in a lethal cell, and a goal outside the map, raise ``NavigationError``."""
        data, (si, sj, _, _), (gi, gj, _, _) = check_request(costmap, start, goal, self.name)
        self.last_failure = ""
        blocked, trav = self._grids(data)
        blocked[sj, si] = False  # the robot's own cell, as navfn clears it
        sxy = np.array([float(start[0]), float(start[1])])
        gxy = np.array([float(goal[0]), float(goal[1])])
        if blocked[gj, gi]:
            self.last_failure = f"goal ({gxy[0]:.3f}, {gxy[1]:.3f}) is in an obstacle (cost {int(data[gj, gi])})"
            self.stats = {"cells": 0, "corners": 0}
            return None
        w = data.shape[1]
        p = self.params
        parent, expanded = _theta_star(
            blocked,
            np.ascontiguousarray(trav),
            sj * w + si,
            gj * w + gi,
            p.how_many_corners,
            p.w_euc_cost,
            p.w_traversal_cost,
            p.w_heuristic_cost,
        )
        if parent[gj * w + gi] < 0:
            self.last_failure = f"goal ({gxy[0]:.3f}, {gxy[1]:.3f}) is cut off from the start"
            self.stats = {"cells": int(expanded), "corners": 0}
            return None
        cells = [gj * w + gi]
        while cells[-1] != sj * w + si:
            cells.append(int(parent[cells[-1]]))
        cells.reverse()
        corners = to_world(costmap, np.array([[c % w, c // w] for c in cells], dtype=np.float64))
        corners = np.vstack([sxy, corners[1:-1], gxy])
        self.stats = {"cells": int(expanded), "corners": len(corners)}
        return densify(dedupe(corners), costmap.resolution)


def densify(path: np.ndarray, spacing: float) -> np.ndarray:
    """``path`` (N, 2) with points added on each segment so that consecutive points are at most ``spacing`` apart."""
    if len(path) < 2:
        return np.vstack([path, path]) if len(path) == 1 else path
    out = [path[:1]]
    for a, b in itertools.pairwise(path):
        k = max(1, math.ceil(float(np.hypot(*(b - a))) / spacing))
        t = np.arange(1, k + 1)[:, None] / k
        out.append(a + t * (b - a))
    dense = np.vstack(out)
    dense[-1] = path[-1]  # exactly the goal, not a rounded interpolation
    return dense
