"""The critics of Nav2's MPPI controller: each adds a cost (S,) to every sampled trajectory.

Names, parameters and defaults are Nav2's (``CostCritic.cost_weight`` ...); each critic's cost is
``(cost_weight * term) ** cost_power`` where the term is (a distance in m, an angle in rad, a cost):

- ``ConstraintCritic``: time outside [vx_min, vx_max] (s * m/s), a guard that is ~0 once samples are clipped;
  with the controller's cost-regulated speed limit on, also the speed above the limit under each point;
- ``CostCritic``: the costmap cost along the trajectory (every ``trajectory_point_step``-th point), with
  ``critical_cost`` at near-collision cells and ``collision_cost`` for a trajectory through LETHAL,
  INSCRIBED or unknown cells (``consider_footprint``: through a polygon footprint's edge cells); the
  weight is divided by 254, as Nav2 does, and the sum by the number of points;
- ``GoalCritic`` / ``GoalAngleCritic``: mean distance to the goal / |yaw - goal yaw|, within
  ``threshold_to_consider`` m of the goal;
- ``PathFollowCritic``: distance from the trajectory's end to the path point ``offset_from_furthest``
  beyond the furthest one any trajectory reached (or the first unblocked one after it);
  ``PathAlignCritic``: mean distance from trajectory points to the path point at the same arc length
  (skipped when more than ``max_path_occupancy_ratio`` of the path is blocked); ``PathAngleCritic``:
  when the robot faces more than ``max_angle_to_furthest`` away from that path point, the mean angle
  between heading and direction to it; all three apply only farther than ``threshold_to_consider`` m
  from the goal;
- ``PreferForwardCritic``: time spent reversing (s * m/s); ``TwirlingCritic``: mean |wz|.

The batch is in grid-local coordinates (see ``common``): positions m, yaw rad, controls m/s and rad/s.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from navlab.core import ParamSpec
from navlab.grid import COST_INSCRIBED, COST_LETHAL
from navlab.navigation.controllers.rollout import footprint_costs
from navlab.navigation.errors import NavigationError


@dataclass
class Critic:
    """What every critic reads: ``enabled``, and its cost ``(cost_weight * term) ** cost_power``."""

    enabled: bool = True
    cost_weight: float = 1.0
    cost_power: int = 1


@dataclass
class NearCritic(Critic):
    """A critic that applies only nearer to (or farther from) the goal than ``threshold_to_consider`` m."""

    threshold_to_consider: float = 0.5


@dataclass
class ConstraintCritic(Critic):
    cost_weight: float = 4.0


@dataclass
class CostCritic(Critic):
    cost_weight: float = 3.81
    consider_footprint: bool = False
    critical_cost: float = 300.0
    collision_cost: float = 1000000.0
    near_collision_cost: int = 253
    near_goal_distance: float = 0.5
    trajectory_point_step: int = 2
    inflation_layer_name: str = ""


@dataclass
class GoalCritic(NearCritic):
    cost_weight: float = 5.0
    threshold_to_consider: float = 1.4


@dataclass
class GoalAngleCritic(NearCritic):
    cost_weight: float = 3.0


@dataclass
class PathAlignCritic(NearCritic):
    cost_weight: float = 10.0
    offset_from_furthest: int = 20
    trajectory_point_step: int = 4
    max_path_occupancy_ratio: float = 0.07
    use_path_orientations: bool = False


@dataclass
class PathFollowCritic(NearCritic):
    cost_weight: float = 5.0
    threshold_to_consider: float = 1.4
    offset_from_furthest: int = 6


@dataclass
class PathAngleCritic(NearCritic):
    cost_weight: float = 2.2
    offset_from_furthest: int = 4
    max_angle_to_furthest: float = 0.785398
    mode: int = 0


@dataclass
class PreferForwardCritic(NearCritic):
    cost_weight: float = 5.0


@dataclass
class TwirlingCritic(Critic):
    cost_weight: float = 10.0


CRITICS: dict[str, type] = {
    c.__name__: c
    for c in (
        ConstraintCritic,
        CostCritic,
        GoalCritic,
        GoalAngleCritic,
        PathAlignCritic,
        PathFollowCritic,
        PathAngleCritic,
        PreferForwardCritic,
        TwirlingCritic,
    )
}
for _name, _cls in CRITICS.items():  # each critic's section is read as "MPPIController <critic>"
    _cls.PARAMS = ParamSpec(f"MPPIController {_name}", NavigationError)  # type: ignore[attr-defined]


@dataclass
class Batch:
    """One optimisation's sampled trajectories and what the critics need (grid-local frame)."""

    x: np.ndarray  # (S, T) m
    y: np.ndarray
    yaw: np.ndarray  # (S, T) rad
    vx: np.ndarray  # (S, T) m/s, the controls actually applied
    wz: np.ndarray  # (S, T) rad/s
    cost: np.ndarray  # (S, T) uint8 costmap cost under each point (255 off the map)
    arc: np.ndarray  # (S, T) m travelled from the robot to each point
    pose: tuple[float, float, float]
    path: np.ndarray  # (P, 2) the pruned plan ahead of the robot
    goal: tuple[float, float, float | None]
    dist_to_goal: float  # m, robot to goal
    dt: float  # model_dt, s
    vx_limits: tuple[float, float]
    grid: np.ndarray  # the local costmap (uint8)
    resolution: float
    outline: np.ndarray | None = None  # polygon footprint edge points (base frame) or None
    vx_cap: np.ndarray | None = None  # (S, T) m/s, the cost-regulated speed limit under each point, or None
    _furthest: int | None = field(default=None, repr=False)

    @property
    def furthest(self) -> int:
        """Index of the furthest path point that any trajectory's end is nearest to (Nav2's
        ``furthest_reached_path_point``)."""
        if self._furthest is None:
            if len(self.path) == 0:
                self._furthest = 0
            else:
                dx = self.x[:, -1:] - self.path[None, :, 0]
                dy = self.y[:, -1:] - self.path[None, :, 1]
                self._furthest = int(np.argmin(dx * dx + dy * dy, axis=1).max())
        return self._furthest

    @property
    def path_valid(self) -> np.ndarray:
        """Mask (P,) of the path points on cells the robot may occupy (cost < INSCRIBED, inside the map)."""
        ij = np.floor(self.path / self.resolution).astype(np.intp)
        h, w = self.grid.shape
        inside = (ij[:, 0] >= 0) & (ij[:, 0] < w) & (ij[:, 1] >= 0) & (ij[:, 1] < h)
        ok = np.zeros(len(self.path), dtype=bool)
        ok[inside] = self.grid[ij[inside, 1], ij[inside, 0]] < COST_INSCRIBED
        return ok

    def target(self, offset: int) -> np.ndarray:
        """The path point ``offset`` beyond the furthest reached one, moved on past blocked points (Nav2: "drive
        to the first valid path point, in case of dynamic obstacles on the path")."""
        k = min(self.furthest + offset, len(self.path) - 1)
        valid = self.path_valid
        ahead = np.nonzero(valid[k:])[0]
        return self.path[k + int(ahead[0])] if len(ahead) else self.path[-1]


