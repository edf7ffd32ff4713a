"""TrajectoryPlanner's rollout scores with the footprint checked only where it can change the result.

A pose's occupancy cost is the highest cost under its footprint outline's points or at its centre cell
(``rollout._pose_cost``); the rollout's is the highest over its poses. Every outline point lies between
``rmin`` and ``rmax`` of the centre (the outline's nearest and farthest point), whatever the heading, so with
the centre in a given part of a cell the points can only fall in a fixed ring of cells around it
(:func:`ring_offsets`). The highest cost in that ring and the centre cell is a bound on the pose's cost, looked
up once per (cell, part) and kept while the costs stay the same (:func:`ring_bound`; a new epoch of the costs
forgets the memo without clearing it). A pose is checked point by point only when its
bound can still fail it (LETHAL or unknown in the ring) or raise the rollout's cost above what its other poses
already cost: first, in time order, the poses that may fail (the first failure decides, as
``rollout.rollout_scores``), then the highest bound of the rest, then (latest first) any pose whose bound is
still above. Every rollout starts from the same pose, checked once a call. A pose that stands where the pose
before or after it stands (the robot turning in place) first takes a tighter bound, the ring of its
``FINE`` x ``FINE`` part of the cell, looked up once for that spot: an in-place turn sweeps the outline round
one spot, and the quarter ring's bound is above its cost at nearly every heading. The costs are those of
``rollout.rollout_scores`` bit for bit: the maximum does not depend on the order, and a bound only decides
which poses need no check. Poses are grid-local (m, rad); cells (i, j) = (column, row).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN
from navlab.navigation.controllers.mapgrid import grow
from navlab.navigation.controllers.rollout import outline_max

QUARTERS = 2  # the centre's cell is split QUARTERS x QUARTERS ways: tighter rings than one ring per cell
FINE = 8  # an in-place turn's spot: its cell split FINE x FINE ways (rings after the quarters' in ring_offsets)
_EPS = 1e-6  # cells: room for the rounding of the outline points' coordinates


def ring_offsets(outline: np.ndarray, resolution: float) -> tuple[np.ndarray, np.ndarray]:
    """(offsets (Q + F, M, 2) as (di, dj), counts (Q + F,)): for each part q = qj * QUARTERS + qi of a cell, the
    cells relative to the centre's that an outline point (base frame, m) can fall in, at any heading, while the
    centre lies in that part of its cell; then, from row Q = QUARTERS², the same for the FINE x FINE parts
    (part Q + qj * FINE + qi). Each ring lists its cells row by row (dj, then di, ascending)."""
    r = np.hypot(outline[:, 0], outline[:, 1]) / resolution
    rmin, rmax = float(r.min()) - _EPS, float(r.max()) + _EPS
    reach = math.ceil(rmax) + 2
    b, a = (g.ravel() for g in np.mgrid[-reach : reach + 1, -reach : reach + 1])  # the cells, row by row
    keep = np.concatenate([_ring_cells(f, rmin, rmax, a, b) for f in (QUARTERS, FINE)])
    counts = keep.sum(axis=1).astype(np.int64)
    offsets = np.zeros((keep.shape[0], int(counts.max()), 2), dtype=np.int64)
    part, cell = np.nonzero(keep)  # row-major: each part's cells in the grid's order
    slot = np.cumsum(keep, axis=1)[part, cell] - 1
    offsets[part, slot, 0], offsets[part, slot, 1] = a[cell], b[cell]
    return offsets, counts


def _ring_cells(f: int, rmin: float, rmax: float, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Which of the cells (``a``, ``b``) (offsets from the centre's) an outline point between ``rmin`` and ``rmax``
    cells from the centre can fall in while the centre lies in part (qi, qj) of its cell split ``f`` x ``f`` ways:
    (f², cells) bool, row qj * f + qi. The centre's offset within its cell is in [qi/f, (qi+1)/f): a point in cell
    a lies between lx and hx away from it along x (likewise y)."""
    q = np.arange(f)[:, None]
    lx, hx = a - (q + 1) / f - _EPS, a + 1 - q / f + _EPS  # (f, cells): one row per qi
    ly, hy = b - (q + 1) / f - _EPS, b + 1 - q / f + _EPS  # one row per qj
    dx = np.where((lx <= 0.0) & (hx >= 0.0), 0.0, np.minimum(np.abs(lx), np.abs(hx)))
    dy = np.where((ly <= 0.0) & (hy >= 0.0), 0.0, np.minimum(np.abs(ly), np.abs(hy)))
    far = np.hypot(np.maximum(np.abs(lx), np.abs(hx))[None], np.maximum(np.abs(ly), np.abs(hy))[:, None])
    keep = (np.hypot(dx[None], dy[:, None]) <= rmax) & (far >= rmin)  # (qj, qi, cells)
    return keep.reshape(f * f, -1)


