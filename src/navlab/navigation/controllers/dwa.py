"""dwa_local_planner/DWAPlannerROS: the dynamic window approach of ROS 1 (see ``rollout_controller`` for the
shared rollout, distance maps and goal handling, and the cost it minimises)."""

from __future__ import annotations

import math

import numpy as np

from navlab.navigation.controllers import mapgrid
from navlab.navigation.controllers.params import DWAPlannerParams
from navlab.navigation.controllers.rollout import footprint_costs, lookup, velocity_samples
from navlab.navigation.controllers.rollout_controller import LocalScene, RolloutController

_EPS = 1e-4


class DWAPlannerROS(RolloutController):
    """dwa_local_planner's DWAPlanner behind the Controller protocol (``params``: a DWAPlannerROS parameter dict,
    ROS 1 names, or ``DWAPlannerParams``; the other arguments as ``RolloutController``'s)."""

    what = "DWAPlannerROS"
    params_class = DWAPlannerParams
    params: DWAPlannerParams

    def _setup(self) -> None:
        self._stopped_vel = (self.params.trans_stopped_vel, self.params.theta_stopped_vel)
        self._accelerate = not self.params.use_dwa

    def _in_place_limits(self, err: float) -> tuple[float, float]:
        return self.params.max_vel_theta, self.params.min_vel_theta

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float]) -> bool:
        """Within the xy (possibly latched) and yaw tolerances and stopped (trans/theta_stopped_vel)."""
        v = (float(velocity[0]), float(velocity[1]))
        return (
            super().is_goal_reached(pose, velocity)
            and abs(v[0]) <= self.params.trans_stopped_vel
            and abs(v[1]) <= self.params.theta_stopped_vel
        )

    def window(self, velocity: tuple[float, float], dist_to_goal: float) -> np.ndarray:
        """The (v, w) samples (S, 2) of one cycle: the dynamic window around ``velocity``, sampled as
        ROS's VelocityIterator does, minus the pairs too slow to move (min_vel_trans and min_vel_theta)
        or too fast (max_vel_trans)."""
        p = self.params
        v0, w0 = velocity
        if p.use_dwa:
            horizon, vmax_x = p.sim_period, p.max_vel_x
        else:  # never plan to overshoot the goal within sim_time
            horizon, vmax_x = p.sim_time, max(min(p.max_vel_x, dist_to_goal / p.sim_time), p.min_vel_x)
        vhi = min(vmax_x, v0 + p.acc_lim_x * horizon)
        vlo = min(max(p.min_vel_x, v0 - p.acc_lim_x * horizon), vhi)
        whi = min(p.max_vel_theta, w0 + p.acc_lim_theta * horizon)
        wlo = min(max(-p.max_vel_theta, w0 - p.acc_lim_theta * horizon), whi)
        vs, ws = velocity_samples(vlo, vhi, p.vx_samples), velocity_samples(wlo, whi, p.vth_samples)
        pairs = np.stack([np.repeat(vs, len(ws)), np.tile(ws, len(vs))], axis=1)
        speed, turn = np.abs(pairs[:, 0]), np.abs(pairs[:, 1])
        keep = ~(
            ((speed + _EPS < p.min_vel_trans) & (turn + _EPS < p.min_vel_theta))
            | (speed - _EPS > p.max_vel_trans)
            | ((speed < _EPS) & (turn < _EPS))
        )
        return pairs[keep]

    def _front_goal_dist(self, scene: LocalScene) -> np.ndarray:
        """Distances to the local goal pushed ``forward_point_distance`` beyond itself, away from the robot
        (dwa_local_planner's ``goal_front_costs``: the plan with its last pose moved, whose last cell in the
        costmap seeds the wave); the local goal's cell if that plan leaves no cell."""
        x, y, _ = scene.pose
        g = scene.local_goal()
        a = math.atan2(g[1] - y, g[0] - x)
        front = scene.plan.copy()
        front[-1] = g + self.params.forward_point_distance * np.array([math.cos(a), math.sin(a)])
        cells = mapgrid.plan_cells(scene.cost, front, scene.resolution)
        seed = cells[-1] if len(cells) else scene.path_cells[-1]
        return mapgrid.distance_map(scene.cost, seed[None, :])

    def _steps(self, targets: np.ndarray) -> np.ndarray:
        """``SimpleTrajectoryGenerator``: ceil(max(|v| sim_time / sim_granularity, |w| sim_time /
        angular_sim_granularity)), at least 1."""
        p = self.params
        need = p.sim_time * np.maximum(
            np.abs(targets[:, 0]) / p.sim_granularity, np.abs(targets[:, 1]) / p.angular_sim_granularity
        )
        return np.maximum(1, np.ceil(need - 1e-9)).astype(np.int64)

    def _check(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        self._osc.reset()  # ROS's DWAPlanner::checkTrajectory resets the oscillation flags first
        return self.score(scene, targets, traj)

    def score(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        """Costs (S,) of the rollouts; -1 for a rejected one (blocked, off the map, no path, oscillating)."""
        p = self.params
        res = scene.resolution
        pdist, gdist = res * p.path_distance_bias, res * p.goal_distance_bias
        g = scene.local_goal()
        sq_dist = (scene.pose[0] - g[0]) ** 2 + (scene.pose[1] - g[1]) ** 2
        near = sq_dist <= p.forward_point_distance**2 * p.cheat_factor
        align = 0.0 if near else pdist
        total = np.zeros(len(targets))
        rejected = ~self._osc.allowed(targets[:, 0], targets[:, 1])
        if p.occdist_scale > 0:
            outline, near = self._outline(res), self._near_max(scene)
            fp = footprint_costs(scene.cost, res, traj, outline, near_max=near, with_centre=True)
            rejected |= (fp < 0).any(axis=1)
            total += p.occdist_scale * fp.max(axis=1)
        # the nose: every pose moved forward_point_distance ahead (MapGrid critics with an x shift read the
        # last one, and reject a rollout any of whose shifted poses is off the map)
        nx = traj[..., 0] + p.forward_point_distance * np.cos(traj[..., 2])
        ny = traj[..., 1] + p.forward_point_distance * np.sin(traj[..., 2])
        if gdist > 0:
            d, inside = lookup(self._front_goal_dist(scene), res, nx, ny)
            rejected |= ~inside.all(axis=1)
            total += gdist * d[:, -1]
        if align > 0:
            d, inside = lookup(scene.path_dist, res, nx, ny)
            rejected |= ~inside.all(axis=1)
            total += align * d[:, -1]
        for scale, grid in ((pdist, scene.path_dist), (gdist, scene.goal_dist)):
            if scale > 0:  # stop on failure: any pose with no path to the plan or goal rejects the rollout
                d, inside = lookup(grid, res, traj[..., 0], traj[..., 1])
                rejected |= (~inside | (d >= scene.impossible)).any(axis=1)
                total += scale * d[:, -1]
        if p.twirling_scale > 0:
            total += p.twirling_scale * np.abs(targets[:, 1])
        total[rejected] = -1.0
        return total

    def _drive(
        self, scene: LocalScene, pose: tuple[float, float, float], velocity: tuple[float, float]
    ) -> tuple[float, float]:
        p = self.params
        g = scene.local_goal()
        targets = self.window(velocity, math.hypot(g[0] - scene.pose[0], g[1] - scene.pose[1]))
        if len(targets) == 0:
            return self._finish(scene, targets, np.zeros((0, 0, 3)), np.zeros(0), -1, pose)
        steps = self._steps(targets)
        traj = self._rollout(scene, velocity, targets, steps)
        if not p.use_dwa:  # continued acceleration: ROS commands the velocity reached after the first step
            dt = (p.sim_time / steps)[:, None]
            now = np.array(velocity)
            acc = np.array([p.acc_lim_x, p.acc_lim_theta])
            targets = np.clip(targets, now - acc * dt, now + acc * dt)
        costs = self.score(scene, targets, traj)
        ok = costs >= 0
        best = int(np.argmin(np.where(ok, costs, np.inf))) if ok.any() else -1
        if best >= 0:
            self._osc.update(pose, float(targets[best, 0]), float(targets[best, 1]), p.min_vel_trans)
        return self._finish(scene, targets, traj, costs, best, pose)


class DWBLocalPlanner(DWAPlannerROS):
    """Nav2's DWB name for the same planner; it reads DWAPlannerROS's (ROS 1) parameter names."""

    what = "DWBLocalPlanner"
