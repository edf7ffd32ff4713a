"""Rollouts and footprint costs of the local planners, pure and compiled (Numba), vectorised over samples.

``rollout`` integrates (v, w) samples as base_local_planner does; ``footprint_costs`` reads a costmap under a
robot's outline (costmap_2d's 16-gon for a round robot) at many poses (``with_centre``: base_local_planner's
obstacle cost); the ``rollout_scores`` kernel scores whole rollouts (path/goal distance, occupancy) in one
pass. Poses are in grid-local metres (the costmap's origin at 0, its axes), costs the costmap's uint8 values.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.ndimage import maximum_filter

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN
from navlab.gridline import TIE_EARLY, line, line_cell
from navlab.navigation.controllers.common import footprint_outline

# --- rollout and footprint cost (pure, vectorised over samples) --------------------------------------


def rollout(
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    targets: np.ndarray,
    steps: int | np.ndarray,
    sim_time: float,
    acc: tuple[float, float],
    *,
    accelerate: bool,
) -> np.ndarray:
    """Poses (S, max(steps), 3) of a unicycle starting at ``pose`` with ``velocity``: sample ``s`` at
    t = 0, dt, ..., (n - 1) dt with n = ``steps[s]`` and dt = ``sim_time`` / n (ROS's rollouts end one step
    short of sim_time), then its last pose repeated up to the longest sample's length.

    ``targets`` (S, 2): commanded (v m/s, w rad/s). With ``accelerate`` the velocity moves towards the
    target by at most ``acc`` (m/s², rad/s²) * dt per step; otherwise it jumps to it (DWA).
    Each step moves along the heading held before the step (base_local_planner's integration).
    """
    n = np.broadcast_to(np.maximum(np.asarray(steps, dtype=np.int64), 1), (len(targets),)).copy()
    out = np.empty((len(targets), int(n.max()) if len(n) else 1, 3))
    none = np.zeros((0, 0))
    integrate_rollouts(
        float(pose[0]),
        float(pose[1]),
        float(pose[2]),
        float(velocity[0]),
        float(velocity[1]),
        np.ascontiguousarray(targets, dtype=np.float64),
        n,
        float(sim_time),
        float(acc[0]),
        float(acc[1]),
        accelerate,
        out,
        none,
        none,
    )
    return out


@numba.njit(cache=True)
def integrate_rollouts(
    x0: float,
    y0: float,
    th0: float,
    v0: float,
    w0: float,
    targets: np.ndarray,
    steps: np.ndarray,
    sim_time: float,
    ax: float,
    ath: float,
    accelerate: bool,
    out: np.ndarray,
    cos: np.ndarray,
    sin: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """:func:`rollout`'s integration into ``out``; ``cos``/``sin`` (the poses' shape, or empty: not kept) get the
    cosine and sine of each pose's heading, which the integration works out anyway. A sample's headings depend only
    on its turn rate and step count, not its speed: one with the same as an earlier sample (TrajectoryPlanner's
    speeds share their turn rates) takes that one's cosines and sines, the same values, instead of working them out
    again (a third of the integration's time on bench nav)."""
    keep = cos.size > 0
    for s in range(out.shape[0]):
        x, y, th, v, w = x0, y0, th0, v0, w0
        tv, tw = targets[s, 0], targets[s, 1]
        dt = sim_time / steps[s]
        twin = -1  # an earlier sample with the same turn rate (bit for bit: the sign of zero too) and steps
        if keep:
            for q in range(s):
                same = targets[q, 1] == tw and math.copysign(1.0, targets[q, 1]) == math.copysign(1.0, tw)
                if same and steps[q] == steps[s]:
                    twin = q
                    break
        for k in range(out.shape[1]):
            if k >= steps[s]:
                out[s, k, 0], out[s, k, 1], out[s, k, 2] = out[s, k - 1, 0], out[s, k - 1, 1], out[s, k - 1, 2]
                if keep:
                    cos[s, k], sin[s, k] = cos[s, k - 1], sin[s, k - 1]
                continue
            out[s, k, 0], out[s, k, 1], out[s, k, 2] = x, y, th
            if accelerate:
                v = min(max(tv, v - ax * dt), v + ax * dt)
                w = min(max(tw, w - ath * dt), w + ath * dt)
            else:
                v, w = tv, tw
            if twin >= 0:
                ch, sh = cos[twin, k], sin[twin, k]
            else:
                ch, sh = math.cos(th), math.sin(th)
            if keep:
                cos[s, k], sin[s, k] = ch, sh
            x += v * ch * dt
            y += v * sh * dt
            th += w * dt


def lookup(grid: np.ndarray, resolution: float, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Values of ``grid`` at grid-local points (any shape, same for x and y) and the mask of points inside it
    (outside points read the grid's cell (0, 0))."""
    shape = np.shape(x)
    vals = np.empty(shape, dtype=grid.dtype)
    inside = np.empty(shape, dtype=np.bool_)
    _lookup(
        grid,
        1.0 / resolution,
        np.ascontiguousarray(x, dtype=np.float64).reshape(-1),
        np.ascontiguousarray(y, dtype=np.float64).reshape(-1),
        vals.reshape(-1),
        inside.reshape(-1),
    )
    return vals, inside


@numba.njit(cache=True)
def _lookup(
    grid: np.ndarray, inv: float, x: np.ndarray, y: np.ndarray, vals: np.ndarray, inside: np.ndarray
) -> None:  # pragma: no cover - compiled
    h, w = grid.shape
    for k in range(x.size):
        i, j = math.floor(x[k] * inv), math.floor(y[k] * inv)
        ok = 0 <= i < w and 0 <= j < h
        inside[k] = ok
        vals[k] = grid[j, i] if ok else grid[0, 0]


def footprint_costs(
    cost: np.ndarray,
    resolution: float,
    poses: np.ndarray,
    outline: np.ndarray | None,
    *,
    near_max: np.ndarray | None = None,
    with_centre: bool = False,
) -> np.ndarray:
    """costmap_2d's footprint cost at each grid-local pose (..., 3): -1 where the robot may not be.

    Circular robot (``outline`` None): the centre cell's cost, -1 if LETHAL, INSCRIBED, unknown or off the
    map. Polygon: the highest cost under its edges (``outline`` (M, 2) base-frame points), -1 if any is
    LETHAL or unknown or the robot is off the map; ``with_centre``: base_local_planner's obstacle cost,
    ``max(footprint cost, centre cell cost)`` (``TrajectoryPlanner::generateTrajectory``,
    ``ObstacleCostFunction::footprintCost``). ``near_max``: :func:`outline_reach_max` of ``cost`` and
    ``outline``, if the caller has it (poses with nothing but free cells around, or with ``with_centre`` whose
    centre cell holds the highest cost around, skip their edges). One compiled pass.
    """
    poses = np.asarray(poses, dtype=np.float64)
    shape = poses.shape[:-1]
    flat = poses.reshape(-1, 3)
    out = np.empty(flat.shape[0], dtype=np.float64)
    grid = np.ascontiguousarray(cost)
    x, y = np.ascontiguousarray(flat[:, 0]), np.ascontiguousarray(flat[:, 1])
    if outline is None:
        empty = np.zeros(0)
        _footprint_pass(grid, grid, 1.0 / resolution, x, y, empty, empty, empty, empty, False, False, with_centre, out)
    else:
        ol = np.asarray(outline, dtype=np.float64)
        near = grid if near_max is None else np.ascontiguousarray(near_max, dtype=grid.dtype)
        # numpy's cos/sin (as before); the edge points are formed in the kernel in the same operation order
        _footprint_pass(
            grid,
            near,
            1.0 / resolution,
            x,
            y,
            np.cos(flat[:, 2]),
            np.sin(flat[:, 2]),
            np.ascontiguousarray(ol[:, 0]),
            np.ascontiguousarray(ol[:, 1]),
            True,
            near_max is not None,
            with_centre,
            out,
        )
    return out.reshape(shape)


def outline_reach_max(cost: np.ndarray, resolution: float, outline: np.ndarray) -> np.ndarray:
    """The highest cost (uint8, ``cost``'s shape; unknown for cells off the grid) in the square of cells that
    the ``outline``'s points can fall in while the robot's centre is in each cell: where it equals the centre
    cell's cost, no edge can cost more (the footprint cost needs no edge lookups)."""
    reach = math.ceil(float(np.hypot(outline[:, 0], outline[:, 1]).max()) / resolution) + 1
    return maximum_filter(np.asarray(cost, dtype=np.uint8), size=2 * reach + 1, mode="constant", cval=COST_UNKNOWN)


@numba.njit(cache=True, inline="always")
def outline_max(
    grid: np.ndarray, inv: float, x: float, y: float, c: float, s: float, ox: np.ndarray, oy: np.ndarray
) -> tuple[np.uint8, bool]:  # pragma: no cover
    """The highest cost under the outline points (``ox``, ``oy``, robot frame, m) of the pose at (``x``, ``y``)
    (grid frame, m; heading cos ``c``, sin ``s``) and whether any point falls off the grid. Every point, without
    early exit: the loop compiles to branch-free code."""
    h, w = grid.shape
    best = np.uint8(0)
    off = False
    for m in range(ox.size):
        px = x + c * ox[m] - s * oy[m]
        py = y + s * ox[m] + c * oy[m]
        pi, pj = np.int64(math.floor(px * inv)), np.int64(math.floor(py * inv))
        ok = (pi >= 0) & (pi < w) & (pj >= 0) & (pj < h)
        off |= not ok
        best = max(best, grid[pj if ok else 0, pi if ok else 0])
    return best, off


@numba.njit(cache=True, inline="always")
def _pose_cost(
    grid: np.ndarray,
    near: np.ndarray,
    inv: float,
    x: float,
    y: float,
    c: float,
    s: float,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    use_near: bool,
    with_centre: bool,
) -> float:  # pragma: no cover
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
    # every edge point: off the grid or on a LETHAL/unknown cell is illegal, else the highest cost
    best, off = outline_max(grid, inv, x, y, c, s, ox, oy)
    if off or best >= COST_LETHAL:
        return -1.0
    return float(max(best, centre)) if with_centre else float(best)


@numba.njit(cache=True)
def _footprint_pass(
    grid: np.ndarray,
    near: np.ndarray,
    inv: float,
    x: np.ndarray,
    y: np.ndarray,
    c: np.ndarray,
    s: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    use_near: bool,
    with_centre: bool,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    for k in range(x.size):
        if k > 0 and x[k] == x[k - 1] and y[k] == y[k - 1] and (not polygon or (c[k] == c[k - 1] and s[k] == s[k - 1])):
            out[k] = out[k - 1]  # a rollout's last pose repeated: the same cost
            continue
        ck, sk = (c[k], s[k]) if polygon else (1.0, 0.0)
        out[k] = _pose_cost(grid, near, inv, x[k], y[k], ck, sk, ox, oy, polygon, use_near, with_centre)


@numba.njit(cache=True)
def rollout_scores(
    grid: np.ndarray,
    near: np.ndarray,
    path_dist: np.ndarray,
    goal_dist: np.ndarray,
    inv: float,
    traj: np.ndarray,
    c: np.ndarray,
    s: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    use_near: bool,
    weights: np.ndarray,
    impossible: float,
    at: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """TrajectoryPlanner's cost of each rollout (S, n, 3): ``weights`` = (scale, pdist, gdist, occdist). As
    ``generateTrajectory``, the poses are checked in time order and the first failure decides: -1 when the pose
    is off the map or its footprint blocked, -2 when its cell has no path to the plan or goal. ``at`` (S,): -1
    scores (and checks) the distances at every pose, the last one counting; k >= 0 only at pose k, and -2 at no
    pose (distances 0): ``heading_scoring``'s single scoring step."""
    h, w = path_dist.shape
    for r in range(traj.shape[0]):
        top = -math.inf
        fail = 0.0
        fp = 0.0
        pd = gd = spd = sgd = 0.0
        for k in range(traj.shape[1]):
            x, y = traj[r, k, 0], traj[r, k, 1]
            i, j = math.floor(x * inv), math.floor(y * inv)
            inside = 0 <= i < w and 0 <= j < h
            pd, gd = (path_dist[j, i], goal_dist[j, i]) if inside else (path_dist[0, 0], goal_dist[0, 0])
            skip = False
            if use_near and polygon and inside:
                bound = near[j, i]  # no edge of this pose costs more: it cannot raise the rollout's cost
                skip = bound < COST_LETHAL and bound <= top
            if not skip:
                same = (
                    k > 0
                    and x == traj[r, k - 1, 0]
                    and y == traj[r, k - 1, 1]
                    and (not polygon or (c[r, k] == c[r, k - 1] and s[r, k] == s[r, k - 1]))
                )
                if not same:  # a rollout's last pose repeated has the same cost
                    fp = _pose_cost(grid, near, inv, x, y, c[r, k], s[r, k], ox, oy, polygon, use_near, True)
                if fp < 0:
                    fail = -1.0
                    break
                top = max(top, fp)
            if at[r] == -1 or at[r] == k:
                spd, sgd = pd, gd
                if pd >= impossible or gd >= impossible:
                    fail = -2.0
                    break
        out[r] = fail if fail < 0 else weights[0] * (weights[1] * spd + weights[2] * sgd + weights[3] * top)


@numba.njit(cache=True)
def heading_diffs(cost: np.ndarray, resolution: float, plan: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """TrajectoryPlanner's ``headingDiff`` at grid-local poses (S, 3): |angle| (rad) between each heading and the
    direction to the centre of the cell of the last plan point (plan (N, 2), grid-local) in a clear line of sight
    from the pose's cell (Bresenham, LETHAL/INSCRIBED/unknown cells block); the largest float when none is."""
    h, w = cost.shape
    out = np.full(poses.shape[0], np.finfo(np.float64).max)
    for r in range(poses.shape[0]):
        x, y, th = poses[r, 0], poses[r, 1], poses[r, 2]
        cx, cy = math.floor(x / resolution), math.floor(y / resolution)
        if not (0 <= cx < w and 0 <= cy < h):
            continue
        for q in range(plan.shape[0] - 1, -1, -1):
            gx, gy = math.floor(plan[q, 0] / resolution), math.floor(plan[q, 1] / resolution)
            if 0 <= gx < w and 0 <= gy < h and _line_clear(cost, cx, gx, cy, gy):
                v1x, v1y = (gx + 0.5) * resolution - x, (gy + 0.5) * resolution - y
                v2x, v2y = math.cos(th), math.sin(th)
                out[r] = abs(math.atan2(v1x * v2y - v1y * v2x, v1x * v2x + v1y * v2y))
                break
    return out


@numba.njit(cache=True, inline="always")
def _line_clear(cost: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> bool:  # pragma: no cover - compiled
    """Whether TrajectoryPlanner's ``lineCost`` (its Bresenham walk) from cell (x0, y0) to (x1, y1) meets no
    LETHAL, INSCRIBED or unknown cell."""
    ln = line(x0, y0, x1, y1, TIE_EARLY)
    for n in range(ln[0] + 1):
        x, y = line_cell(ln, n)
        if cost[y, x] >= COST_INSCRIBED:
            return False
    return True


def footprint_cells(
    shape: tuple[int, int],
    resolution: float,
    pose: tuple[float, float, float],
    polygon: np.ndarray | None,
    *,
    edges: np.ndarray | None = None,
) -> np.ndarray:
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
    return cells_under(
        int(h), int(w), float(resolution), float(x), float(y), poly, np.ascontiguousarray(ex), np.ascontiguousarray(ey)
    )


@numba.njit(cache=True)
def cells_under(
    h: int, w: int, res: float, x: float, y: float, poly: np.ndarray, ex: np.ndarray, ey: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`footprint_cells` of an ``h`` x ``w`` grid for the robot centred at grid-local (x, y): its polygon
    ``poly`` (K, 2) and outline points (``ex``, ``ey``) already placed in grid-local coordinates."""
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
    crosses = np.empty(n, dtype=np.bool_)
    at_x = np.empty(n)
    for j in range(lo_j, hi_j + 1):
        py = (j + 0.5) * res  # points_in_polygon's test of the cell centres, the row's edge crossings worked out once
        for m in range(n):
            ax, ay = poly[m, 0], poly[m, 1]
            bx, by = poly[(m + 1) % n, 0], poly[(m + 1) % n, 1]
            crosses[m] = (ay > py) != (by > py)
            at_x[m] = ax + (py - ay) * (bx - ax) / (by - ay) if crosses[m] else 0.0
        for i in range(lo_i, hi_i + 1):
            px = (i + 0.5) * res
            inside = False
            for m in range(n):
                if crosses[m] and px < at_x[m]:
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
            return np.array([*out[: k + 1], 0.0, *out[k + 1 :]])
    return np.array(out)