def new_memo(shape: tuple[int, int]) -> np.ndarray:
    """An empty bound memo (Q, H, W) int32 for a grid of ``shape``: an entry holds ``bound | epoch << 8`` and
    counts only under its epoch (see :func:`ring_scores`); 0 = never looked up. A new epoch forgets every entry
    without touching the memo (the costs changed)."""
    return np.zeros((QUARTERS * QUARTERS, *shape), dtype=np.int32)


MAX_EPOCH = (1 << 23) - 1  # epochs 1 .. MAX_EPOCH fit an int32 entry beside the bound; then start a new memo


@numba.njit(cache=True)
def ring_bound(
    grid: np.ndarray, memo: np.ndarray, epoch: int, offsets: np.ndarray, counts: np.ndarray, q: int, i: int, j: int
) -> int:  # pragma: no cover - compiled
    """The highest cost of the centre cell (i, j) and its ring ``q`` (unknown if the ring leaves the grid); kept
    in ``memo`` under ``epoch``."""
    h, w = grid.shape
    top = int(grid[j, i])
    for m in range(counts[q]):
        pi, pj = i + offsets[q, m, 0], j + offsets[q, m, 1]
        if pi < 0 or pj < 0 or pi >= w or pj >= h:
            top = COST_UNKNOWN
        else:
            top = max(top, int(grid[pj, pi]))
    memo[q, j, i] = top | (epoch << 8)
    return top


@numba.njit(cache=True)
def bound_at(
    grid: np.ndarray, memo: np.ndarray, epoch: int, offsets: np.ndarray, counts: np.ndarray, fx: float, fy: float
) -> int:  # pragma: no cover - compiled
    """:func:`ring_bound` of the centre at cell coordinates (fx, fy) (inside the grid), from ``memo`` when looked up
    before in this ``epoch``."""
    i, j = math.floor(fx), math.floor(fy)
    q = QUARTERS
    part = min(q - 1, int((fy - j) * q)) * q + min(q - 1, int((fx - i) * q))
    kept = int(memo[part, j, i])
    if kept >> 8 == epoch:
        return kept & 0xFF
    return ring_bound(grid, memo, epoch, offsets, counts, part, i, j)


@numba.njit(cache=True, inline="always")
def _stands(traj: np.ndarray, r: int, k: int, x: float, y: float) -> bool:  # pragma: no cover - compiled
    """Whether pose ``k`` of rollout ``r`` (at x, y) stands where the pose before or after it stands."""
    n = traj.shape[1]
    before = k > 0 and x == traj[r, k - 1, 0] and y == traj[r, k - 1, 1]
    return before or (k + 1 < n and x == traj[r, k + 1, 0] and y == traj[r, k + 1, 1])


