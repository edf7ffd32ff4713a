"""TrajectoryPlanner's sampling cycle as compiled kernels: samples, rollouts, scores and the choice.

``score_samples`` builds TrajectoryPlanner's velocity samples (forward speeds x turn rates, in-place turns,
the escape), rolls them out and scores them in one call; ``choose`` picks the command from the scores
(the cheapest forward rollout, else an in-place turn towards the goal); ``run_cycle`` is the whole cycle in one
call: both, the heading term in between and the chosen rollout as the local plan. They compute exactly what the
numpy steps in ``trajectory.TrajectoryPlannerROS._drive`` did (``np.linspace``'s arithmetic, ROS's step
counts, ``rollout.integrate_rollouts`` and ``rollout.rollout_scores``), without a Python step in between: one
controller cycle makes two calls instead of some forty numpy calls. Poses are grid-local (m, rad).

Numba's cache keys a kernel on its own file only: ``score_samples`` holds compiled copies of
``rollout.integrate_rollouts`` and ``ring_bounds.ring_scores`` (now with its FINE bound for in-place turns and its
flat-index reads of the memo and the distances), so
after changing those, change this file too (or clear the ``__pycache__`` caches) or the old copies keep running.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.navigation.controllers.mapgrid import wave_to
from navlab.navigation.controllers.ring_bounds import ring_scores
from navlab.navigation.controllers.rollout import heading_diffs, integrate_rollouts
from navlab.navigation.controllers.scene_kernel import moved_length, poses_out


@numba.njit(cache=True, inline="always")
def _linspace(start: float, stop: float, num: int, out: np.ndarray) -> None:  # pragma: no cover - compiled
    """``out[:num]`` = ``np.linspace(start, stop, num)`` bit for bit (``num`` 1: ``[start]``, as the caller's)."""
    if num <= 1:
        out[0] = start
        return
    div = num - 1
    delta = stop - start
    step = delta / div
    for k in range(num):
        out[k] = (k / div) * delta + start if step == 0 else k * step + start
    out[num - 1] = stop


@numba.njit(cache=True)
def score_samples(
    grid: np.ndarray,
    memo: np.ndarray,
    epoch: int,
    rings: np.ndarray,
    ring_counts: np.ndarray,
    path_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    goal_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    resolution: float,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    limits: np.ndarray,
    counts: tuple[int, int],
    timing: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    weights: np.ndarray,
    impossible: float,
    at: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:  # pragma: no cover
    """TrajectoryPlanner's samples, rollouts and costs: (targets (S, 2), rollouts (S, n, 3), costs (S,), turn
    rates ws (nw,), their spacing dw).

    ``limits`` = (vmin, vmax, wmin, wmax, min_in_place_vel_theta, escape_vel, acc_lim_x, acc_lim_theta);
    ``counts`` = (vx_samples, vtheta_samples); ``timing`` = (sim_time, sim_granularity, angular granularity,
    heading_scoring 0/1); ``path_wave``, ``goal_wave``: the path and goal distances (``mapgrid.wave_start``). A
    polygon robot's footprint is checked with ``ring_bounds.ring_scores`` (``memo``, ``epoch``, ``rings``,
    ``ring_counts``: its bound memo, the costs' epoch and rings; a point robot's centre cell alone). Rows: per
    speed the straight rollout then ``nw - 1`` turn rates from the lowest up, then the ``nw`` in-place turns, then
    the escape. ``at``: the scored step (``_heading_step``)."""
    vmin, vmax, wmin, wmax, min_ip, escape_vel, ax, ath = (
        limits[0],
        limits[1],
        limits[2],
        limits[3],
        limits[4],
        limits[5],
        limits[6],
        limits[7],
    )
    nvx, nw = max(counts[0], 1), max(counts[1], 1)
    vxs = np.empty(nvx)
    ws = np.empty(nw)
    _linspace(vmin, vmax, nvx, vxs)
    _linspace(wmin, wmax, nw, ws)
    dw = (wmax - wmin) / (nw - 1) if nw > 1 else 0.0
    nf = nvx * nw
    n = nf + nw + 1
    targets = np.zeros((n, 2))
    for a in range(nvx):
        for b in range(nw):
            targets[a * nw + b, 0] = vxs[a]
            if b > 0:
                targets[a * nw + b, 1] = ws[b - 1]
    for b in range(nw):
        targets[nf + b, 1] = max(ws[b], min_ip) if ws[b] > 0 else min(ws[b], -min_ip)
    targets[n - 1, 0] = escape_vel
    sim_time, gran, ang, heading = timing[0], timing[1], timing[2], timing[3] != 0.0
    steps = np.empty(n, dtype=np.int64)
    for r in range(n):
        if heading:
            steps[r] = max(1, int(sim_time / gran + 0.5))
        else:  # np.maximum(|v| * sim_time / granularity, |w| / angular granularity), rounded, at least 1
            need = max(abs(targets[r, 0]) * sim_time / gran, abs(targets[r, 1]) / ang)
            steps[r] = max(1, math.floor(need + 0.5))
    traj = np.empty((n, steps.max(), 3))
    c = np.empty(traj.shape[:2])
    s = np.empty(traj.shape[:2])
    integrate_rollouts(
        pose[0], pose[1], pose[2], velocity[0], velocity[1], targets, steps, sim_time, ax, ath, True, traj, c, s
    )
    costs = np.empty(n)
    ats = np.full(n, at, dtype=np.int64)
    inv = 1.0 / resolution
    scene = (path_wave, goal_wave, inv, traj, c, s, ox, oy, polygon, weights, impossible, ats, costs)
    ring_scores(grid, memo, epoch, rings, ring_counts, *scene)
    return targets, traj, costs, ws, dw


@numba.njit(cache=True)
def choose(
    costs: np.ndarray,
    traj: np.ndarray,
    ws: np.ndarray,
    dw: float,
    nf: int,
    escaping: bool,
    grid: np.ndarray,
    goal_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    resolution: float,
    lookahead: float,
    stuck_left: bool,
    stuck_right: bool,
) -> int:  # pragma: no cover - compiled
    """The chosen row of ``score_samples``' samples, -1 for none: the cheapest valid forward rollout (not while
    escaping), unless an in-place turn costs no more; among those turns (faster than one sample step, allowed by
    the stuck flags, look-ahead point on the grid) the one whose look-ahead point (``lookahead`` m ahead of its
    last pose) is nearest the goal (``goal_wave``: its distances on the costs ``grid``)."""
    best = -1
    if not escaping:
        low = math.inf
        for r in range(nf):
            if costs[r] >= 0 and costs[r] < low:
                best, low = r, costs[r]
    h, w = grid.shape
    inv = 1.0 / resolution
    last = traj.shape[1] - 1
    best_heading = math.inf
    for k in range(ws.size):
        c = costs[nf + k]
        if c < 0 or not (best < 0 or c <= costs[best]) or abs(ws[k]) <= dw:
            continue
        if not ((ws[k] < 0 and not stuck_left) or (ws[k] > 0 and not stuck_right)):
            continue
        th = traj[nf + k, last, 2]
        hx = traj[nf + k, last, 0] + lookahead * math.cos(th)
        hy = traj[nf + k, last, 1] + lookahead * math.sin(th)
        i, j = math.floor(hx * inv), math.floor(hy * inv)
        if not (0 <= i < w and 0 <= j < h):
            continue
        d = wave_to(grid, goal_wave, i, j)
        if d < best_heading:
            best, best_heading = nf + k, d
    return best


@numba.njit(cache=True)
def run_cycle(
    grid: np.ndarray,
    memo: np.ndarray,
    epoch: int,
    rings: np.ndarray,
    ring_counts: np.ndarray,
    path_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    goal_wave: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    resolution: float,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    limits: np.ndarray,
    counts: tuple[int, int],
    timing: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    polygon: bool,
    weights: np.ndarray,
    impossible: float,
    at: int,
    plan: np.ndarray,
    choice: tuple[bool, float, bool, bool],
    frame: tuple[float, float, float, float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int, np.ndarray]:  # pragma: no cover - compiled
    """One TrajectoryPlanner cycle: ``score_samples`` (its arguments first), with ``heading_scoring`` (``at`` >= 0)
    + 0.3 x ``rollout.heading_diffs`` at step ``at`` to the (grid-local) ``plan`` on every valid cost, then
    ``choose`` (``choice`` = (escaping, heading_lookahead, stuck_left, stuck_right)). Returns (targets, rollouts,
    costs, the chosen row (-1 none), the row to command (the chosen one, else the escape unless it has no path, else
    -1), that row's rollout up to where it stops moving in the costmap frame (``frame`` = the grid's origin x, y,
    yaw and the yaw's cosine and sine; empty for -1))."""
    targets, traj, costs, ws, dw = score_samples(
        grid,
        memo,
        epoch,
        rings,
        ring_counts,
        path_wave,
        goal_wave,
        resolution,
        pose,
        velocity,
        limits,
        counts,
        timing,
        ox,
        oy,
        polygon,
        weights,
        impossible,
        at,
    )
    n = costs.size
    if at >= 0:  # TrajectoryPlannerROS._add_heading
        valid = 0
        for r in range(n):
            valid += costs[r] >= 0
        poses = np.empty((valid, 3))
        k = 0
        for r in range(n):
            if costs[r] >= 0:
                poses[k, 0], poses[k, 1], poses[k, 2] = traj[r, at, 0], traj[r, at, 1], traj[r, at, 2]
                k += 1
        diffs = heading_diffs(grid, resolution, plan, poses)
        k = 0
        for r in range(n):
            if costs[r] >= 0:
                costs[r] += 0.3 * diffs[k]
                k += 1
    escaping, lookahead, stuck_left, stuck_right = choice
    nf = n - ws.size - 1
    best = choose(costs, traj, ws, dw, nf, escaping, grid, goal_wave, resolution, lookahead, stuck_left, stuck_right)
    row = best if best >= 0 else (n - 1 if costs[n - 1] > -2.0 else -1)
    if row < 0:
        return targets, traj, costs, best, row, np.zeros((0, 3))
    ox0, oy0, oyaw, c, s = frame
    path = traj[row]
    return targets, traj, costs, best, row, poses_out(path, moved_length(path), ox0, oy0, oyaw, c, s)
