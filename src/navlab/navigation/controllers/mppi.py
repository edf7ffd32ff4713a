"""A Nav2-style MPPI controller (``nav2_mppi_controller::MPPIController``) for a differential base.

Model Predictive Path Integral control: each cycle shifts the previous optimal control sequence one
step (warm start), samples ``batch_size`` sequences around it (Gaussian noise ``vx_std``, ``wz_std``),
limits them to what ``ax_max``/``ax_min``/``az_max`` allow from the current velocity, rolls every
sequence out as a unicycle over ``time_steps`` x ``model_dt`` (one compiled loop, reading the costmap
under each point), scores them with the critics (``mppi_critics``; ConstraintCritic charges samples
beyond ``vx_min``/``vx_max``) plus the control cost ``gamma / std² · Σ u·ε``, and averages them with
softmax weights ``exp(-(cost - min) / temperature)``; the average is clipped to the velocity and
acceleration limits. After ``iteration_count`` rounds the sequence is smoothed (Savitzky-Golay, with
the commands already sent) and its first control is the command.

One navlab addition: ``noise_correlation`` makes each sample's noise an AR(1) process over time
(same per-step spread, coherent swerves instead of jitter), which finds the way round obstacles the
path runs into (default 0.9; 0 is Nav2's white noise, which stalls in front of an obstacle on the path).
A second, off by default: Regulated Pure Pursuit's cost-regulated linear velocity scaling with its names
(``use_cost_regulated_linear_velocity_scaling``, ``cost_scaling_dist``, ``cost_scaling_gain``,
``inflation_cost_scaling_factor``, ``regulated_linear_scaling_min_speed``): the costmap cost under a point
stands for its distance to the nearest obstacle, and nearer than ``cost_scaling_dist`` the speed limit drops
with it. The command is capped by the limit under the robot, and ConstraintCritic charges every sample's speed
above the limit under each of its points, so the optimum slows before a gap, not in it.
A third, off by default: ``use_rotation_shim``, Nav2's rotation shim for a robot standing still facing away from
its path (``mppi_rotation``: it turns in place toward the path, then MPPI drives).

As in Nav2 the rollout's first step moves at the measured velocity (the command acts one
``model_dt`` later). Trajectories through LETHAL/INSCRIBED/unknown cells take ``collision_cost``; if
every sample collides the sequence is reset and the round retried (``retry_attempt_limit``), then
the controller stops and sets ``valid`` False. Parameters (``mppi_params``): Nav2 names and defaults; a critic's own are
in a dict under its name (``CostCritic: {cost_weight: 3.81}``) or dotted (``CostCritic.cost_weight``).
The goal checker's ``xy_goal_tolerance``/``yaw_goal_tolerance`` (Nav2 SimpleGoalChecker, stateful)
are read here too. Units: m, rad, s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numba
import numpy as np
from scipy.signal import savgol_coeffs

from navlab.core import read_params
from navlab.grid import COST_INSCRIBED, Grid
from navlab.navigation.controllers import mppi_critics as critics
from navlab.navigation.controllers.common import (
    LocalFrame,
    Nav2PlanController,
    cost_regulated_speeds,
    footprint_outline,
    inscribed_radius,
)
from navlab.navigation.controllers.mppi_params import WHAT, MppiParams
from navlab.navigation.controllers.mppi_rotation import RotationShim
from navlab.navigation.errors import NavigationError
from navlab.plugins import PluginContext

PATH_SPACING = 0.05  # m: plans are resampled to this (Nav2's path-index offsets assume costmap cells)


@numba.njit(cache=True, inline="always")
def _reachable(
    cv: float, cw: float, v: float, om: float, dt: float, acc: float, dec: float, aw: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """The control (cv, cw) limited to what the accelerations allow in ``dt`` from (v, om): ``acc`` speeding up and
    ``dec`` (<= 0) slowing down, in either direction of travel, ``aw`` for the turn rate."""
    if v >= 0.0:
        cv = min(max(cv, v + dec * dt), v + acc * dt)
    else:
        cv = min(max(cv, v - acc * dt), v - dec * dt)
    return cv, min(max(cw, om - aw * dt), om + aw * dt)


@numba.njit(cache=True)
def _sample_rollout(
    rng: np.random.Generator,
    seq: np.ndarray,
    std: np.ndarray,
    corr: float,
    v0: float,
    w0: float,
    x0: float,
    y0: float,
    th0: float,
    dt: float,
    limits: np.ndarray,
    cost: np.ndarray,
    res: float,
    u: np.ndarray,
    xs: np.ndarray,
    ys: np.ndarray,
    ths: np.ndarray,
    cs: np.ndarray,
    arc: np.ndarray,
    dots: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Sample controls ``seq`` (T, 2) + noise from ``rng`` (N(0, std) at every step, AR(1)-correlated over time
    with coefficient ``corr``), constrain them into ``u`` (S, T, 2), roll every sample out (poses, cost under
    each point, distance travelled) and sum ``seq · (u - seq) / std²`` into ``dots`` (S,) for the control cost."""
    acc, dec, aw = limits[3], limits[4], limits[5]
    n_s, n_t = u.shape[0], u.shape[1]
    h, w = cost.shape
    inv = 1.0 / res
    iv, iw = 1.0 / (std[0] * std[0]), 1.0 / (std[1] * std[1])
    fresh = math.sqrt(1.0 - corr * corr)
    for s in range(n_s):
        v, om, x, y, th, d, dot = v0, w0, x0, y0, th0, 0.0, 0.0
        ev, ew = rng.standard_normal(), rng.standard_normal()
        for t in range(n_t):
            if t > 0:
                ev = corr * ev + fresh * rng.standard_normal()
                ew = corr * ew + fresh * rng.standard_normal()
            step = v * dt
            x += step * math.cos(th)
            y += step * math.sin(th)
            th += om * dt
            d += abs(step)
            xs[s, t], ys[s, t], ths[s, t], arc[s, t] = x, y, th, d
            i, j = math.floor(x * inv), math.floor(y * inv)
            cs[s, t] = cost[j, i] if 0 <= i < w and 0 <= j < h else 255
            cv, cw = _reachable(seq[t, 0] + std[0] * ev, seq[t, 1] + std[1] * ew, v, om, dt, acc, dec, aw)
            u[s, t, 0], u[s, t, 1] = cv, cw
            dot += seq[t, 0] * (cv - seq[t, 0]) * iv + seq[t, 1] * (cw - seq[t, 1]) * iw
            v, om = cv, cw
        dots[s] = dot