def _out(c: Critic, term: np.ndarray) -> np.ndarray:
    val = c.cost_weight * term
    return val if c.cost_power == 1 else val**c.cost_power


def constraint(c: ConstraintCritic, b: Batch) -> np.ndarray | None:
    lo, hi = b.vx_limits
    if b.vx_cap is not None:
        over = np.maximum(b.vx - np.minimum(b.vx_cap, hi), 0.0) + np.maximum(lo - b.vx, 0.0)
        return _out(c, over.sum(axis=1) * b.dt)
    if b.vx.max() <= hi and b.vx.min() >= lo:
        return None
    over = np.maximum(b.vx - hi, 0.0) + np.maximum(lo - b.vx, 0.0)
    return _out(c, over.sum(axis=1) * b.dt)


def cost(c: CostCritic, b: Batch) -> np.ndarray | None:
    pts = b.cost[:, :: max(1, c.trajectory_point_step)]
    if c.consider_footprint and b.outline is not None:
        hit = pts >= COST_LETHAL
        check = (pts > 0) & ~hit  # only cells near obstacles can put an edge on one
        if check.any():
            step = max(1, c.trajectory_point_step)
            poses = np.stack([b.x[:, ::step][check], b.y[:, ::step][check], b.yaw[:, ::step][check]], axis=1)
            hit[check] = footprint_costs(b.grid, b.resolution, poses, b.outline) < 0
    else:
        hit = pts >= COST_INSCRIBED
    collide = hit.any(axis=1)
    vals = pts.astype(np.float64)
    critical = vals >= c.near_collision_cost
    if b.dist_to_goal < c.near_goal_distance:
        vals[:] = 0.0
    vals[critical] = c.critical_cost
    total = np.where(collide, c.collision_cost, vals.sum(axis=1))
    return _out(c, total / (254.0 * pts.shape[1]))


