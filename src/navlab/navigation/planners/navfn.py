"""navfn (ROS 1 ``navfn/NavfnROS``): a potential field over the costmap, then gradient descent on it.

Costs map as navfn's ``setCostmap``: a cell of cost ``c`` < 253 costs ``COST_NEUTRAL + COST_FACTOR * c``
(50 + 0.8 c) per cell crossed; inscribed (253) and lethal (254) cells are obstacles; unknown (255) cells cost 253
with ``allow_unknown`` (navfn's default; navlab's ``unknown_cost`` prices them otherwise) and are obstacles
without it. The potential is the solution of the Eikonal equation ``|grad P| = cost`` grown from the start (fast
marching with the exact two-neighbour quadratic update, Dijkstra order, or A* order with ``use_dijkstra: false``),
so it measures Euclidean path length weighted by cost, not 8-connected steps. The path descends the interpolated
gradient from the goal in half-cell steps (a grid step to the lowest neighbour next to obstacles or where the
gradient fails) and is returned start to goal, in metres, in the costmap frame.
``default_tolerance`` (m): a goal in an obstacle or cut off is replaced by the nearest reachable cell
within that distance. ``planner_window_x/y``, ``visualize_potential`` and the like are accepted and
ignored (the last potential stays available as ``planner.potential``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numba
import numpy as np

from navlab.core import ParamSpec
from navlab.grid import COST_INSCRIBED, COST_UNKNOWN, Grid
from navlab.navigation.errors import NavigationError
from navlab.navigation.planners.common import GridPlanner, check_request, dedupe, iheap_pop, iheap_update, to_world
from navlab.navigation.planners.navfn_wave import propagate as _wave

COST_NEUTRAL = 50.0
COST_FACTOR = 0.8


@dataclass
class NavfnParams:
    """``navfn/NavfnROS`` parameters (ROS 1 names and defaults; Nav2's ``use_astar``, ``tolerance`` accepted)."""

    allow_unknown: bool = True
    default_tolerance: float = 0.0  # m
    use_dijkstra: bool = True  # false: A* order (navfn's compile-time option, global_planner's parameter)
    visualize_potential: bool = False
    planner_window_x: float = 0.0
    planner_window_y: float = 0.0
    planner_costmap_publish_frequency: float = 0.0
    cost_factor: float = COST_FACTOR
    neutral_cost: float = COST_NEUTRAL
    lethal_cost: int = COST_INSCRIBED  # costs >= this are obstacles (navfn: COST_OBS_ROS = 253)
    # navlab: what crossing an unknown cell costs with allow_unknown, in the units where a free cell costs neutral_cost;
    # -1: navfn's, the ceiling max(lethal_cost, neutral_cost) (253: ~5x a free cell)
    unknown_cost: float = -1.0
    PARAMS: ClassVar[ParamSpec]

    def validate(self, what: str = "navfn") -> None:
        """Refuse a bad value naming the key."""
        if not 1 <= self.lethal_cost <= COST_UNKNOWN:
            raise NavigationError(f"{what} parameter lethal_cost: expected 1..255, got {self.lethal_cost}")
        if self.unknown_cost != -1.0 and not self.unknown_cost > 0.0:
            raise NavigationError(
                f"{what} parameter unknown_cost: expected -1 (navfn's) or > 0, got {self.unknown_cost}"
            )


@dataclass
class GlobalPlannerParams(NavfnParams):
    """``global_planner/GlobalPlanner`` parameters (ROS 1 names and defaults); same engine as navfn.

    ``use_quadratic`` (the exact quadratic update is always used), ``use_grid_path`` (must stay false),
    ``old_navfn_behavior``, ``orientation_mode``, ``outline_map`` and ``publish_potential`` are accepted.
    """

    cost_factor: float = 3.0
    use_quadratic: bool = True
    use_grid_path: bool = False
    old_navfn_behavior: bool = False
    orientation_mode: int = 0
    orientation_window_size: int = 1
    outline_map: bool = True
    publish_potential: bool = True

    def validate(self, what: str = "global_planner") -> None:
        super().validate(what)
        if self.use_grid_path:
            raise NavigationError(
                f"{what} parameter use_grid_path: only false (gradient-descent paths) is supported, got true"
            )


def _use_astar(values: dict[str, Any]) -> dict[str, Any]:
    """Nav2 navfn's ``use_astar`` is ``use_dijkstra`` negated."""
    if "use_astar" in values:
        values = dict(values)
        if "use_dijkstra" in values:
            raise NavigationError("navfn parameters use_astar and use_dijkstra both set; keep one")
        astar = values.pop("use_astar")
        values["use_dijkstra"] = (not astar) if isinstance(astar, bool) else astar
    return values


NavfnParams.PARAMS = ParamSpec(
    "navfn",
    NavigationError,
    aliases={"tolerance": "default_tolerance"},
    prepare=_use_astar,
    above={"neutral_cost": 0.0},
    at_least={"default_tolerance": 0.0, "cost_factor": 0.0},
)
GlobalPlannerParams.PARAMS = replace(NavfnParams.PARAMS, what="global_planner")


# --- kernels (Numba) -----------------------------------------------------------------------------


@numba.njit(cache=True)
def _propagate(
    data: np.ndarray,
    table: np.ndarray,
    start: int,
    goal: int,
    astar: bool,
    h_scale: float,
    stop_at_goal: bool,
    margin: float,
) -> tuple[np.ndarray, int]:
    """Fast marching from ``start`` over the costmap costs ``data`` (H, W) uint8, a cell costing ``table[data]``
    (``cell_costs``, inf = obstacle; the start's own cost is never read: it is settled first). Returns the potential
    (exact where settled, an upper bound on the front, inf beyond) and the number of settled cells. With
    ``stop_at_goal`` it stops once the queue's keys pass the goal's by ``margin``, so the goal sits inside
    settled cells and the gradient around it is defined."""
    h, w = data.shape
    n = h * w
    c = data.ravel()
    pot = np.full(n, np.inf)
    pos = np.full(n, -1, np.int32)  # heap slot, -1 never queued, -2 settled (int32: half the memory traffic)
    keys = np.empty(n)
    vals = np.empty(n, np.int32)
    gi, gj = goal % w, goal // w
    pot[start] = 0.0
    size = iheap_update(keys, vals, pos, 0, 0.0, start)
    settled = 0
    stop_key = np.inf
    while size > 0:
        if keys[0] > stop_key:
            break
        k = vals[0]
        key_k = keys[0]
        size = iheap_pop(keys, vals, pos, size)
        settled += 1
        if stop_at_goal and k == goal:
            stop_key = key_k + margin
        ki = k % w
        kj = k // w
        for d in range(4):
            mi = ki
            mj = kj
            if d == 0:
                mi -= 1
            elif d == 1:
                mi += 1
            elif d == 2:
                mj -= 1
            else:
                mj += 1
            if mi < 0 or mj < 0 or mi >= w or mj >= h:
                continue
            m = mj * w + mi
            if pos[m] == -2:
                continue
            hc = table[c[m]]
            if not math.isfinite(hc):
                continue
            ta = np.inf
            if mi > 0 and pos[m - 1] == -2:
                ta = pot[m - 1]
            if mi < w - 1 and pos[m + 1] == -2 and pot[m + 1] < ta:
                ta = pot[m + 1]
            tb = np.inf
            if mj > 0 and pos[m - w] == -2:
                tb = pot[m - w]
            if mj < h - 1 and pos[m + w] == -2 and pot[m + w] < tb:
                tb = pot[m + w]
            if tb < ta:
                ta, tb = tb, ta
            diff = tb - ta
            if diff >= hc:
                new = ta + hc
            else:
                new = 0.5 * (ta + tb + math.sqrt(2.0 * hc * hc - diff * diff))
            if new < pot[m]:
                pot[m] = new
                key = new
                if astar:
                    di = mi - gi
                    dj = mj - gj
                    key += h_scale * math.sqrt(di * di + dj * dj)
                size = iheap_update(keys, vals, pos, size, key, m)
    return pot.reshape(h, w), settled


@numba.njit(cache=True)
def _interp(pot: np.ndarray, u: float, v: float) -> float:
    """Bilinear potential at centre coordinates (u, v); inf if a corner is unsettled or off the grid."""
    h, w = pot.shape
    i0 = math.floor(u)
    j0 = math.floor(v)
    if i0 < 0 or j0 < 0 or i0 + 1 >= w or j0 + 1 >= h:
        return np.inf
    fu = u - i0
    fv = v - j0
    a = pot[j0, i0]
    b = pot[j0, i0 + 1]
    c = pot[j0 + 1, i0]
    d = pot[j0 + 1, i0 + 1]
    return (a * (1 - fu) + b * fu) * (1 - fv) + (c * (1 - fu) + d * fu) * fv


@numba.njit(cache=True, inline="always")
def _slope(lo: float, c: float, hi: float) -> float:  # pragma: no cover - compiled
    """dP along one axis at a cell of potential ``c`` between neighbours ``lo`` and ``hi``: the central difference,
    one-sided next to an obstacle or unreached cell (inf), 0 between two."""
    if math.isfinite(lo) and math.isfinite(hi):
        return 0.5 * (hi - lo)
    if math.isfinite(hi):
        return hi - c
    if math.isfinite(lo):
        return c - lo
    return 0.0


@numba.njit(cache=True)
def _cell_gradient(pot: np.ndarray, i: int, j: int) -> tuple[float, float]:
    """(dP/di, dP/dj) at a settled cell: central differences, one-sided next to obstacles or unreached cells."""
    h, w = pot.shape
    c = pot[j, i]
    left = pot[j, i - 1] if i > 0 else np.inf
    right = pot[j, i + 1] if i < w - 1 else np.inf
    down = pot[j - 1, i] if j > 0 else np.inf
    up = pot[j + 1, i] if j < h - 1 else np.inf
    return _slope(left, c, right), _slope(down, c, up)


@numba.njit(cache=True)
def _gradient(pot: np.ndarray, u: float, v: float) -> tuple[float, float, bool]:
    """Bilinear interpolation of the cell gradients at (u, v); ok False unless all four cells are reached."""
    h, w = pot.shape
    i0 = math.floor(u)
    j0 = math.floor(v)
    if i0 < 0 or j0 < 0 or i0 + 1 >= w or j0 + 1 >= h:
        return 0.0, 0.0, False
    fu = u - i0
    fv = v - j0
    gx = 0.0
    gy = 0.0
    for dj in range(2):
        for di in range(2):
            if not math.isfinite(pot[j0 + dj, i0 + di]):
                return 0.0, 0.0, False
            cx, cy = _cell_gradient(pot, i0 + di, j0 + dj)
            wgt = (fu if di else 1 - fu) * (fv if dj else 1 - fv)
            gx += wgt * cx
            gy += wgt * cy
    return gx, gy, True


@numba.njit(cache=True)
def _descend(pot: np.ndarray, u: float, v: float, tu: float, tv: float, step: float) -> tuple[np.ndarray, bool]:
    """Gradient descent on ``pot`` from (u, v) to the target (tu, tv) (centre coordinates) in ``step``-cell
    steps; a grid step to the lowest 8-neighbour where the gradient is unusable. The potential strictly
    decreases along the way, so the walk ends. Returns the points visited (M, 2) and whether it arrived."""
    h, w = pot.shape
    cap = 4 * (h * w) + 16
    out = np.empty((cap, 2))
    out[0, 0] = u
    out[0, 1] = v
    m = 1
    ci = math.floor(u + 0.5)
    cj = math.floor(v + 0.5)
    cur = _interp(pot, u, v)
    if not math.isfinite(cur):
        cur = pot[cj, ci]
    while m < cap - 1:
        if (u - tu) ** 2 + (v - tv) ** 2 <= 1.0:
            return out[:m], True
        gx, gy, ok = _gradient(pot, u, v)
        norm = math.sqrt(gx * gx + gy * gy)
        moved = False
        if ok and norm > 0.0:
            nu = u - step * gx / norm
            nv = v - step * gy / norm
            val = _interp(pot, nu, nv)
            if val < cur:
                u, v, cur = nu, nv, val
                moved = True
        if not moved:
            ci = math.floor(u + 0.5)
            cj = math.floor(v + 0.5)
            best = pot[cj, ci] if pot[cj, ci] < cur else cur
            bi, bj = -1, -1
            for dj in range(-1, 2):
                for di in range(-1, 2):
                    i = ci + di
                    j = cj + dj
                    if (di == 0 and dj == 0) or i < 0 or j < 0 or i >= w or j >= h:
                        continue
                    if pot[j, i] < best:
                        best = pot[j, i]
                        bi, bj = i, j
            if bi < 0:
                if pot[cj, ci] < cur:  # snap to the current cell's centre first
                    bi, bj, best = ci, cj, pot[cj, ci]
                else:
                    return out[:m], False
            u, v, cur = float(bi), float(bj), best
        out[m, 0] = u
        out[m, 1] = v
        m += 1
    return out[:m], False


@numba.njit(cache=True)
def _cell_costs(data: np.ndarray, table: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """``table`` (256,) looked up at every cell of ``data`` (uint8)."""
    out = np.empty(data.shape)
    for j in range(data.shape[0]):
        for i in range(data.shape[1]):
            out[j, i] = table[data[j, i]]
    return out


# --- the planner ---------------------------------------------------------------------------------


class NavfnPlanner(GridPlanner):
    """``navfn/NavfnROS`` as a pure planner: :meth:`make_plan` over a costmap ``Grid`` (uint8 costs).

    After a call, ``last_failure`` says why there was no path ("" on success), ``stats`` holds the
    settled-cell count, and ``potential`` the potential field (H, W; inf where not reached).
    """

    params_class = NavfnParams
    params: NavfnParams
    name = "navfn"
    potential: np.ndarray | None = None
    _table: tuple[tuple[float, float, int, bool, float], np.ndarray] | None = None  # cost_table's (parameters, table)

    def cost_table(self) -> np.ndarray:
        """Traversal cost (256,) float64 of each costmap_2d cost value (inf = obstacle), as navfn's ``setCostmap``;
        kept while the parameters it depends on stay the same."""
        p = self.params
        key = (p.neutral_cost, p.cost_factor, p.lethal_cost, p.allow_unknown, p.unknown_cost)
        cached = self._table
        if cached is not None and cached[0] == key:
            return cached[1]
        ceiling = max(float(p.lethal_cost), p.neutral_cost)  # navfn: COST_OBS - 1 = 253
        levels = np.arange(256)
        table = np.minimum(p.neutral_cost + p.cost_factor * levels.astype(np.float64), ceiling)  # per cost value
        table[levels >= p.lethal_cost] = np.inf
        if p.allow_unknown:
            table[COST_UNKNOWN] = ceiling if p.unknown_cost == -1.0 else p.unknown_cost
        table.flags.writeable = False
        self._table = (key, table)
        return table

    def cell_costs(self, data: np.ndarray) -> np.ndarray:
        """Per-cell traversal cost (float64; inf = obstacle) from costmap_2d costs, as navfn's ``setCostmap``."""
        return _cell_costs(np.ascontiguousarray(data, dtype=np.uint8), self.cost_table())

    def make_plan(
        self, costmap: Grid, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> np.ndarray | None:
        """A path (N, 2) in metres from ``start`` to ``goal`` (both included) in the costmap's frame, or None
        when the goal cannot be reached (``last_failure`` says why). A start outside the map or in a lethal
        cell, and a goal outside the map, raise ``NavigationError``."""
        data, (si, sj, su, sv), (gi, gj, gu, gv) = check_request(costmap, start, goal, self.name)
        self.last_failure = ""
        table = self.cost_table()
        data = np.ascontiguousarray(data, dtype=np.uint8)
        _h, w = data.shape
        # navfn clears the robot's cell (cost neutral_cost); the wave starts there, so only the goal check reads it
        goal_ok = (gi, gj) == (si, sj) or math.isfinite(table[data[gj, gi]])
        tol = self.params.default_tolerance
        # A*'s heuristic: the cheapest cell cost per cell of distance, over sqrt(2) because one quadratic update
        # can raise the potential by as little as cost / sqrt(2) per step (keeps the heuristic consistent)
        h_scale = float(self.params.neutral_cost) / math.sqrt(2.0)
        s, g, margin = sj * w + si, gj * w + gi, 4.0 * self.params.neutral_cost
        if self.params.use_dijkstra:  # the bucketed queue: the same potentials, ~40 % faster
            pot, settled = _wave(data, table, s, g, goal_ok, margin)
        else:
            pot, settled = _propagate(data, table, s, g, True, h_scale, goal_ok, margin)
        self.potential = pot
        self.stats = {"cells": int(settled)}
        end_xy = (float(goal[0]), float(goal[1]))
        eu, ev = gu, gv
        if not math.isfinite(pot[gj, gi]):
            best = _nearest_reached(pot, costmap, end_xy, tol)
            if best is None:
                why = f"in an obstacle (cost {int(data[gj, gi])})" if not goal_ok else "cut off from the start"
                extra = f" and no reachable cell within default_tolerance {tol} m" if tol > 0 else ""
                self.last_failure = f"goal ({end_xy[0]:.3f}, {end_xy[1]:.3f}) is {why}{extra}"
                return None
            bi, bj = best
            eu, ev = float(bi), float(bj)
            end_xy = tuple(to_world(costmap, np.array([[eu, ev]]))[0])
        if (si, sj) == (round(eu), round(ev)) and math.hypot(eu - su, ev - sv) <= 1.0:
            return np.array([[float(start[0]), float(start[1])], list(end_xy)])
        pts, arrived = _descend(pot, eu, ev, su, sv, 0.5)
        if not arrived:
            self.last_failure = f"gradient descent from the goal did not reach the start after {len(pts)} steps"
            return None
        path = to_world(costmap, pts[::-1])
        path = np.vstack([[float(start[0]), float(start[1])], path[:-1], [end_xy]])
        return dedupe(path)


def _nearest_reached(
    pot: np.ndarray, costmap: Grid, goal_xy: tuple[float, float], tol: float
) -> tuple[int, int] | None:
    """The reached cell (i, j) nearest to ``goal_xy`` within ``tol`` m (centre distance), or None."""
    if tol <= 0:
        return None
    res = costmap.resolution
    r = math.ceil(tol / res) + 1
    c = costmap.world_to_cell(np.array(goal_xy))[0]
    i0, i1 = max(0, c[0] - r), min(costmap.width, c[0] + r + 1)
    j0, j1 = max(0, c[1] - r), min(costmap.height, c[1] + r + 1)
    jj, ii = np.mgrid[j0:j1, i0:i1]
    centres = to_world(costmap, np.stack([ii.ravel(), jj.ravel()], axis=1).astype(np.float64))
    d = np.hypot(centres[:, 0] - goal_xy[0], centres[:, 1] - goal_xy[1])
    ok = (d <= tol + 1e-9) & np.isfinite(pot[jj.ravel(), ii.ravel()])
    if not ok.any():
        return None
    k = int(np.argmin(np.where(ok, d, np.inf)))
    return int(ii.ravel()[k]), int(jj.ravel()[k])


class GlobalPlanner(NavfnPlanner):
    """``global_planner/GlobalPlanner``: navfn's engine with global_planner's parameters (cost_factor 3.0,
    ``use_dijkstra: false`` for A*)."""

    params_class = GlobalPlannerParams
    params: GlobalPlannerParams
    name = "global_planner"
