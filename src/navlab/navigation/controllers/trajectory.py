"""base_local_planner's TrajectoryPlanner (with its ``dwa`` flag) and dwa_local_planner's DWAPlanner.

Both sample velocity pairs (v, w) in a dynamic window around the current velocity, roll every sample
out over ``sim_time`` (all at once, numpy), score the rollouts on the local costmap and command the
best one's velocity:

- *window*: ``v ± acc_lim_x * T``, ``w ± acc_lim_theta * T`` clipped to the velocity limits, with
  ``T = sim_period`` (1 / controller_frequency) for DWA and ``T = sim_time`` for plain trajectory rollout;
- *plan*: as ``transformGlobalPlan`` hands it on, the (pruned) plan from its first pose within half the
  local costmap's larger side of the robot up to the first pose beyond that again; the *local goal* is
  its last pose (it caps TrajectoryPlanner's speed at ``distance / sim_time``, DWA pushes it
  ``forward_point_distance`` away from the robot for its front goal);
- *distances*: base_local_planner's MapGrid, 4-connected cell steps from the plan's cells and from the
  local goal's cell (the plan's last cell in the local costmap), blocked by LETHAL/INSCRIBED/unknown
  cells (TrajectoryPlanner: except, on the path map, the cells under the robot now);
- *footprint*: costmap_2d's robot footprint, a polygon (``robot_radius`` alone: ``makeFootprintFromRadius``'s
  16-gon). A pose is blocked when the polygon's edges cross a LETHAL or unknown cell, its cost is the
  highest cost under the edges or at the centre cell (``occdist`` takes the highest along the rollout).
  Without a polygon or radius the robot is a point: its centre cell, blocked from INSCRIBED up;
- *TrajectoryPlanner cost* = pdist_scale * path_dist + gdist_scale * goal_dist + occdist_scale *
  max_cost, distances at the rollout's end (in cells, or metres with ``meter_scoring``); a rollout that
  leaves the map, is blocked, or passes a cell with no path to the plan or goal is rejected. In-place
  turns (at least ``min_in_place_vel_theta``) win when their cost is no higher than the best forward
  rollout's (an in-place turn ends where the robot is: it wins when no forward rollout gets closer),
  the one whose look-ahead point (``heading_lookahead``) is closest to the goal; with nothing valid it
  backs off at ``escape_vel``;
- *DWA cost* = path_distance_bias * path_dist + goal_distance_bias * goal_dist + occdist_scale *
  max_cost + the same biases at a point ``forward_point_distance`` ahead of the end pose (to the plan,
  and to the local goal pushed that far beyond itself) + ``twirling_scale`` * |w|; biases scaled by the
  resolution (ROS does); a rollout any of whose poses sits on a cell with no path to the plan or goal is
  rejected. As in ROS, a critic whose scale is 0 is skipped, rejections included.

Each sample is rolled out in ROS's number of steps (from its speed and turn rate over
``sim_granularity`` / ``angular_sim_granularity``) and scored at its last step, one step short of
``sim_time``.

Near the goal both stop within the acceleration limits, then turn in place to the goal yaw
(``xy_goal_tolerance``, ``yaw_goal_tolerance``, ``latch_xy_goal_tolerance``). Oscillation flags
forbid turning back the other way (DWA: or reversing) until the robot moved ``oscillation_reset_dist``
(TrajectoryPlanner's ``stuck_left``/``stuck_right`` on its in-place turns, DWA's
``OscillationCostFunction``).

The planners read move_base's ``controller_frequency`` (ROS searches the parameter upward) unless their
own section sets it: ``sim_period`` is one controller cycle.

Deliberate differences from ROS: holonomic (y-velocity) samples are not generated, since the
controllers command a differential base; the 16-gon of a round robot is not padded vertex by vertex
(``robot_radius`` is taken as given, padding included); footprint edges are sampled every half cell
rather than Bresenham-rasterised.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.controllers import mapgrid
from navlab.navigation.controllers.common import (
    GoalLatch,
    LocalFrame,
    OscillationFlags,
    as_plan,
    circle_footprint,
    crop_plan,
    footprint_outline,
    goal_of,
    prune_plan,
    rotate_to_goal,
    same_goal,
    stop_with_acc_limits,
    stopped,
)
from navlab.navigation.controllers.params import TrajectoryPlannerParams
from navlab.navigation.errors import NavigationError

# --- rollout and footprint cost (pure, vectorised over samples) --------------------------------------


def rollout(pose: tuple[float, float, float], velocity: tuple[float, float], targets: np.ndarray,
            steps: int | np.ndarray, sim_time: float, acc: tuple[float, float], *, accelerate: bool) -> np.ndarray:
    """Poses (S, max(steps), 3) of a unicycle starting at ``pose`` with ``velocity``: sample ``s`` at
    t = 0, dt, ..., (n - 1) dt with n = ``steps[s]`` and dt = ``sim_time`` / n (ROS's rollouts end one step
    short of sim_time), then its last pose repeated up to the longest sample's length.

    ``targets`` (S, 2): commanded (v m/s, w rad/s). With ``accelerate`` the velocity moves towards the
    target by at most ``acc`` (m/s², rad/s²) * dt per step; otherwise it jumps to it (DWA).
    Each step moves along the heading held before the step (base_local_planner's integration).
    """
    n = np.broadcast_to(np.maximum(np.asarray(steps, dtype=np.int64), 1), (len(targets),)).copy()
    out = np.empty((len(targets), int(n.max()) if len(n) else 1, 3))
    _rollout(float(pose[0]), float(pose[1]), float(pose[2]), float(velocity[0]), float(velocity[1]),
             np.ascontiguousarray(targets, dtype=np.float64), n, float(sim_time), float(acc[0]), float(acc[1]),
             accelerate, out)
    return out


@numba.njit(cache=True)
def _rollout(x0: float, y0: float, th0: float, v0: float, w0: float, targets: np.ndarray, steps: np.ndarray,
             sim_time: float, ax: float, ath: float, accelerate: bool,
             out: np.ndarray) -> None:  # pragma: no cover - compiled
    for s in range(out.shape[0]):
        x, y, th, v, w = x0, y0, th0, v0, w0
        tv, tw = targets[s, 0], targets[s, 1]
        dt = sim_time / steps[s]
        for k in range(out.shape[1]):
            if k >= steps[s]:
                out[s, k, 0], out[s, k, 1], out[s, k, 2] = out[s, k - 1, 0], out[s, k - 1, 1], out[s, k - 1, 2]
                continue
            out[s, k, 0], out[s, k, 1], out[s, k, 2] = x, y, th
            if accelerate:
                v = min(max(tv, v - ax * dt), v + ax * dt)
                w = min(max(tw, w - ath * dt), w + ath * dt)
            else:
                v, w = tv, tw
            x += v * math.cos(th) * dt
            y += v * math.sin(th) * dt
            th += w * dt


def lookup(grid: np.ndarray, resolution: float, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Values of ``grid`` at grid-local points (any shape, same for x and y) and the mask of points inside it
    (outside points read the grid's cell (0, 0))."""
    shape = np.shape(x)
    vals = np.empty(shape, dtype=grid.dtype)
    inside = np.empty(shape, dtype=np.bool_)
    _lookup(grid, 1.0 / resolution, np.ascontiguousarray(x, dtype=np.float64).reshape(-1),
            np.ascontiguousarray(y, dtype=np.float64).reshape(-1), vals.reshape(-1), inside.reshape(-1))
    return vals, inside


@numba.njit(cache=True)
def _lookup(grid: np.ndarray, inv: float, x: np.ndarray, y: np.ndarray, vals: np.ndarray,
            inside: np.ndarray) -> None:  # pragma: no cover - compiled
    h, w = grid.shape
    for k in range(x.size):
        i, j = math.floor(x[k] * inv), math.floor(y[k] * inv)
        ok = 0 <= i < w and 0 <= j < h
        inside[k] = ok
        vals[k] = grid[j, i] if ok else grid[0, 0]


def footprint_costs(cost: np.ndarray, resolution: float, poses: np.ndarray, outline: np.ndarray | None, *,
                    near_max: np.ndarray | None = None) -> np.ndarray:
    """costmap_2d's footprint cost at each grid-local pose (..., 3): -1 where the robot may not be.

    Circular robot (``outline`` None): the centre cell's cost, -1 if LETHAL, INSCRIBED, unknown or off the
    map. Polygon: the highest cost under its edges (``outline`` (M, 2) base-frame points), -1 if any is
    LETHAL or unknown or the robot is off the map. ``near_max``: :func:`outline_reach_max` of ``cost`` and
    ``outline``, if the caller has it (poses with nothing but free cells around skip their edges).
    """
    return _pose_costs(cost, resolution, poses, outline, near_max, with_centre=False)


def occupancy_costs(cost: np.ndarray, resolution: float, poses: np.ndarray, outline: np.ndarray | None, *,
                    near_max: np.ndarray | None = None) -> np.ndarray:
    """base_local_planner's obstacle cost of each grid-local pose (..., 3): -1 where the robot may not be.

    Polygon: ``max(footprint cost, centre cell cost)`` (``TrajectoryPlanner::generateTrajectory``,
    ``ObstacleCostFunction::footprintCost``), the footprint cost being costmap_2d's ``footprintCost``
    (the highest cost under the edges, -1 when one is LETHAL or unknown). Point robot: :func:`footprint_costs`.
    ``near_max``: :func:`outline_reach_max` of ``cost`` and ``outline``, if the caller has it (poses whose
    centre cell holds the highest cost around skip their edges).
    """
    return _pose_costs(cost, resolution, poses, outline, near_max, with_centre=True)


def outline_reach_max(cost: np.ndarray, resolution: float, outline: np.ndarray) -> np.ndarray:
    """The highest cost (uint8, ``cost``'s shape; unknown for cells off the grid) in the square of cells that
    the ``outline``'s points can fall in while the robot's centre is in each cell: where it equals the centre
    cell's cost, no edge can cost more (the footprint cost needs no edge lookups)."""
    reach = math.ceil(float(np.hypot(outline[:, 0], outline[:, 1]).max()) / resolution) + 1
    out = np.empty(cost.shape, dtype=np.uint8)
    _box_max(np.ascontiguousarray(cost, dtype=np.uint8), reach, out)
    return out


@numba.njit(cache=True)
def _box_max(grid: np.ndarray, reach: int, out: np.ndarray) -> None:  # pragma: no cover - compiled
    h, w = grid.shape
    rows = np.empty((h, w), dtype=np.uint8)
    for j in range(h):
        for i in range(w):
            m = grid[j, i]
            if i - reach < 0 or i + reach >= w:
                m = COST_UNKNOWN
            else:
                for k in range(i - reach, i + reach + 1):
                    m = max(m, grid[j, k])
            rows[j, i] = m
    for j in range(h):
        for i in range(w):
            m = rows[j, i]
            if j - reach < 0 or j + reach >= h:
                m = COST_UNKNOWN
            else:
                for k in range(j - reach, j + reach + 1):
                    m = max(m, rows[k, i])
            out[j, i] = m


def _pose_costs(cost: np.ndarray, resolution: float, poses: np.ndarray, outline: np.ndarray | None,
                near_max: np.ndarray | None, *, with_centre: bool) -> np.ndarray:
    """:func:`footprint_costs` (``with_centre`` False) or :func:`occupancy_costs` (True), one compiled pass."""
    poses = np.asarray(poses, dtype=np.float64)
    shape = poses.shape[:-1]
    flat = poses.reshape(-1, 3)
    out = np.empty(flat.shape[0], dtype=np.float64)
    grid = np.ascontiguousarray(cost)
    x, y = np.ascontiguousarray(flat[:, 0]), np.ascontiguousarray(flat[:, 1])
    if outline is None:
        empty = np.zeros(0)
        _footprint_pass(grid, grid, 1.0 / resolution, x, y, empty, empty, empty, empty, False, False, with_centre,
                        out)
    else:
        ol = np.asarray(outline, dtype=np.float64)
        near = grid if near_max is None else np.ascontiguousarray(near_max, dtype=grid.dtype)
        # numpy's cos/sin (as before); the edge points are formed in the kernel in the same operation order
        _footprint_pass(grid, near, 1.0 / resolution, x, y, np.cos(flat[:, 2]), np.sin(flat[:, 2]),
                        np.ascontiguousarray(ol[:, 0]), np.ascontiguousarray(ol[:, 1]), True, near_max is not None,
                        with_centre, out)
    return out.reshape(shape)


@numba.njit(cache=True, inline="always")
def _pose_cost(grid: np.ndarray, near: np.ndarray, inv: float, x: float, y: float, c: float, s: float, ox: np.ndarray,
               oy: np.ndarray, polygon: bool, use_near: bool, with_centre: bool) -> float:  # pragma: no cover
    """One pose's footprint (``with_centre`` False) or occupancy (True) cost, -1 where the robot may not be."""
    h, w = grid.shape
    i, j = math.floor(x * inv), math.floor(y * inv)
    inside = 0 <= i < w and 0 <= j < h
    centre = grid[j, i] if inside else grid[0, 0]
    if not polygon:
        return -1.0 if (centre >= COST_INSCRIBED or not inside) else float(centre)
    if not inside:
        return -1.0
    if use_near:  # every edge point lies in the square ``near`` holds the highest cost of
        top = near[j, i]
        if top < COST_LETHAL and (top == 0 or (with_centre and top == centre)):
            return float(top)
    # every edge point, without early exit (the loop compiles to branch-free code): off the grid or on a
    # LETHAL/unknown cell is illegal, else the highest cost
    best = np.uint8(0)
    off = False
    for m in range(ox.size):
        px = x + c * ox[m] - s * oy[m]
        py = y + s * ox[m] + c * oy[m]
        pi, pj = np.int64(math.floor(px * inv)), np.int64(math.floor(py * inv))
        ok = (pi >= 0) & (pi < w) & (pj >= 0) & (pj < h)
        off |= not ok
        best = max(best, grid[pj if ok else 0, pi if ok else 0])
    if off or best >= COST_LETHAL:
        return -1.0
    return float(max(best, centre)) if with_centre else float(best)


@numba.njit(cache=True)
def _footprint_pass(grid: np.ndarray, near: np.ndarray, inv: float, x: np.ndarray, y: np.ndarray, c: np.ndarray,
                    s: np.ndarray, ox: np.ndarray, oy: np.ndarray, polygon: bool, use_near: bool, with_centre: bool,
                    out: np.ndarray) -> None:  # pragma: no cover - compiled
    for k in range(x.size):
        if k > 0 and x[k] == x[k - 1] and y[k] == y[k - 1] and (not polygon or (c[k] == c[k - 1] and s[k] == s[k - 1])):
            out[k] = out[k - 1]  # a rollout's last pose repeated: the same cost
            continue
        ck, sk = (c[k], s[k]) if polygon else (1.0, 0.0)
        out[k] = _pose_cost(grid, near, inv, x[k], y[k], ck, sk, ox, oy, polygon, use_near, with_centre)


@numba.njit(cache=True)
def _rollout_scores(grid: np.ndarray, near: np.ndarray, path_dist: np.ndarray, goal_dist: np.ndarray, inv: float,
                    traj: np.ndarray, c: np.ndarray, s: np.ndarray, ox: np.ndarray, oy: np.ndarray, polygon: bool,
                    use_near: bool, weights: np.ndarray, impossible: float,
                    out: np.ndarray) -> None:  # pragma: no cover - compiled
    """TrajectoryPlanner's cost of each rollout (S, n, 3): ``weights`` = (scale, pdist, gdist, occdist);
    -1 when a pose is blocked, else -2 when a pose has no path to the plan or goal."""
    h, w = path_dist.shape
    for r in range(traj.shape[0]):
        top = -math.inf
        blocked = False
        no_path = False
        fp = 0.0
        pd = gd = 0.0
        for k in range(traj.shape[1]):
            x, y = traj[r, k, 0], traj[r, k, 1]
            i, j = math.floor(x * inv), math.floor(y * inv)
            inside = 0 <= i < w and 0 <= j < h
            pd, gd = (path_dist[j, i], goal_dist[j, i]) if inside else (path_dist[0, 0], goal_dist[0, 0])
            if pd >= impossible or gd >= impossible:
                no_path = True
            if blocked:
                continue
            if use_near and polygon and inside:
                bound = near[j, i]  # no edge of this pose costs more: it cannot raise the rollout's cost
                if bound < COST_LETHAL and bound <= top:
                    continue
            same = k > 0 and x == traj[r, k - 1, 0] and y == traj[r, k - 1, 1] and (
                not polygon or (c[r, k] == c[r, k - 1] and s[r, k] == s[r, k - 1]))
            if not same:  # a rollout's last pose repeated has the same cost
                fp = _pose_cost(grid, near, inv, x, y, c[r, k], s[r, k], ox, oy, polygon, use_near, True)
            if fp < 0:
                blocked = True
            elif fp > top:
                top = fp
        if blocked:
            out[r] = -1.0
        elif no_path:
            out[r] = -2.0
        else:
            out[r] = weights[0] * (weights[1] * pd + weights[2] * gd + weights[3] * top)


def footprint_cells(shape: tuple[int, int], resolution: float, pose: tuple[float, float, float],
                    polygon: np.ndarray | None, *, edges: np.ndarray | None = None) -> np.ndarray:
    """Cells (K, 2) as (i, j) under the robot at grid-local ``pose``: the centre cell, and with a polygon
    (base frame, m) every cell whose centre lies inside it (even-odd rule) or that its edges cross (ROS's
    filled ``getFootprintCells``), sorted by i then j. ``edges``: the polygon's ``footprint_outline`` at
    ``resolution`` if the caller has it already."""
    x, y, th = pose
    h, w = shape
    if polygon is None:
        i, j = math.floor(x / resolution), math.floor(y / resolution)
        ok = 0 <= i < w and 0 <= j < h
        return np.array([[i, j]] if ok else np.zeros((0, 2)), dtype=np.int64).reshape(-1, 2)
    if edges is None:
        edges = footprint_outline(polygon, resolution)
    assert edges is not None
    c, s = math.cos(th), math.sin(th)
    poly = np.column_stack([x + c * polygon[:, 0] - s * polygon[:, 1], y + s * polygon[:, 0] + c * polygon[:, 1]])
    ex = x + c * edges[:, 0] - s * edges[:, 1]
    ey = y + s * edges[:, 0] + c * edges[:, 1]
    return _footprint_cells(int(h), int(w), float(resolution), float(x), float(y), poly, np.ascontiguousarray(ex),
                            np.ascontiguousarray(ey))


@numba.njit(cache=True)
def _footprint_cells(h: int, w: int, res: float, x: float, y: float, poly: np.ndarray, ex: np.ndarray,
                     ey: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    ci, cj = math.floor(x / res), math.floor(y / res)
    lo_i, lo_j = math.floor(poly[:, 0].min() / res), math.floor(poly[:, 1].min() / res)
    hi_i, hi_j = math.floor(poly[:, 0].max() / res), math.floor(poly[:, 1].max() / res)
    ei = np.empty(ex.size, dtype=np.int64)
    ej = np.empty(ex.size, dtype=np.int64)
    for k in range(ex.size):
        ei[k], ej[k] = math.floor(ex[k] / res), math.floor(ey[k] / res)
    # a box over every candidate cell: the centre, the polygon's bounding cells and the edge cells
    bi0, bj0 = min(ci, lo_i, ei.min()), min(cj, lo_j, ej.min())
    bi1, bj1 = max(ci, hi_i, ei.max()), max(cj, hi_j, ej.max())
    mark = np.zeros((bi1 - bi0 + 1, bj1 - bj0 + 1), dtype=np.bool_)
    mark[ci - bi0, cj - bj0] = True
    for k in range(ex.size):
        mark[ei[k] - bi0, ej[k] - bj0] = True
    n = poly.shape[0]
    for i in range(lo_i, hi_i + 1):
        for j in range(lo_j, hi_j + 1):
            px, py = (i + 0.5) * res, (j + 0.5) * res  # points_in_polygon's test of the cell centre
            inside = False
            for m in range(n):
                ax, ay = poly[m, 0], poly[m, 1]
                bx, by = poly[(m + 1) % n, 0], poly[(m + 1) % n, 1]
                if (ay > py) != (by > py) and px < ax + (py - ay) * (bx - ax) / (by - ay):
                    inside = not inside
            if inside:
                mark[i - bi0, j - bj0] = True
    count = 0
    for a in range(mark.shape[0]):
        for b in range(mark.shape[1]):
            if mark[a, b] and 0 <= a + bi0 < w and 0 <= b + bj0 < h:
                count += 1
    out = np.empty((count, 2), dtype=np.int64)
    count = 0
    for a in range(mark.shape[0]):
        for b in range(mark.shape[1]):
            if mark[a, b] and 0 <= a + bi0 < w and 0 <= b + bj0 < h:
                out[count, 0], out[count, 1] = a + bi0, b + bj0
                count += 1
    return out


def velocity_samples(low: float, high: float, n: int) -> np.ndarray:
    """base_local_planner's VelocityIterator: ``n`` even steps from low to high, plus 0 if crossed."""
    if low >= high:
        return np.array([high])
    n = max(2, n)
    out = list(np.linspace(low, high, n))
    for k in range(n - 1):
        if out[k] < 0.0 < out[k + 1]:
            return np.array([*out[: k + 1], 0.0, *out[k + 1:]])
    return np.array(out)


# --- the shared cycle ------------------------------------------------------------------------------


@dataclass
class LocalScene:
    """One cycle's inputs in grid-local coordinates: pose, cost array, the plan as ROS's planners get it
    (``plan`` (N, 2), cropped around the robot), its cells and the distance maps."""

    frame: LocalFrame
    pose: tuple[float, float, float]
    cost: np.ndarray
    resolution: float
    plan: np.ndarray
    path_cells: np.ndarray
    path_dist: np.ndarray
    goal_dist: np.ndarray

    @property
    def impossible(self) -> float:
        """MapGrid's obstacle value (cells in the grid): distances at or above it are hopeless."""
        return float(self.cost.size)

    def local_goal(self) -> np.ndarray:
        """Grid-local point (2,): the cropped plan's last pose (``transformed_plan.back()``)."""
        return self.plan[-1].copy()


class RolloutController:
    """What TrajectoryPlannerROS and DWAPlannerROS share: plan, goal handling, outputs.

    After each :meth:`compute_velocity`: ``local_plan`` (N, 3) chosen rollout (costmap frame; empty when
    stopping, turning at the goal or failing), ``samples`` (S, 2) the (v, w) tried, ``costs`` (S,) their
    costs (< 0: rejected), ``valid`` False when no valid command was found (ROS's ``computeVelocityCommands``
    returning false: move_base's cue for recovery).
    """

    what = ""
    params: Any
    _stopped_vel = (0.01, 0.01)
    _accelerate = True

    def __init__(self, params: Mapping[str, Any] | Any | None = None, *, footprint: Any = None,
                 robot_radius: float | None = None, controller_frequency: float | None = None,
                 rng: np.random.Generator | None = None) -> None:
        if controller_frequency is not None and (params is None or isinstance(params, Mapping)):
            params = {"controller_frequency": controller_frequency, **(params or {})}  # its own value wins
        self.params = self._parse(params)
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64)
        if footprint_outline(self.footprint, 0.05) is None:  # validate now; no polygon: the round robot's 16-gon
            self.footprint = None if robot_radius is None else circle_footprint(float(robot_radius))
        p = self.params
        self._latch = GoalLatch(p.xy_goal_tolerance, p.yaw_goal_tolerance, p.latch_xy_goal_tolerance)
        self._osc = OscillationFlags(p.oscillation_reset_dist, getattr(p, "oscillation_reset_angle", -1.0))
        self._plan: np.ndarray | None = None
        self._rotating_to_goal = False
        self._outlines: dict[tuple[float, bytes | None], np.ndarray | None] = {}
        self._near: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._clear_outputs()

    @staticmethod
    def _parse(params: Any) -> Any:
        raise NotImplementedError

    def _clear_outputs(self) -> None:
        self.local_plan = np.zeros((0, 3))
        self.samples = np.zeros((0, 2))
        self.costs = np.zeros(0)
        self._traj = np.zeros((0, 0, 3))
        self._frame = LocalFrame(0.0, 0.0, 0.0)
        self.valid = True

    @property
    def trajectories(self) -> np.ndarray:
        """Every rollout (S, n, 3) of the last cycle, in the costmap frame."""
        if self._traj.size == 0:
            return self._traj.copy()
        return self._frame.poses_out(self._traj.reshape(-1, 3)).reshape(self._traj.shape)

    def set_plan(self, path: np.ndarray) -> None:
        """The global plan (N, 2) or (N, 3) in the costmap's frame; an (N, 3) plan's last yaw is the goal yaw.

        A plan to a new goal (beyond the goal tolerances from the last one) clears the goal latch and the
        oscillation flags; the same plan sent again every cycle keeps them."""
        plan = as_plan(path)
        p = self.params
        if self._plan is None or not same_goal(goal_of(self._plan), goal_of(plan), p.xy_goal_tolerance,
                                               p.yaw_goal_tolerance):
            self._latch.reset()
            self._osc.reset()
            self._rotating_to_goal = False
            self._new_goal()
        self._plan = plan

    def _new_goal(self) -> None:
        """Forget per-goal state (subclasses add theirs)."""

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float]) -> bool:
        """Within xy (possibly latched) and yaw tolerance of the plan's last pose."""
        if self._plan is None:
            return False
        return self._latch.reached(tuple(map(float, pose)), goal_of(self._plan))  # type: ignore[arg-type]

    def compute_velocity(self, pose: tuple[float, float, float], velocity: tuple[float, float],
                         costmap: Grid | None) -> tuple[float, float]:
        """(v m/s, w rad/s) for the robot at ``pose`` (costmap frame) moving at ``velocity`` (v, w)."""
        if self._plan is None:
            raise NavigationError(f"{self.what}: compute_velocity called before set_plan")
        if costmap is None:
            raise NavigationError(f"{self.what}: needs a local costmap (got None)")
        pose = (float(pose[0]), float(pose[1]), float(pose[2]))
        velocity = (float(velocity[0]), float(velocity[1]))
        self._clear_outputs()
        if self.params.prune_plan:
            self._plan = prune_plan(self._plan, pose[0], pose[1])
        goal = goal_of(self._plan)
        scene = self._scene(pose, costmap)
        if self._latch.xy_reached(pose, goal):
            return self._stop_rotate(pose, velocity, goal, scene)
        if scene is None:
            self.valid = False
            return 0.0, 0.0
        return self._drive(scene, pose, velocity, goal)

    # --- pieces -----------------------------------------------------------------------------------

    def _scene(self, pose: tuple[float, float, float], costmap: Grid) -> LocalScene | None:
        assert self._plan is not None
        frame = LocalFrame.of(costmap)
        self._frame = frame
        cost = np.ascontiguousarray(costmap.data, dtype=np.uint8)
        res = costmap.resolution
        pose_l = frame.pose_in(pose)
        reach = 0.5 * res * max(cost.shape)
        plan = crop_plan(frame.points_in(self._plan[:, :2]), pose_l[0], pose_l[1], reach)
        if len(plan) == 0:
            return None  # ROS: an empty transformed plan (no pose of the plan near the robot)
        cells = mapgrid.plan_cells(cost, plan, res)
        if len(cells) == 0:
            return None  # ROS: "None of the points of the global plan were in the local costmap"
        free = self._free_cells(cost, pose_l, res)
        return LocalScene(frame, pose_l, cost, res, plan, cells, mapgrid.distance_map(cost, cells, free),
                          mapgrid.distance_map(cost, cells[-1:]))

    def _free_cells(self, cost: np.ndarray, pose_l: tuple[float, float, float], res: float) -> np.ndarray | None:
        """Cells never obstacles for the path map's wave (None: none)."""
        return None

    def _outline(self, res: float) -> np.ndarray | None:
        """The footprint's edge points at ``res`` (cached: the same footprint and resolution every cycle)."""
        key = (res, None if self.footprint is None else self.footprint.tobytes())
        if key not in self._outlines:
            self._outlines[key] = footprint_outline(self.footprint, res)
        return self._outlines[key]

    def _near_max(self, scene: LocalScene) -> np.ndarray | None:
        """``outline_reach_max`` of the scene's costs (None for a point robot), kept while the costs stay the
        same (the local costmap updates less often than the controller runs)."""
        outline = self._outline(scene.resolution)
        if outline is None:
            return None
        cached = self._near
        if (cached is not None and cached[0] is outline and cached[1].shape == scene.cost.shape
                and np.array_equal(cached[1], scene.cost)):
            return cached[2]
        near = outline_reach_max(scene.cost, scene.resolution, outline)
        self._near = (outline, scene.cost.copy(), near)
        return near

    def _stop_rotate(self, pose: tuple[float, float, float], velocity: tuple[float, float],
                     goal: tuple[float, float, float | None], scene: LocalScene | None) -> tuple[float, float]:
        """At the goal position: stop within the acceleration limits, then turn in place to the goal yaw."""
        p = self.params
        err = self._latch.yaw_error(pose, goal)
        if abs(err) <= p.yaw_goal_tolerance:
            self._rotating_to_goal = False
            return 0.0, 0.0
        if not self._rotating_to_goal and not stopped(velocity, *self._stopped_vel):
            cmd = stop_with_acc_limits(velocity, p.acc_lim_x, p.acc_lim_theta, p.sim_period)
        else:
            self._rotating_to_goal = True
            max_w, min_w = self._in_place_limits(err)
            cmd = (0.0, rotate_to_goal(err, velocity[1], max_w=max_w, min_in_place_w=min_w,
                                       acc_theta=p.acc_lim_theta, sim_period=p.sim_period))
        if scene is not None and not self._command_valid(scene, velocity, cmd):
            self.valid = False
            return 0.0, 0.0
        return cmd

    def _in_place_limits(self, err: float) -> tuple[float, float]:
        raise NotImplementedError

    def _command_valid(self, scene: LocalScene, velocity: tuple[float, float], cmd: tuple[float, float]) -> bool:
        """Whether rolling ``cmd`` out for sim_time scores as a legal trajectory (ROS's ``checkTrajectory``)."""
        p = self.params
        targets = np.array([cmd])
        traj = rollout(scene.pose, velocity, targets, self._steps(targets), p.sim_time,
                       (p.acc_lim_x, p.acc_lim_theta), accelerate=self._accelerate)
        return bool(self._check(scene, targets, traj)[0] >= 0)

    def _check(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        """Costs (S,) of rollouts checked outside the sampling loop (< 0: illegal)."""
        raise NotImplementedError

    def _steps(self, targets: np.ndarray) -> np.ndarray:
        """Rollout steps (S,) of each sample, as the ROS planner counts them."""
        raise NotImplementedError

    def _finish(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray, costs: np.ndarray, best: int,
                pose: tuple[float, float, float]) -> tuple[float, float]:
        """Store the cycle's outputs; command sample ``best`` (or stop and flag failure if it is -1)."""
        self.samples, self.costs, self._traj = targets, costs, traj
        if best < 0:
            self.valid = False
            return 0.0, 0.0
        path = traj[best]
        moved = np.nonzero(np.any(path[1:] != path[:-1], axis=1))[0]
        self.local_plan = scene.frame.poses_out(path[: (int(moved[-1]) + 2) if len(moved) else 1])
        return float(targets[best, 0]), float(targets[best, 1])

    def _drive(self, scene: LocalScene, pose: tuple[float, float, float], velocity: tuple[float, float],
               goal: tuple[float, float, float | None]) -> tuple[float, float]:
        raise NotImplementedError


# --- base_local_planner/TrajectoryPlannerROS ----------------------------------------------------------


class InPlaceFlags:
    """TrajectoryPlanner's guard against turning on the spot back and forth (``stuck_left``/``stuck_right``).

    Each in-place turn (v <= 0) is recorded with the pose it was chosen at; once the robot turned in place the
    same way twice, in-place turns the other way are no longer tried. Everything is forgotten when the robot is
    more than ``reset_dist`` m from the last in-place turn's pose.
    """

    def __init__(self, reset_dist: float) -> None:
        self.reset_dist = reset_dist
        self.prev = (0.0, 0.0)
        self.reset()

    def reset(self) -> None:
        """Clear every flag."""
        self.rotating_left = self.rotating_right = self.stuck_left = self.stuck_right = False

    def allowed(self, w: np.ndarray) -> np.ndarray:
        """Mask of the in-place turn rates (rad/s) that may be tried (ROS: w < 0 unless ``stuck_left``, w > 0
        unless ``stuck_right``)."""
        return ((w < 0) & (not self.stuck_left)) | ((w > 0) & (not self.stuck_right))

    def moved(self, pose: tuple[float, float, float]) -> None:
        """Forget the flags once the robot is far enough from the last in-place turn."""
        if math.hypot(pose[0] - self.prev[0], pose[1] - self.prev[1]) > self.reset_dist:
            self.reset()

    def update(self, pose: tuple[float, float, float], v: float, w: float) -> None:
        """Record the chosen command (v m/s, w rad/s) at ``pose``."""
        if not v > 0:
            if w < 0:
                self.stuck_right |= self.rotating_right
                self.rotating_right = True
            elif w > 0:
                self.stuck_left |= self.rotating_left
                self.rotating_left = True
            self.prev = (pose[0], pose[1])
        self.moved(pose)


class TrajectoryPlannerROS(RolloutController):
    """base_local_planner's trajectory rollout / DWA planner (``dwa`` flag) behind the Controller protocol.

    ``params``: a TrajectoryPlannerROS parameter dict (ROS 1 names) or ``TrajectoryPlannerParams``;
    ``footprint``: polygon [[x, y], ...] (m, base frame), else ``robot_radius`` (m: costmap_2d's 16-gon), else
    a point robot (centre cell); ``controller_frequency``: move_base's (Hz), used unless ``params`` sets it.
    ``rng`` is accepted for a uniform constructor and not used (the planner is deterministic).
    """

    what = "TrajectoryPlannerROS"
    params: TrajectoryPlannerParams

    def __init__(self, params: Mapping[str, Any] | TrajectoryPlannerParams | None = None, *, footprint: Any = None,
                 robot_radius: float | None = None, controller_frequency: float | None = None,
                 rng: np.random.Generator | None = None) -> None:
        super().__init__(params, footprint=footprint, robot_radius=robot_radius,
                         controller_frequency=controller_frequency, rng=rng)
        self._escaping = False
        self._escape_pose = (0.0, 0.0, 0.0)
        self._spin = InPlaceFlags(self.params.oscillation_reset_dist)

    @staticmethod
    def _parse(params: Any) -> TrajectoryPlannerParams:
        return TrajectoryPlannerParams.from_dict(params)

    def _new_goal(self) -> None:
        self._escaping = False
        self._spin.reset()

    def _in_place_limits(self, err: float) -> tuple[float, float]:
        p = self.params
        return (p.max_vel_theta if err > 0 else -p.min_vel_theta), p.min_in_place_vel_theta

    def _free_cells(self, cost: np.ndarray, pose_l: tuple[float, float, float], res: float) -> np.ndarray | None:
        """Cells under the robot now, never obstacles for the path map's wave (ROS's ``within_robot``)."""
        edges = self._outline(res)
        return footprint_cells(cost.shape, res, pose_l, self.footprint if edges is not None else None, edges=edges)

    def _check(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        return self._score(scene, traj)

    def _steps(self, targets: np.ndarray) -> np.ndarray:
        """``TrajectoryPlanner::generateTrajectory``: round(max(|v| sim_time / sim_granularity, |w| /
        angular_sim_granularity)), at least 1 (ROS leaves sim_time out of the angular term)."""
        p = self.params
        ang = p.angular_sim_granularity if p.angular_sim_granularity > 0 else p.sim_granularity
        need = np.maximum(np.abs(targets[:, 0]) * p.sim_time / p.sim_granularity, np.abs(targets[:, 1]) / ang)
        return np.maximum(1, np.floor(need + 0.5)).astype(np.int64)

    def _score(self, scene: LocalScene, traj: np.ndarray) -> np.ndarray:
        """Costs (S,): pdist * path_dist + gdist * goal_dist + occdist * max_cost; -1 blocked, -2 no path."""
        p = self.params
        res = scene.resolution
        traj = np.ascontiguousarray(traj, dtype=np.float64)
        outline = self._outline(res)
        near = self._near_max(scene)
        grid = scene.cost
        if outline is None:
            c = s = np.zeros(traj.shape[:2])
            ox = oy = np.zeros(0)
        else:  # numpy's cos/sin, as occupancy_costs
            c, s = np.cos(traj[..., 2]), np.sin(traj[..., 2])
            ox, oy = np.ascontiguousarray(outline[:, 0]), np.ascontiguousarray(outline[:, 1])
        weights = np.array([res if p.meter_scoring else 1.0, p.pdist_scale, p.gdist_scale, p.occdist_scale])
        cost = np.empty(traj.shape[0])
        _rollout_scores(grid, grid if near is None else near, np.ascontiguousarray(scene.path_dist),
                        np.ascontiguousarray(scene.goal_dist), 1.0 / res, traj, c, s, ox, oy, outline is not None,
                        near is not None, weights, scene.impossible, cost)
        return cost

    def _drive(self, scene: LocalScene, pose: tuple[float, float, float], velocity: tuple[float, float],
               goal: tuple[float, float, float | None]) -> tuple[float, float]:
        p = self.params
        v0, w0 = velocity
        x, y, _ = scene.pose
        lg = scene.local_goal()
        horizon = p.sim_period if p.dwa else p.sim_time
        vmax = min(p.max_vel_x, math.hypot(lg[0] - x, lg[1] - y) / p.sim_time)
        vmax = max(min(vmax, v0 + p.acc_lim_x * horizon), p.min_vel_x)
        vmin = min(max(p.min_vel_x, v0 - p.acc_lim_x * horizon), vmax)
        wmax = min(p.max_vel_theta, w0 + p.acc_lim_theta * horizon)
        wmin = min(max(p.min_vel_theta, w0 - p.acc_lim_theta * horizon), wmax)
        # ROS's order: per speed the straight rollout, then vtheta_samples - 1 turn rates from the lowest up
        vxs = np.linspace(vmin, vmax, p.vx_samples) if p.vx_samples > 1 else np.array([vmin])
        ws = np.linspace(wmin, wmax, p.vtheta_samples) if p.vtheta_samples > 1 else np.array([wmin])
        dw = (wmax - wmin) / (p.vtheta_samples - 1) if p.vtheta_samples > 1 else 0.0
        fwd_w = np.concatenate([[0.0], ws[:-1]]) if len(ws) > 1 else np.array([0.0])
        forward = np.stack([np.repeat(vxs, len(fwd_w)), np.tile(fwd_w, len(vxs))], axis=1)
        spin = np.where(ws > 0, np.maximum(ws, p.min_in_place_vel_theta), np.minimum(ws, -p.min_in_place_vel_theta))
        in_place = np.stack([np.zeros_like(spin), spin], axis=1)
        targets = np.vstack([forward, in_place, [[p.escape_vel, 0.0]]])
        traj = rollout(scene.pose, velocity, targets, self._steps(targets), p.sim_time, (p.acc_lim_x, p.acc_lim_theta),
                       accelerate=True)
        costs = self._score(scene, traj)
        nf, ni = len(forward), len(in_place)
        best = -1
        if not self._escaping:
            ok = costs[:nf] >= 0
            if ok.any():
                best = int(np.argmin(np.where(ok, costs[:nf], np.inf)))
        # turn in place towards where the look-ahead point is nearest the goal
        ahead = traj[nf:nf + ni, -1]
        hx = ahead[:, 0] + p.heading_lookahead * np.cos(ahead[:, 2])
        hy = ahead[:, 1] + p.heading_lookahead * np.sin(ahead[:, 2])
        head_dist, head_in = lookup(scene.goal_dist, scene.resolution, hx, hy)
        allowed = self._spin.allowed(ws)
        best_heading = math.inf
        for k in range(ni):
            c = costs[nf + k]
            if c < 0 or not (best < 0 or c <= costs[best]) or abs(ws[k]) <= dw or not head_in[k] or not allowed[k]:
                continue
            if head_dist[k] < best_heading:
                best, best_heading = nf + k, float(head_dist[k])
        if best >= 0:
            self._spin.update(pose, float(targets[best, 0]), float(targets[best, 1]))
            self._end_escape(pose)
            return self._finish(scene, targets, traj, costs, best, pose)
        # nothing valid: back off slowly, even into cost (ROS does), unless there is no path at all
        self._spin.moved(pose)
        esc = len(targets) - 1
        if costs[esc] > -2.0 and not self._escaping:
            self._escaping, self._escape_pose = True, pose
        self._end_escape(pose)
        return self._finish(scene, targets, traj, costs, esc if costs[esc] > -2.0 else -1, pose)

    def _end_escape(self, pose: tuple[float, float, float]) -> None:
        """Leave escape mode once ``escape_reset_dist`` m or ``escape_reset_theta`` rad from where it began."""
        p = self.params
        moved = math.hypot(pose[0] - self._escape_pose[0], pose[1] - self._escape_pose[1])
        turned = abs(math.remainder(pose[2] - self._escape_pose[2], 2 * math.pi))
        if moved > p.escape_reset_dist or turned > p.escape_reset_theta:
            self._escaping = False