def goal(c: GoalCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal > c.threshold_to_consider:
        return None
    return _out(c, np.hypot(b.x - b.goal[0], b.y - b.goal[1]).mean(axis=1))


def goal_angle(c: GoalAngleCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal > c.threshold_to_consider or b.goal[2] is None:
        return None
    err = np.abs((b.yaw - b.goal[2] + np.pi) % (2 * np.pi) - np.pi)
    return _out(c, err.mean(axis=1))


def path_follow(c: PathFollowCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal < c.threshold_to_consider or len(b.path) < 2:
        return None
    target = b.target(c.offset_from_furthest)
    return _out(c, np.hypot(b.x[:, -1] - target[0], b.y[:, -1] - target[1]))


def path_align(c: PathAlignCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal < c.threshold_to_consider or len(b.path) < 2 or b.furthest < c.offset_from_furthest:
        return None
    reach = b.path[: b.furthest + 1]
    if 1.0 - b.path_valid[: b.furthest + 1].mean() > c.max_path_occupancy_ratio:
        return None  # an obstacle blocks the path: let the other critics find the way round
    seg = np.hypot(*np.diff(reach, axis=0).T)
    path_s = np.concatenate([[0.0], np.cumsum(seg)])
    step = max(1, c.trajectory_point_step)
    traj_s = b.arc[:, step - 1 :: step]
    idx = np.clip(np.searchsorted(path_s, traj_s), 0, len(reach) - 1)
    px, py = reach[idx, 0], reach[idx, 1]
    return _out(c, np.hypot(b.x[:, step - 1 :: step] - px, b.y[:, step - 1 :: step] - py).mean(axis=1))


def path_angle(c: PathAngleCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal < c.threshold_to_consider or len(b.path) < 2:
        return None
    tx, ty = b.target(c.offset_from_furthest)
    facing = np.arctan2(ty - b.pose[1], tx - b.pose[0]) - b.pose[2]
    if abs((facing + np.pi) % (2 * np.pi) - np.pi) < c.max_angle_to_furthest:
        return None
    err = np.abs((np.arctan2(ty - b.y, tx - b.x) - b.yaw + np.pi) % (2 * np.pi) - np.pi)
    return _out(c, err.mean(axis=1))


def prefer_forward(c: PreferForwardCritic, b: Batch) -> np.ndarray | None:
    if b.dist_to_goal < c.threshold_to_consider:
        return None
    return _out(c, np.maximum(-b.vx, 0.0).sum(axis=1) * b.dt)


def twirling(c: TwirlingCritic, b: Batch) -> np.ndarray | None:
    return _out(c, np.abs(b.wz).mean(axis=1))


Scorer = Callable[[Any, Batch], np.ndarray | None]  # (a critic's parameters, batch) -> costs (S,) or None
SCORERS: dict[str, Scorer] = {
    "ConstraintCritic": constraint,
    "CostCritic": cost,
    "GoalCritic": goal,
    "GoalAngleCritic": goal_angle,
    "PathAlignCritic": path_align,
    "PathFollowCritic": path_follow,
    "PathAngleCritic": path_angle,
    "PreferForwardCritic": prefer_forward,
    "TwirlingCritic": twirling,
}
