"""Nav2's Smac Hybrid-A* planner (``nav2_smac_planner/SmacPlannerHybrid``): kinematically feasible global paths.

Hybrid-A* (Dolgov et al. 2008; Macenski et al. 2024 for Smac): A* over (cell, heading bin) where each node
keeps its continuous pose. A node expands by motion primitives of a car with ``minimum_turning_radius``: a
straight step and a left and right arc that each turn by the smallest multiple of the heading bin
(``angle_quantization_bins``) that moves the robot at least one cell diagonally; ``REEDS_SHEPP`` adds the
three in reverse. Every successor's footprint is checked against the costmap (a polygon footprint's edge
cells must be free of LETHAL, and of unknown unless ``allow_unknown``; a round robot's centre cell must be
under INSCRIBED), so paths through gaps narrower than the footprint's outer circle are found when the robot
fits lengthwise. Step cost (Smac's): length x (1 + ``cost_penalty`` x cost / 252), x ``non_straight_penalty``
on arcs, x ``reverse_penalty`` backwards, + ``change_penalty`` on a switch of turn direction. The heuristic is
the larger of the goal distance and a cost-aware 2-D Dijkstra distance from the goal (Smac's obstacle
heuristic). Analytic expansion: every few expansions (fewer as the goal nears, ``analytic_expansion_ratio``)
a Dubins curve to the goal pose is tried (up to ``analytic_expansion_max_length`` m) and ends the search
if its footprint is free; the search also ends on the goal's cell within one heading bin. Then the path
is thinned of duplicate points. With ``downsample_costmap`` the search runs on a coarser grid (the max of
each block). Nav2's names and defaults; ``tolerance`` lets the plan end at the reachable cell nearest the
goal within that many metres. Frames: the costmap's; poses (x m, y m, yaw rad).

Not Smac's: the analytic expansion uses Dubins curves only (forward), also with ``REEDS_SHEPP`` search;
``smooth_path`` is accepted but the path is left as searched (already curvature-bounded).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import numba
import numpy as np

from navlab.core import ParamSpec
from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.controllers.common import footprint_outline
from navlab.navigation.errors import NavigationError
from navlab.navigation.planners import dubins
from navlab.navigation.planners.common import GridPlanner, check_costmap, iheap_pop, iheap_update, pose_cell

WHAT = "SmacPlannerHybrid"


@dataclass
class SmacHybridParams:
    """nav2_smac_planner's SmacPlannerHybrid parameters (Nav2 names and defaults)."""

    PARAMS: ClassVar[ParamSpec] = ParamSpec(WHAT, NavigationError)
    downsample_costmap: bool = False
    downsampling_factor: int = 1
    tolerance: float = 0.25
    allow_unknown: bool = True
    max_iterations: int = 1000000
    max_on_approach_iterations: int = 1000
    max_planning_time: float = 5.0  # s (navlab counts expansions instead: see max_iterations)
    motion_model_for_search: str = "DUBIN"
    angle_quantization_bins: int = 72
    analytic_expansion_ratio: float = 3.5
    analytic_expansion_max_length: float = 3.0
    minimum_turning_radius: float = 0.4
    reverse_penalty: float = 2.0
    change_penalty: float = 0.0
    non_straight_penalty: float = 1.2
    cost_penalty: float = 2.0
    retrospective_penalty: float = 0.015
    lookup_table_size: float = 20.0
    cache_obstacle_heuristic: bool = False
    smooth_path: bool = True
    debug_visualizations: bool = False
    plugin: str = "nav2_smac_planner/SmacPlannerHybrid"

    def validate(self) -> None:
        """Refuse values the planner cannot run with (one-line errors naming the key)."""
        if self.motion_model_for_search not in ("DUBIN", "REEDS_SHEPP"):
            raise NavigationError(
                f"{WHAT} parameter motion_model_for_search: expected DUBIN or REEDS_SHEPP, got "
                f"{self.motion_model_for_search!r}"
            )
        for key in ("minimum_turning_radius", "analytic_expansion_ratio", "non_straight_penalty", "reverse_penalty"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise NavigationError(f"{WHAT} parameter {key}: expected > 0, got {v}")
        if self.angle_quantization_bins < 4 or self.max_iterations < 1 or self.downsampling_factor < 1:
            raise NavigationError(
                f"{WHAT} parameters angle_quantization_bins >= 4, max_iterations >= 1 and "
                "downsampling_factor >= 1 expected, got "
                f"{self.angle_quantization_bins}, {self.max_iterations}, {self.downsampling_factor}"
            )
        for key in ("tolerance", "cost_penalty", "change_penalty", "analytic_expansion_max_length"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v >= 0):
                raise NavigationError(f"{WHAT} parameter {key}: expected >= 0, got {v}")


@numba.njit(cache=True)
def _dijkstra8(step_cost: np.ndarray, goal: int) -> np.ndarray:  # pragma: no cover - compiled
    """Cost-to-goal (cells x step cost) over an 8-connected grid; ``step_cost`` inf = impassable."""
    h, w = step_cost.shape
    n = h * w
    dist = np.full(n, np.inf)
    keys = np.empty(n)
    vals = np.empty(n, dtype=np.int64)
    pos = np.full(n, -1, dtype=np.int64)
    flat = step_cost.ravel()
    dist[goal] = 0.0
    size = iheap_update(keys, vals, pos, 0, 0.0, goal)
    di = np.array([1, -1, 0, 0, 1, 1, -1, -1])
    dj = np.array([0, 0, 1, -1, 1, -1, 1, -1])
    dl = np.array([1.0, 1.0, 1.0, 1.0, math.sqrt(2.0), math.sqrt(2.0), math.sqrt(2.0), math.sqrt(2.0)])
    while size > 0:
        d0 = keys[0]
        c = vals[0]
        size = iheap_pop(keys, vals, pos, size)
        j, i = c // w, c % w
        for k in range(8):
            ii, jj = i + di[k], j + dj[k]
            if ii < 0 or jj < 0 or ii >= w or jj >= h:
                continue
            nb = jj * w + ii
            if pos[nb] == -2 or not math.isfinite(flat[nb]):
                continue
            nd = d0 + dl[k] * 0.5 * (flat[nb] + flat[c])
            if nd < dist[nb]:
                dist[nb] = nd
                size = iheap_update(keys, vals, pos, size, nd, nb)
    return dist.reshape(h, w)


class _Search:
    """One planning problem: the (possibly downsampled) grid, the footprint checks and the primitives."""

    def __init__(self, planner: SmacPlannerHybrid, costmap: Grid) -> None:
        p = planner.params
        data = check_costmap(costmap, WHAT)
        f = p.downsampling_factor if p.downsample_costmap else 1
        if f > 1:
            h, w = data.shape[0] // f * f, data.shape[1] // f * f
            data = data[:h, :w].reshape(h // f, f, w // f, f).max(axis=(1, 3))
        self.cost = data
        self.res = costmap.resolution * f
        self.ox, self.oy = costmap.origin[0], costmap.origin[1]
        self.h, self.w = data.shape
        self.p = p
        self.bins = p.angle_quantization_bins
        self.outline = footprint_outline(planner.footprint, self.res)
        self.blocked = (data == COST_LETHAL) | ((data == COST_UNKNOWN) & (not p.allow_unknown))
        if self.outline is None:  # a round robot: its centre must stay off inscribed cells
            self.blocked |= (data >= COST_INSCRIBED) & (data != COST_UNKNOWN)
        self._collision: dict[tuple[int, int, int], bool] = {}
        self.primitives = self._primitives()

    def _primitives(self) -> list[tuple[float, float, int, float, bool, int]]:
        """(dx, dy, dbin, length m, reverse, turn sign) in the robot frame at heading 0."""
        p = self.p
        r = p.minimum_turning_radius
        bin_size = 2 * math.pi / self.bins
        # the smallest turn that moves the robot one cell diagonally, rounded up to whole heading bins
        s = min(1.0, math.sqrt(2.0) * self.res / (2 * r))
        k = max(1, math.ceil(2 * math.asin(s) / bin_size - 1e-9))
        a = k * bin_size
        arc = r * a
        prims = [
            (arc, 0.0, 0, arc, False, 0),
            (r * math.sin(a), r * (1 - math.cos(a)), k, arc, False, 1),
            (r * math.sin(a), -r * (1 - math.cos(a)), -k, arc, False, -1),
        ]
        if p.motion_model_for_search == "REEDS_SHEPP":
            prims += [(-dx, dy, -db, length, True, -t) for dx, dy, db, length, _, t in prims]
        return prims

    def cell(self, x: float, y: float) -> tuple[int, int]:
        return math.floor((x - self.ox) / self.res), math.floor((y - self.oy) / self.res)

    def bin_of(self, yaw: float) -> int:
        return round(yaw / (2 * math.pi / self.bins)) % self.bins

    def cell_cost(self, i: int, j: int) -> int:
        return int(self.cost[j, i])

    def free(self, x: float, y: float, yaw: float) -> bool:
        """Whether the footprint at (x, y, yaw) is clear (cached per cell and heading bin)."""
        i, j = self.cell(x, y)
        if not (0 <= i < self.w and 0 <= j < self.h):
            return False
        key = (i, j, self.bin_of(yaw))
        hit = self._collision.get(key)
        if hit is None:
            hit = bool(self.blocked[j, i])
            if not hit and self.outline is not None:
                th = key[2] * 2 * math.pi / self.bins
                c, s = math.cos(th), math.sin(th)
                cx, cy = self.ox + (i + 0.5) * self.res, self.oy + (j + 0.5) * self.res
                px = cx + c * self.outline[:, 0] - s * self.outline[:, 1]
                py = cy + s * self.outline[:, 0] + c * self.outline[:, 1]
                ii = np.floor((px - self.ox) / self.res).astype(np.int64)
                jj = np.floor((py - self.oy) / self.res).astype(np.int64)
                inside = (ii >= 0) & (jj >= 0) & (ii < self.w) & (jj < self.h)
                hit = not bool(inside.all()) or bool(self.blocked[jj, ii].any())
            self._collision[key] = hit
        return not hit

    def obstacle_heuristic(self, gi: int, gj: int) -> np.ndarray:
        """Cost-to-goal (m, cost-weighted) of every cell from Smac's 2-D search."""
        step = 1.0 + self.p.cost_penalty * np.minimum(self.cost, COST_INSCRIBED - 1).astype(np.float64) / 252.0
        step[self.blocked] = np.inf
        step[self.cost == COST_UNKNOWN] = 1.0 if self.p.allow_unknown else np.inf
        return _dijkstra8(step, gj * self.w + gi) * self.res


class SmacPlannerHybrid(GridPlanner):
    """``nav2_smac_planner/SmacPlannerHybrid`` (see the module docstring). ``footprint``: the robot's polygon
    (N, 2; base frame, m) or None for a round robot (the costmap's inflation then stands for its radius)."""

    params_class = SmacHybridParams
    params: SmacHybridParams
    name = WHAT

    def __init__(self, params: SmacHybridParams | Mapping[str, Any] | None = None, *, footprint: Any = None) -> None:
        super().__init__(params)
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64)

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: Any = None) -> Self:
        """The plugin contract's constructor: ``context.footprint`` (its polygon, if any)."""
        return cls(params, footprint=getattr(getattr(context, "footprint", None), "polygon", None))

    def make_plan(
        self, costmap: Grid, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> np.ndarray | None:
        """A path (N, 3) of poses from ``start`` to ``goal`` in the costmap's frame whose turns respect
        ``minimum_turning_radius``, or None (``last_failure`` says why). A start or goal outside the map raises
        ``NavigationError``."""
        pose_cell(costmap, start, "start", WHAT)
        pose_cell(costmap, goal, "goal", WHAT)
        s = _Search(self, costmap)
        self.last_failure = ""
        start = (float(start[0]), float(start[1]), float(start[2]))
        goal = (float(goal[0]), float(goal[1]), float(goal[2]))
        gi, gj = s.cell(goal[0], goal[1])
        if not s.free(*goal):
            near = self._nearest_free_goal(s, goal)
            if near is None:
                self.last_failure = (
                    f"goal ({goal[0]:.3f}, {goal[1]:.3f}) is in collision for the footprint and no "
                    f"free pose within tolerance {self.params.tolerance} m"
                )
                return None
            goal = near
            gi, gj = s.cell(goal[0], goal[1])
        h2d = s.obstacle_heuristic(gi, gj)
        si, sj = s.cell(start[0], start[1])
        if not math.isfinite(h2d[sj, si]):
            self.last_failure = f"goal ({goal[0]:.3f}, {goal[1]:.3f}) is cut off from the start"
            return None
        path = self._search(s, start, goal, h2d)
        if path is not None:
            path[:, 2] = np.angle(np.exp(1j * path[:, 2]))  # yaw wrapped to (-pi, pi]
        return path

    def _nearest_free_goal(self, s: _Search, goal: tuple[float, float, float]) -> tuple[float, float, float] | None:
        """The free pose (goal's yaw) nearest the goal within ``tolerance`` m, on the search grid."""
        tol = self.params.tolerance
        n = math.ceil(tol / s.res)
        best: tuple[float, tuple[float, float, float]] | None = None
        for dj in range(-n, n + 1):
            for di in range(-n, n + 1):
                x, y = goal[0] + di * s.res, goal[1] + dj * s.res
                d = math.hypot(di, dj) * s.res
                if d <= tol and (best is None or d < best[0]) and s.free(x, y, goal[2]):
                    best = (d, (x, y, goal[2]))
        return None if best is None else best[1]

    def _search(
        self, s: _Search, start: tuple[float, float, float], goal: tuple[float, float, float], h2d: np.ndarray
    ) -> np.ndarray | None:
        p = self.params
        gi, gj = s.cell(goal[0], goal[1])
        gbin = s.bin_of(goal[2])

        def heuristic(x: float, y: float) -> float:
            i, j = s.cell(x, y)
            return max(math.hypot(goal[0] - x, goal[1] - y), float(h2d[j, i]))

        poses: list[tuple[float, float, float]] = [start]
        parent: list[int] = [-1]
        turn: list[int] = [0]
        g_cost: dict[tuple[int, int, int], float] = {}
        k0 = (*s.cell(start[0], start[1]), s.bin_of(start[2]))
        g_cost[k0] = 0.0
        node_g = [0.0]
        heap: list[tuple[float, int]] = [(heuristic(start[0], start[1]), 0)]
        closed: set[tuple[int, int, int]] = set()
        expansions = 0
        countdown = 0
        approach: int | None = None  # the expansion count when a node first came within tolerance of the goal
        best = (math.inf, -1)  # (heuristic, node) of the best node within tolerance
        while heap:
            _f, n = heapq.heappop(heap)
            x, y, th = poses[n]
            key = (*s.cell(x, y), s.bin_of(th))
            if key in closed:
                continue
            closed.add(key)
            expansions += 1
            if key[:2] == (gi, gj) and min((key[2] - gbin) % s.bins, (gbin - key[2]) % s.bins) <= 1:
                self.stats = {"expansions": expansions}
                return self._path(poses, parent, n, goal)
            h = heuristic(x, y)
            if h <= p.tolerance and h < best[0]:
                best = (h, n)
                approach = expansions if approach is None else approach
            if expansions > p.max_iterations or (
                approach is not None and expansions - approach > p.max_on_approach_iterations
            ):
                break
            countdown -= 1
            if countdown <= 0:
                countdown = max(1, int(h / s.res / p.analytic_expansion_ratio))
                tail = self._analytic(s, (x, y, th), goal)
                if tail is not None:
                    self.stats = {"expansions": expansions}
                    return np.vstack([self._path(poses, parent, n, None), tail])
            c, sn = math.cos(th), math.sin(th)
            for dx, dy, dbin, length, reverse, sign in s.primitives:
                nx, ny = x + c * dx - sn * dy, y + sn * dx + c * dy
                nth = th + dbin * 2 * math.pi / s.bins
                if not s.free(nx, ny, nth):
                    continue
                nkey = (*s.cell(nx, ny), s.bin_of(nth))
                if nkey in closed:
                    continue
                i, j = nkey[0], nkey[1]
                step = length * (
                    1.0 + p.cost_penalty * min(s.cell_cost(i, j), COST_INSCRIBED - 1) / 252.0
                    if s.cell_cost(i, j) != COST_UNKNOWN
                    else 1.0
                )
                if sign != 0:
                    step *= p.non_straight_penalty
                    if turn[n] != 0 and turn[n] != sign:
                        step += p.change_penalty * length
                if reverse:
                    step *= p.reverse_penalty
                g = node_g[n] + step
                if g >= g_cost.get(nkey, math.inf):
                    continue
                g_cost[nkey] = g
                poses.append((nx, ny, nth))
                parent.append(n)
                turn.append(sign)
                node_g.append(g)
                heapq.heappush(heap, (g + heuristic(nx, ny), len(poses) - 1))
        self.stats = {"expansions": expansions}
        if best[1] >= 0:  # Smac: the best path within tolerance of the goal
            return self._path(poses, parent, best[1], None)
        self.last_failure = f"no kinematically feasible path found in {expansions} expansions"
        return None

    def _analytic(
        self, s: _Search, pose: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> np.ndarray | None:
        """A collision-free Dubins tail (N, 3) from ``pose`` to ``goal`` (pose excluded), or None."""
        r = self.params.minimum_turning_radius
        best = dubins.shortest(pose, goal, r)
        if best is None or sum(best[1]) > self.params.analytic_expansion_max_length:
            return None
        tail = dubins.sample(pose, best[0], best[1], r, 0.5 * s.res)
        if all(s.free(x, y, th) for x, y, th in tail):
            return tail
        return None

    @staticmethod
    def _path(
        poses: list[tuple[float, float, float]], parent: list[int], n: int, goal: tuple[float, float, float] | None
    ) -> np.ndarray:
        out = []
        while n >= 0:
            out.append(poses[n])
            n = parent[n]
        path = np.array(out[::-1], dtype=np.float64)
        if goal is not None:
            path = np.vstack([path, goal])
        keep = np.ones(len(path), bool)
        keep[1:] = np.hypot(*np.diff(path[:, :2], axis=0).T) > 1e-9
        return path[keep]