@numba.njit(cache=True)
def _accel_limit(seq: np.ndarray, v0: float, w0: float, dt: float, limits: np.ndarray) -> None:  # pragma: no cover
    """Limit each control of ``seq`` (T, 2) in place to what the acceleration limits allow from the one before."""
    acc, dec, aw = limits[3], limits[4], limits[5]
    v, om = v0, w0
    for t in range(seq.shape[0]):
        seq[t, 0], seq[t, 1] = _reachable(seq[t, 0], seq[t, 1], v, om, dt, acc, dec, aw)
        v, om = seq[t, 0], seq[t, 1]


class MPPIController(Nav2PlanController):
    """The MPPI controller behind the Controller protocol.

    ``params``: a Nav2 MPPI parameter dict or ``MppiParams``; ``rng``: the seeded generator every noise
    sample comes from (required: same seed, same commands); ``footprint``: polygon [[x, y], ...] (m, base
    frame) for CostCritic's ``consider_footprint``, or None for a circular robot of ``robot_radius`` m
    (the cost-regulated speed limit reads the inscribed radius of either).

    After each cycle: ``local_plan`` (T + 1, 3) the optimal trajectory (costmap frame), ``sequence``
    (T, 2) the optimal controls, ``costs`` (S,) the samples' costs, ``valid`` False if every sample collided.
    """

    what = WHAT
    spacing = PATH_SPACING

    def __init__(
        self,
        params: Mapping[str, Any] | MppiParams | None = None,
        *,
        rng: np.random.Generator | None = None,
        footprint: Any = None,
        robot_radius: float | None = None,
    ) -> None:
        if not isinstance(rng, np.random.Generator):
            raise NavigationError(f"{WHAT} needs rng=numpy.random.Generator (seeded), got {type(rng).__name__}")
        self.params = read_params(MppiParams, params)
        self.rng = rng
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64)
        footprint_outline(self.footprint, PATH_SPACING)  # validate now
        p = self.params
        self._limits = np.array([p.vx_min, p.vx_max, p.wz_max, p.ax_max, p.ax_min, p.az_max])
        self._std = np.array([p.vx_std, p.wz_std])
        self._sg = savgol_coeffs(9, 2)  # Nav2 smooths with a 9-point quadratic Savitzky-Golay filter
        self._speed_limits = (
            cost_regulated_speeds(
                p.vx_max,
                p.cost_scaling_dist,
                p.cost_scaling_gain,
                p.inflation_cost_scaling_factor,
                inscribed_radius(self.footprint, robot_radius),
                p.regulated_linear_scaling_min_speed,
            )
            if p.use_cost_regulated_linear_velocity_scaling
            else None
        )  # m/s per costmap cost, or None
        self._shim = RotationShim.of(p)
        self._plan_state(p.xy_goal_tolerance, p.yaw_goal_tolerance, p.stateful)
        self.reset()

    def reset(self) -> None:
        """Forget the optimal sequence and the command history (a new goal)."""
        self.sequence = np.zeros((self.params.time_steps, 2))
        self._history = np.zeros((4, 2))
        self.local_plan = np.zeros((0, 3))
        self.costs = np.zeros(0)
        self.valid = True
        self._backing = False  # the rotation shim is backing the robot out to turn

    def _local_path(self, pose: tuple[float, float, float]) -> np.ndarray:
        """The plan from the point nearest the robot (searched ahead of the last one) to ``prune_distance``
        along it (Nav2's path handler), in the costmap frame."""
        assert self._plan is not None
        plan = self._plan
        ahead = plan[self._progress : self._progress + int(4.0 / PATH_SPACING)]
        d = np.hypot(ahead[:, 0] - pose[0], ahead[:, 1] - pose[1])
        self._progress += int(np.argmin(d))
        rest = plan[self._progress :]
        seg = np.hypot(*np.diff(rest, axis=0).T)
        n = int(np.searchsorted(np.cumsum(seg), self.params.prune_distance)) + 2
        return rest[:n]

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> MPPIController:
        """From the controller's parameter namespace, the host's seeded ``rng`` (required) and the local costmap's
        footprint polygon (None for a round robot)."""
        fp = context.footprint
        return cls(
            params,
            rng=context.rng,
            footprint=None if fp is None else fp.polygon,
            robot_radius=None if fp is None else fp.radius,
        )

    def _command(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        self._check_call(self._plan, costmap)
        assert costmap is not None
        p = self.params
        pose = (float(pose[0]), float(pose[1]), float(pose[2]))
        v0, w0 = float(velocity[0]), float(velocity[1])
        frame = LocalFrame.of(costmap)
        grid = np.ascontiguousarray(costmap.data, dtype=np.uint8)
        res = costmap.resolution
        px, py, pth = frame.pose_in(pose)
        path = frame.points_in(self._local_path(pose))
        g = frame.points_in(np.array([self._goal[:2]]))[0]
        goal = (float(g[0]), float(g[1]), None if self._goal[2] is None else self._goal[2] - frame.oyaw)
        dist_to_goal = math.hypot(pose[0] - self._goal[0], pose[1] - self._goal[1])
        outline = footprint_outline(self.footprint, res)
        if self._shim is not None:
            cmd = self._shim.command(
                (px, py, pth), (v0, w0), path, 1.0 / p.controller_frequency, grid, res, outline, backing=self._backing
            )
            self._backing = cmd is not None and cmd[0] < 0.0
            if cmd is not None:  # turning in place toward the path (or backing out to turn): MPPI starts afresh
                v, w = cmd
                self.sequence[:] = 0.0
                self._history = np.vstack([self._history[1:], [[v, w]]])
                ahead = (pth + w / p.controller_frequency, v / p.controller_frequency)
                x1, y1 = px + ahead[1] * math.cos(pth), py + ahead[1] * math.sin(pth)
                self.local_plan = frame.poses_out(np.array([[px, py, pth], [x1, y1, ahead[0]]]))
                return v, w
        s_n, t_n = p.batch_size, p.time_steps
        u = np.empty((s_n, t_n, 2))
        xs, ys, ths, arc = (np.empty((s_n, t_n)) for _ in range(4))
        cs = np.empty((s_n, t_n), dtype=np.uint8)
        dots = np.empty(s_n)
        self.sequence = np.vstack([self.sequence[1:], self.sequence[-1:]])  # warm start
        self.valid = True
        attempts = 0
        iteration = 0
        while iteration < p.iteration_count:
            _sample_rollout(
                self.rng,
                self.sequence,
                self._std,
                p.noise_correlation,
                v0,
                w0,
                px,
                py,
                pth,
                p.model_dt,
                self._limits,
                grid,
                res,
                u,
                xs,
                ys,
                ths,
                cs,
                arc,
                dots,
            )
            batch = critics.Batch(
                xs,
                ys,
                ths,
                u[..., 0],
                u[..., 1],
                cs,
                arc,
                (px, py, pth),
                path,
                goal,
                dist_to_goal,
                p.model_dt,
                (p.vx_min, p.vx_max),
                grid,
                res,
                outline,
                None if self._speed_limits is None else self._speed_limits[cs],
            )
            costs = self._score(batch)
            if bool((cs >= COST_INSCRIBED).any(axis=1).all()):  # every sample collides
                attempts += 1
                self.sequence[:] = 0.0
                if attempts > p.retry_attempt_limit:
                    self.valid = False
                    self.costs, self.local_plan = costs, np.zeros((0, 3))
                    return 0.0, 0.0
                continue
            costs += p.gamma * dots
            weights = np.exp(-(costs - costs.min()) / p.temperature)
            weights /= weights.sum()
            self.sequence = np.einsum("s,stc->tc", weights, u)
            self._constrain_sequence(v0, w0)
            self.costs = costs
            iteration += 1
        self._smooth()
        v = float(min(max(self.sequence[0, 0], p.vx_min), p.vx_max))
        if self._speed_limits is not None:
            i, j = math.floor(px / res), math.floor(py / res)
            inside = 0 <= i < grid.shape[1] and 0 <= j < grid.shape[0]
            v = min(v, float(self._speed_limits[grid[j, i] if inside else 255]))
        w = float(min(max(self.sequence[0, 1], -p.wz_max), p.wz_max))
        self._history = np.vstack([self._history[1:], [[v, w]]])
        self.local_plan = frame.poses_out(self._optimal_trajectory(px, py, pth, v0, w0))
        return v, w

    def _score(self, batch: critics.Batch) -> np.ndarray:
        total = np.zeros(len(batch.x))
        for name in self.params.critics:
            c = self.params.critic(name)
            if c.enabled:
                out = critics.SCORERS[name](c, batch)
                if out is not None:
                    total += out
        return total

    def _constrain_sequence(self, v0: float, w0: float) -> None:
        """Clip the optimal sequence to the velocity limits and, step by step from the measured velocity, to
        the acceleration limits (Nav2's ``applyControlSequenceConstraints``)."""
        p = self.params
        seq = self.sequence
        np.clip(seq[:, 0], p.vx_min, p.vx_max, out=seq[:, 0])
        np.clip(seq[:, 1], -p.wz_max, p.wz_max, out=seq[:, 1])
        _accel_limit(seq, v0, w0, p.model_dt, self._limits)

    def _smooth(self) -> None:
        """Savitzky-Golay smoothing of the sequence, with the last 4 commands sent before it."""
        seq = self.sequence
        ext = np.vstack([self._history, seq, np.repeat(seq[-1:], 4, axis=0)])
        for c in range(2):
            seq[:, c] = np.convolve(ext[:, c], self._sg, mode="valid")

    def _optimal_trajectory(self, x: float, y: float, th: float, v0: float, w0: float) -> np.ndarray:
        """Poses (T + 1, 3) from the robot along the optimal sequence (first step at the measured velocity)."""
        dt = self.params.model_dt
        v = np.concatenate([[v0], self.sequence[:-1, 0]])
        w = np.concatenate([[w0], self.sequence[:-1, 1]])
        yaw = th + np.concatenate([[0.0], np.cumsum(w * dt)])
        px = x + np.concatenate([[0.0], np.cumsum(v * np.cos(yaw[:-1]) * dt)])
        py = y + np.concatenate([[0.0], np.cumsum(v * np.sin(yaw[:-1]) * dt)])
        return np.column_stack([px, py, yaw])