@numba.njit(cache=True)
def _fine_bound(
    grid: np.ndarray, offsets: np.ndarray, counts: np.ndarray, fx: float, fy: float
) -> int:  # pragma: no cover - compiled
    """The highest cost of the centre cell at cell coordinates (fx, fy) (inside the grid) and the ring of its FINE x
    FINE part (``ring_offsets``' rows from QUARTERS²; unknown if the ring leaves the grid)."""
    h, w = grid.shape
    i, j = math.floor(fx), math.floor(fy)
    f = FINE
    part = QUARTERS * QUARTERS + min(f - 1, int((fy - j) * f)) * f + min(f - 1, int((fx - i) * f))
    top = int(grid[j, i])
    for m in range(counts[part]):
        pi, pj = i + offsets[part, m, 0], j + offsets[part, m, 1]
        if pi < 0 or pj < 0 or pi >= w or pj >= h:
            return COST_UNKNOWN
        top = max(top, int(grid[pj, pi]))
    return top


@numba.njit(cache=True, inline="always")
def _exact(
    grid: np.ndarray, inv: float, x: float, y: float, c: float, s: float, ox: np.ndarray, oy: np.ndarray, bound: int
) -> float:  # pragma: no cover - compiled
    """``rollout._pose_cost`` with the centre inside the grid and ``with_centre``, given the pose's ring bound."""
    i, j = math.floor(x * inv), math.floor(y * inv)
    centre = grid[j, i]
    if bound < COST_LETHAL and (bound == 0 or bound == centre):
        return float(bound)  # nothing under the outline costs more than the centre
    best, off = outline_max(grid, inv, x, y, c, s, ox, oy)  # rollout._pose_cost's loop, inlined
    if off or best >= COST_LETHAL:
        return -1.0
    return float(max(best, centre))


