"""base_local_planner/TrajectoryPlannerROS: trajectory rollout (or DWA with its ``dwa`` flag) as ROS 1's
base_local_planner does it (see ``rollout_controller`` for the shared cycle and the cost it minimises).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab.navigation.controllers import ring_bounds
from navlab.navigation.controllers import trajectory_cycle as cycle
from navlab.navigation.controllers.common import InPlaceFlags
from navlab.navigation.controllers.params import TrajectoryPlannerParams
from navlab.navigation.controllers.rollout import heading_diffs
from navlab.navigation.controllers.rollout_controller import LocalScene, RolloutController

_NO_MEMO, _NO_OFFSETS, _NO_COUNTS = (  # a point robot's (typed) empties
    np.zeros((0, 0, 0), dtype=np.int32),
    np.zeros((0, 0, 2), dtype=np.int64),
    np.zeros(0, dtype=np.int64),
)

# --- base_local_planner/TrajectoryPlannerROS ----------------------------------------------------------


class TrajectoryPlannerROS(RolloutController):
    """base_local_planner's trajectory rollout / DWA planner (``dwa`` flag) behind the Controller protocol
    (``params``: a TrajectoryPlannerROS parameter dict, ROS 1 names, or ``TrajectoryPlannerParams``; the other
    arguments as ``RolloutController``'s)."""

    what = "TrajectoryPlannerROS"
    params_class = TrajectoryPlannerParams
    params: TrajectoryPlannerParams

    def _setup(self) -> None:
        self._escaping = False
        self._escape_pose = (0.0, 0.0, 0.0)
        self._spin = InPlaceFlags(self.params.oscillation_reset_dist)
        self._rings: dict[float, tuple[np.ndarray, ...]] = {}  # resolution: ring offsets, counts, outline x, y
        self._memo: tuple[np.ndarray | None, np.ndarray, int] | None = None  # (costs seen, ring bound memo, epoch)
        self._consts: tuple[Any, tuple[np.ndarray, np.ndarray, int]] | None = None  # (key, _constants')

    def _new_goal(self) -> None:
        self._escaping = False
        self._spin.reset()

    def _in_place_limits(self, err: float) -> tuple[float, float]:
        p = self.params
        return (p.max_vel_theta if err > 0 else -p.min_vel_theta), p.min_in_place_vel_theta

    def _free_mode(self, res: float) -> tuple[int, np.ndarray | None, np.ndarray | None]:
        """The cells under the robot now never block the path map's wave (ROS's ``within_robot``): its centre cell
        for a point robot, else the cells under its polygon."""
        edges = self._outline(res)
        return (1, None, None) if edges is None or self.footprint is None else (2, self.footprint, edges)

    def _check(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        return self._score(scene, traj)

    def _steps(self, targets: np.ndarray) -> np.ndarray:
        """``TrajectoryPlanner::generateTrajectory``: round(max(|v| sim_time / sim_granularity, |w| /
        angular_sim_granularity)), at least 1 (ROS leaves sim_time out of the angular term)."""
        p = self.params
        if p.heading_scoring:  # every sample: sim_time / sim_granularity steps
            return np.full(len(targets), max(1, int(p.sim_time / p.sim_granularity + 0.5)), dtype=np.int64)
        ang = p.angular_sim_granularity if p.angular_sim_granularity > 0 else p.sim_granularity
        need = np.maximum(np.abs(targets[:, 0]) * p.sim_time / p.sim_granularity, np.abs(targets[:, 1]) / ang)
        return np.maximum(1, np.floor(need + 0.5)).astype(np.int64)

    def _heading_step(self, steps: int) -> int:
        """With ``heading_scoring``, the one step whose path and goal distances (and heading) are scored: the
        first whose time (accumulated as ROS adds dt) lies in [heading_scoring_timestep, + dt); -2 when none
        does (then they count 0). Without it -1: every step, the last one counting."""
        p = self.params
        if not p.heading_scoring:
            return -1
        dt, t = p.sim_time / steps, 0.0
        for k in range(steps):
            if p.heading_scoring_timestep <= t < p.heading_scoring_timestep + dt:
                return k
            t += dt
        return -2

    def _score(self, scene: LocalScene, traj: np.ndarray) -> np.ndarray:
        """Costs (S,): pdist * path_dist + gdist * goal_dist + occdist * max_cost (+ 0.3 * heading difference
        with ``heading_scoring``); -1 blocked, -2 no path."""
        res = scene.resolution
        traj = np.ascontiguousarray(traj, dtype=np.float64)
        memo, epoch, offsets, counts, ox, oy, polygon = self._footprint(scene)
        if polygon:  # numpy's cos/sin, as footprint_costs
            c, s = np.cos(traj[..., 2]), np.sin(traj[..., 2])
        else:
            c = s = np.zeros(traj.shape[:2])
        cost = np.empty(traj.shape[0])
        at = self._heading_step(traj.shape[1])
        args = (1.0 / res, traj, c, s, ox, oy)
        ats = np.full(len(traj), at, dtype=np.int64)
        scored = (scene.goal_wave, *args, polygon, self._weights(res), scene.impossible, ats, cost)
        ring_bounds.ring_scores(scene.cost, memo, epoch, offsets, counts, scene.path_wave, *scored)
        self._add_heading(scene, cost, traj, at)
        return cost

    def _drive(
        self, scene: LocalScene, pose: tuple[float, float, float], velocity: tuple[float, float]
    ) -> tuple[float, float]:
        p = self.params
        v0, w0 = velocity
        x, y, _ = scene.pose
        lg = scene.local_goal()
        horizon = p.sim_period if p.dwa else p.sim_time
        vmax = min(p.max_vel_x, math.hypot(lg[0] - x, lg[1] - y) / p.sim_time)
        vmax = max(min(vmax, v0 + p.acc_lim_x * horizon), p.min_vel_x)
        # not clamped to vmax: a robot faster than the local goal's cap samples from its reachable lowest speed
        # down to the cap, as createTrajectories does (its dvx is then negative)
        vmin = max(p.min_vel_x, v0 - p.acc_lim_x * horizon)
        wmax = min(p.max_vel_theta, w0 + p.acc_lim_theta * horizon)
        wmin = min(max(p.min_vel_theta, w0 - p.acc_lim_theta * horizon), wmax)
        # samples, rollouts, costs, the choice and the local plan in one compiled call (trajectory_cycle)
        res = scene.resolution
        memo, epoch, offsets, counts, ox, oy, polygon = self._footprint(scene)
        limits = np.array(
            [vmin, vmax, wmin, wmax, p.min_in_place_vel_theta, p.escape_vel, p.acc_lim_x, p.acc_lim_theta]
        )
        timing, weights, at = self._constants(res)
        f = scene.frame
        targets, traj, costs, best, row, local = cycle.run_cycle(
            scene.cost,
            memo,
            epoch,
            offsets,
            counts,
            scene.path_wave,
            scene.goal_wave,
            res,
            scene.pose,
            velocity,
            limits,
            (p.vx_samples, p.vtheta_samples),
            timing,
            ox,
            oy,
            polygon,
            weights,
            scene.impossible,
            at,
            scene.plan,
            (self._escaping, p.heading_lookahead, self._spin.stuck_left, self._spin.stuck_right),
            (f.ox, f.oy, f.oyaw, math.cos(f.oyaw), math.sin(f.oyaw)),
        )
        if best >= 0:
            self._spin.update(pose, float(targets[best, 0]), float(targets[best, 1]))
        else:  # nothing valid: back off slowly, even into cost (ROS does), unless there is no path at all
            self._spin.moved(pose)
            if costs[-1] > -2.0 and not self._escaping:
                self._escaping, self._escape_pose = True, pose
        self._end_escape(pose)
        self.samples, self.costs, self._traj = targets, costs, traj
        if row < 0:
            self.valid = False
            return 0.0, 0.0
        self.local_plan = local
        return float(targets[row, 0]), float(targets[row, 1])

    def _constants(self, res: float) -> tuple[np.ndarray, np.ndarray, int]:
        """The cycle kernel's (timing, weights, scored step) at resolution ``res``: the same every cycle."""
        p = self.params
        key: tuple[Any, ...] = (res, p.sim_time, p.sim_granularity, p.angular_sim_granularity, p.heading_scoring)
        key += (p.heading_scoring_timestep, p.meter_scoring, p.pdist_scale, p.gdist_scale, p.occdist_scale)
        cached = self._consts
        if cached is None or cached[0] != key:
            ang = p.angular_sim_granularity if p.angular_sim_granularity > 0 else p.sim_granularity
            timing = np.array([p.sim_time, p.sim_granularity, ang, float(p.heading_scoring)])
            steps = max(1, int(p.sim_time / p.sim_granularity + 0.5)) if p.heading_scoring else 0
            at = self._heading_step(steps) if p.heading_scoring else -1
            cached = self._consts = (key, (timing, self._weights(res), at))
        return cached[1]

    def _footprint(
        self, scene: LocalScene
    ) -> tuple[np.ndarray, int, np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
        """The scoring kernels' footprint inputs: (the ring bound memo and the epoch of the scene's costs, the rings'
        offsets and counts (``ring_bounds``), the outline's x and y, whether the robot is a polygon); empty for a
        point robot."""
        res = scene.resolution
        outline = self._outline(res)
        if outline is None:
            none = np.zeros(0)
            return _NO_MEMO, 0, _NO_OFFSETS, _NO_COUNTS, none, none, False
        if res not in self._rings:
            xy = (np.ascontiguousarray(outline[:, 0]), np.ascontiguousarray(outline[:, 1]))
            self._rings[res] = (*ring_bounds.ring_offsets(outline, res), *xy)
        offsets, counts, ox, oy = self._rings[res]
        memo = self._memo
        if memo is None or memo[0] is not self._costs_seen or memo[1].shape[1:] != scene.cost.shape:
            # the bounds hold while the costs are the ones seen (the local costmap updates less often): new costs
            # take a new epoch, which forgets the memo's entries without clearing it
            if memo is None or memo[1].shape[1:] != scene.cost.shape or memo[2] >= ring_bounds.MAX_EPOCH:
                memo = (None, ring_bounds.new_memo(scene.cost.shape), 0)
            memo = self._memo = (self._costs_seen, memo[1], memo[2] + 1)
        return memo[1], memo[2], offsets, counts, ox, oy, True

    @staticmethod
    def _add_heading(scene: LocalScene, costs: np.ndarray, traj: np.ndarray, at: int) -> None:
        """With ``heading_scoring`` (scored step ``at`` >= 0): + 0.3 x headingDiff at that step to every valid cost,
        in place (ROS; not scaled by meter_scoring)."""
        if at >= 0:
            ok = costs >= 0
            plan = np.ascontiguousarray(scene.plan[:, :2])
            costs[ok] += 0.3 * heading_diffs(scene.cost, scene.resolution, plan, np.ascontiguousarray(traj[ok, at]))

    def _weights(self, res: float) -> np.ndarray:
        """The scoring kernel's (1, pdist, gdist, occdist) weights (m or cell units for the distances)."""
        p = self.params
        # meter_scoring scales all three biases by the resolution: what noetic scores with after start-up.
        # TrajectoryPlannerROS::initialize scales pdist and gdist alone, but its dynamic-reconfigure callback runs
        # once at start-up and TrajectoryPlanner::reconfigure re-reads the three biases from the parameters and
        # scales all three when its (never initialised) meter_scoring_ reads true, none when it reads false: the
        # same ratios either way, so the same choices (the heading_scoring term aside). Melodic's initialize
        # scaled all three too.
        scale = res if p.meter_scoring else 1.0
        return np.array([1.0, scale * p.pdist_scale, scale * p.gdist_scale, scale * p.occdist_scale])

    def _end_escape(self, pose: tuple[float, float, float]) -> None:
        """Leave escape mode once ``escape_reset_dist`` m or ``escape_reset_theta`` rad from where it began."""
        p = self.params
        moved = math.hypot(pose[0] - self._escape_pose[0], pose[1] - self._escape_pose[1])
        turned = abs(math.remainder(pose[2] - self._escape_pose[2], 2 * math.pi))
        if moved > p.escape_reset_dist or turned > p.escape_reset_theta:
            self._escaping = False