@numba.njit(cache=True)
def ring_scores(
    grid: np.ndarray,
    memo: np.ndarray,
    epoch: int,
    offsets: np.ndarray,
    counts: np.ndarray,
    path_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    goal_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    inv: float,
    traj: np.ndarray,
    c: np.ndarray,
    s: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    weights: np.ndarray,
    impossible: float,
    at: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """``rollout.rollout_scores`` with ``with_centre`` (the same arguments, ``memo``/``epoch``/``offsets``/``counts``
    (:func:`new_memo`, :func:`ring_offsets`; the epoch names the costs ``grid`` holds) in place of ``near`` and
    ``use_near``, which a point robot (``polygon`` False) does without; the distance waves to the path and to the
    goal (``mapgrid.wave_start``) in place of their maps, grown as far as the rollouts need): the cost of each
    rollout (S, n, 3) into ``out``; -1 blocked or off the map, -2 no path."""
    h, w = grid.shape
    n = traj.shape[1]
    q = QUARTERS
    path_dist, path_reached, path_free, path_queue, path_ends = path_wave
    goal_dist, goal_reached, goal_free, goal_queue, goal_ends = goal_wave
    bounds = np.empty(n, dtype=np.int64)
    # the memo and the distances read by flat index (part, row, column): ~5 % of a TrajectoryPlanner cycle
    memo_flat, path_flat, goal_flat, part_size = memo.flat, path_dist.flat, goal_dist.flat, h * w
    unreached = float(h * w) + 1.0  # mapgrid's unreachable_value: a wave's cells not reached (yet)
    fine = counts.size > q * q  # ring_offsets' FINE rings follow the quarters'
    spot_x = spot_y = math.nan  # the last spot whose FINE bound was looked up, and that bound
    spot = 0
    # the first pose, which every rollout of a cycle shares: its cost once, when it cannot fail
    e0 = -1.0
    if polygon and traj.shape[0] > 0 and n > 0:
        x0, y0 = traj[0, 0, 0], traj[0, 0, 1]
        i0, j0 = math.floor(x0 * inv), math.floor(y0 * inv)
        inside = 0 <= i0 < w and 0 <= j0 < h
        b0 = bound_at(grid, memo, epoch, offsets, counts, x0 * inv, y0 * inv) if inside else COST_UNKNOWN
        if b0 < COST_LETHAL:
            e0 = _exact(grid, inv, x0, y0, c[0, 0], s[0, 0], ox, oy, b0)
    for r in range(traj.shape[0]):
        shared = e0 >= 0.0 and traj[r, 0, 0] == traj[0, 0, 0] and traj[r, 0, 1] == traj[0, 0, 1]
        shared = shared and c[r, 0] == c[0, 0] and s[r, 0] == s[0, 0]
        top = e0 if shared else -math.inf  # the shared first pose's cost, known
        fail = 0.0
        spd = sgd = 0.0
        first, first_bound = -1, -1  # the deferred pose of highest bound
        for k in range(n):
            x, y = traj[r, k, 0], traj[r, k, 1]
            bounds[k] = -1
            moved = k == 0 or x != traj[r, k - 1, 0] or y != traj[r, k - 1, 1]
            turned = moved or c[r, k] != c[r, k - 1] or s[r, k] != s[r, k - 1]
            if not (turned or at[r] == k):
                continue  # the pose before, repeated: nothing new (its distances passed already)
            fx, fy = x * inv, y * inv
            i, j = math.floor(fx), math.floor(fy)
            inside = 0 <= i < w and 0 <= j < h
            if turned:
                if not inside:
                    fail = -1.0
                    break
                if not polygon:  # a point robot: its centre cell, blocked from INSCRIBED up
                    if grid[j, i] >= COST_INSCRIBED:
                        fail = -1.0
                        break
                    top = max(top, float(grid[j, i]))
                else:
                    part = min(q - 1, int((fy - j) * q)) * q + min(q - 1, int((fx - i) * q))
                    # bound_at, written out (the hot loop: a call costs more than a hit)
                    kept = int(memo_flat[part * part_size + j * w + i])
                    if kept >> 8 == epoch:
                        b = kept & 0xFF
                    else:
                        b = ring_bound(grid, memo, epoch, offsets, counts, part, i, j)
                    if b >= COST_LETHAL:  # it may fail: check it now, in time order
                        fp = _exact(grid, inv, x, y, c[r, k], s[r, k], ox, oy, b)
                        if fp < 0:
                            fail = -1.0
                            break
                        top = max(top, fp)
                    else:
                        bounds[k] = b
                        if b > first_bound:
                            first, first_bound = k, b
            if at[r] == k or (at[r] == -1 and moved):  # (unmoved, the distances are those that passed)
                pi, pj = (i, j) if inside else (0, 0)
                pd = path_flat[pj * w + pi]
                if pd == unreached:  # not reached yet: wave_start's fill (cells + 1); a reached cell reads less
                    pd = grow(grid, path_dist, path_reached, path_free, path_queue, path_ends, pi, pj)
                gd = goal_flat[pj * w + pi]
                if gd == unreached:
                    gd = grow(grid, goal_dist, goal_reached, goal_free, goal_queue, goal_ends, pi, pj)
                spd, sgd = pd, gd
                if pd >= impossible or gd >= impossible:
                    fail = -2.0
                    break
        if fail < 0:
            out[r] = fail
            continue
        # the deferred poses whose bound is above the cost so far: the highest first, then the latest first (a
        # rollout's cost tends to grow along it)
        for a in range(-1, n):
            k = first if a < 0 else n - 1 - a
            if k < 0 or bounds[k] <= top or (a >= 0 and k == first) or (k == 0 and shared):
                continue
            x, y, b = traj[r, k, 0], traj[r, k, 1], bounds[k]
            if fine and _stands(traj, r, k, x, y):  # turning on one spot: its FINE part's ring, once
                if not (x == spot_x and y == spot_y):
                    spot_x, spot_y, spot = x, y, _fine_bound(grid, offsets, counts, x * inv, y * inv)
                if spot <= top:
                    continue
                b = min(b, spot)
            top = max(top, _exact(grid, inv, x, y, c[r, k], s[r, k], ox, oy, b))
        out[r] = weights[0] * (weights[1] * spd + weights[2] * sgd + weights[3] * top)
