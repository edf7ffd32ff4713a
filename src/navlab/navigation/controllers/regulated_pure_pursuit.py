"""Nav2's Regulated Pure Pursuit (``nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController``).

Macenski et al. 2023, "Regulated Pure Pursuit for Robot Path Tracking". Each cycle: the plan is cut to the
stretch ahead of the robot; the carrot is where a circle of the lookahead distance (fixed, or ``|v|`` x
``lookahead_time`` clamped to [``min_lookahead_dist``, ``max_lookahead_dist``]) leaves the path (interpolated),
or the path's end; the curvature to it is ``2 y / (x² + y²)`` in the robot frame. Far off its heading
(``rotate_to_heading_min_angle``) the robot first turns in place at ``rotate_to_heading_angular_vel``, limited
by ``max_angular_accel``; within the goal tolerance it turns to the goal's heading. Otherwise the speed is
``desired_linear_vel`` regulated down by the curvature (radius under ``regulated_linear_scaling_min_radius``)
and by the cost under the robot (obstacles nearer than ``cost_scaling_dist``, from the inflation's cost
through ``inflation_cost_scaling_factor``), not under ``regulated_linear_scaling_min_speed``, then slowed on
approach (the last ``approach_velocity_scaling_dist`` m of path, not under ``min_approach_linear_velocity``);
``w = v * curvature``. The arc is then projected for ``max_allowed_time_to_collision_up_to_carrot`` s (not
past the carrot) with the footprint: a collision ahead stops the robot and the cycle is invalid (Nav2 throws;
move_base then recovers). Nav2's names and defaults; one navlab addition, ``max_angular_vel`` (rad/s): a
sharper turn lowers ``v`` so that ``w`` stays within it on the same curvature. Units m, rad, s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from navlab.core import ParamSpec, read_params
from navlab.grid import COST_UNKNOWN, Grid
from navlab.navigation.controllers.common import (
    LocalFrame,
    Nav2PlanController,
    bad,
    cost_regulated_speeds,
    footprint_outline,
    inscribed_radius,
)
from navlab.navigation.controllers.rollout import footprint_costs
from navlab.navigation.errors import NavigationError

WHAT = "RegulatedPurePursuitController"
SPACING = 0.05  # m: plans are resampled to this
SEARCH_M = 5.0  # m of path ahead of the last nearest point searched for the robot's nearest point
_IGNORED = frozenset(
    {"plugin", "transform_tolerance", "use_sim_time", "max_robot_pose_search_dist", "use_interpolation"}
)


@dataclass
class RppParams:
    """nav2_regulated_pure_pursuit_controller's parameters (Nav2 names and defaults)."""

    PARAMS: ClassVar[ParamSpec] = ParamSpec(
        WHAT,
        NavigationError,
        ignored=_IGNORED,
        above={
            k: 0.0
            for k in (
                "desired_linear_vel",
                "lookahead_dist",
                "min_lookahead_dist",
                "max_lookahead_dist",
                "rotate_to_heading_angular_vel",
                "max_angular_accel",
                "controller_frequency",
                "max_angular_vel",
                "inflation_cost_scaling_factor",
            )
        },
    )
    desired_linear_vel: float = 0.5
    lookahead_dist: float = 0.6
    min_lookahead_dist: float = 0.3
    max_lookahead_dist: float = 0.9
    lookahead_time: float = 1.5
    rotate_to_heading_angular_vel: float = 1.8
    use_velocity_scaled_lookahead_dist: bool = False
    min_approach_linear_velocity: float = 0.05
    approach_velocity_scaling_dist: float = 0.6
    use_collision_detection: bool = True
    max_allowed_time_to_collision_up_to_carrot: float = 1.0
    use_regulated_linear_velocity_scaling: bool = True
    use_cost_regulated_linear_velocity_scaling: bool = True
    regulated_linear_scaling_min_radius: float = 0.9
    regulated_linear_scaling_min_speed: float = 0.25
    use_rotate_to_heading: bool = True
    rotate_to_heading_min_angle: float = 0.785
    max_angular_accel: float = 3.2
    allow_reversing: bool = False
    cost_scaling_dist: float = 0.6
    cost_scaling_gain: float = 1.0
    inflation_cost_scaling_factor: float = 3.0
    max_angular_vel: float = 2.5  # navlab: |w| cap (rad/s), reached by slowing down on the same arc
    controller_frequency: float = 20.0
    xy_goal_tolerance: float = 0.25
    yaw_goal_tolerance: float = 0.25
    stateful: bool = True

    def validate(self) -> None:
        """Refuse values Nav2 could not run with (one-line errors naming the key)."""
        if self.min_lookahead_dist > self.max_lookahead_dist:
            raise bad(
                WHAT,
                "min_lookahead_dist",
                self.min_lookahead_dist,
                f"<= max_lookahead_dist ({self.max_lookahead_dist})",
            )
        if self.allow_reversing:
            raise bad(WHAT, "allow_reversing", True, "false (navlab's RPP drives forward only)")


def carrot_on(path: np.ndarray, lookahead: float) -> np.ndarray:
    """The carrot (x, y) in the robot frame: where ``path`` (N, 2; robot frame, starting near the robot) first
    leaves the circle of radius ``lookahead`` (interpolated on that segment), or its last point."""
    d = np.hypot(path[:, 0], path[:, 1])
    out = np.nonzero(d >= lookahead)[0]
    if len(out) == 0:
        return path[-1].copy()
    k = int(out[0])
    if k == 0:
        return path[0].copy()
    a, b = path[k - 1], path[k]
    # solve |a + t (b - a)| = lookahead for t in [0, 1]
    ab = b - a
    qa, qb, qc = float(ab @ ab), 2.0 * float(a @ ab), float(a @ a) - lookahead * lookahead
    disc = max(qb * qb - 4 * qa * qc, 0.0)
    t = (-qb + math.sqrt(disc)) / (2 * qa) if qa > 0 else 0.0
    return a + min(max(t, 0.0), 1.0) * ab


class RegulatedPurePursuitController(Nav2PlanController):
    """``nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController`` (see the module docstring).

    ``params``: a Nav2 RPP parameter dict or ``RppParams``; ``footprint``: polygon [[x, y], ...] (m, base frame),
    else ``robot_radius`` (m); ``controller_frequency``: move_base's (Hz), used unless ``params`` sets it. ``rng``
    is accepted for a uniform constructor and not used. Its ``local_plan`` is the projected arc; ``valid`` is False
    when a collision is ahead.
    """

    what = WHAT
    spacing = SPACING

    def __init__(
        self,
        params: Mapping[str, Any] | RppParams | None = None,
        *,
        footprint: Any = None,
        robot_radius: float | None = None,
        controller_frequency: float | None = None,
        rng: np.random.Generator | None = None,
    ) -> None:
        values = dict(params) if isinstance(params, Mapping) else params
        if isinstance(values, dict) and controller_frequency is not None:
            values.setdefault("controller_frequency", controller_frequency)
        self.params = read_params(RppParams, values)
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64)
        footprint_outline(self.footprint, SPACING)  # validate now
        self.inscribed_radius = inscribed_radius(self.footprint, robot_radius)
        p = self.params
        self._cost_speeds = cost_regulated_speeds(
            p.desired_linear_vel,
            p.cost_scaling_dist,
            p.cost_scaling_gain,
            p.inflation_cost_scaling_factor,
            self.inscribed_radius,
            p.regulated_linear_scaling_min_speed,
        )  # m/s per costmap cost under the robot
        self._plan_state(p.xy_goal_tolerance, p.yaw_goal_tolerance, p.stateful)
        self.local_plan = np.zeros((0, 3))
        self.carrot: np.ndarray | None = None
        self.valid = True
        self.last_failure = ""

    def _command(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        self._check_call(self._plan, costmap, needs_costmap=False)
        p = self.params
        x, y, th = (float(v) for v in pose[:3])
        dt = 1.0 / p.controller_frequency
        w_now = float(velocity[1])
        self.valid, self.last_failure = True, ""
        ahead = self._ahead(x, y)
        c, s = math.cos(th), math.sin(th)
        rel = ahead - (x, y)
        robot = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]])
        v_now = float(velocity[0])
        lookahead = (
            min(max(abs(v_now) * p.lookahead_time, p.min_lookahead_dist), p.max_lookahead_dist)
            if p.use_velocity_scaled_lookahead_dist
            else p.lookahead_dist
        )
        carrot = carrot_on(robot, lookahead)
        self.carrot = np.array([x + c * carrot[0] - s * carrot[1], y + s * carrot[0] + c * carrot[1]])
        goal_dist = math.hypot(self._goal[0] - x, self._goal[1] - y)
        if p.use_rotate_to_heading and self._latch.xy_reached((x, y, th), self._goal):
            return self._rotate(self._latch.yaw_error((x, y, th), self._goal), w_now, dt, pose, costmap)
        angle = math.atan2(carrot[1], carrot[0])
        if p.use_rotate_to_heading and abs(angle) > p.rotate_to_heading_min_angle:
            return self._rotate(angle, w_now, dt, pose, costmap)
        d2 = float(carrot @ carrot)
        curvature = 2.0 * float(carrot[1]) / d2 if d2 > 1e-9 else 0.0
        v = self._regulated_speed(curvature, (x, y, th), costmap, _path_length(robot), goal_dist)
        w = v * curvature
        if abs(w) > p.max_angular_vel:
            v, w = v * p.max_angular_vel / abs(w), math.copysign(p.max_angular_vel, w)
        return self._checked(v, w, pose, costmap, math.sqrt(d2))

    # --- pieces ----------------------------------------------------------------------------------------

    def _ahead(self, x: float, y: float) -> np.ndarray:
        """The plan from the point nearest the robot (searched within ``SEARCH_M`` of path ahead of the last one)
        onwards (Nav2's ``max_robot_pose_search_dist``)."""
        assert self._plan is not None
        plan = self._plan[self._progress :]
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(plan, axis=0).T))])
        window = plan[: int(np.searchsorted(along, SEARCH_M)) + 1]
        self._progress += int(np.argmin(np.hypot(window[:, 0] - x, window[:, 1] - y)))
        return self._plan[self._progress :]

    def _rotate(
        self, angle: float, w_now: float, dt: float, pose: tuple[float, float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        """Turn in place toward ``angle`` (rad, robot frame) at ``rotate_to_heading_angular_vel``, within
        ``max_angular_accel`` of the current turn rate."""
        p = self.params
        if abs(angle) <= 1e-3:
            return self._checked(0.0, 0.0, pose, costmap, 0.0)
        # slow down into the heading as an acceleration-limited stop allows (Nav2's rotate-to-heading)
        target = math.copysign(
            min(p.rotate_to_heading_angular_vel, math.sqrt(2 * p.max_angular_accel * abs(angle))), angle
        )
        step = p.max_angular_accel * dt
        w = min(max(target, w_now - step), w_now + step)
        return self._checked(0.0, w, pose, costmap, 0.0)

    def _regulated_speed(
        self,
        curvature: float,
        pose: tuple[float, float, float],
        costmap: Grid | None,
        remaining: float,
        goal_dist: float,
    ) -> float:
        """``desired_linear_vel`` regulated by curvature, proximity to obstacles and the approach to the goal."""
        p = self.params
        v = p.desired_linear_vel
        curve_v = cost_v = v
        if p.use_regulated_linear_velocity_scaling and abs(curvature) > 1e-9:
            radius = 1.0 / abs(curvature)
            if radius < p.regulated_linear_scaling_min_radius:
                curve_v = v * radius / p.regulated_linear_scaling_min_radius
        if p.use_cost_regulated_linear_velocity_scaling and costmap is not None:
            cost_v = float(self._cost_speeds[int(costmap.value_at(np.array([pose[:2]]), outside=COST_UNKNOWN)[0])])
        if p.use_regulated_linear_velocity_scaling or p.use_cost_regulated_linear_velocity_scaling:
            v = max(min(curve_v, cost_v), p.regulated_linear_scaling_min_speed)
        left = min(remaining, goal_dist)
        if left < p.approach_velocity_scaling_dist:
            v = max(v * left / p.approach_velocity_scaling_dist, p.min_approach_linear_velocity)
        return min(v, p.desired_linear_vel)

    def _checked(
        self, v: float, w: float, pose: tuple[float, float, float], costmap: Grid | None, carrot_dist: float
    ) -> tuple[float, float]:
        """(v, w) after Nav2's ``isCollisionImminent``: the arc projected for
        ``max_allowed_time_to_collision_up_to_carrot`` s (not past the carrot) must stay off lethal cells."""
        p = self.params
        traj = self._project(v, w, pose, carrot_dist)
        self.local_plan = traj
        if not p.use_collision_detection or costmap is None or len(traj) == 0:
            return v, w
        frame = LocalFrame.of(costmap)
        local = np.column_stack([frame.points_in(traj[:, :2]), traj[:, 2] - frame.oyaw])
        outline = footprint_outline(self.footprint, costmap.resolution)
        costs = footprint_costs(np.asarray(costmap.data), costmap.resolution, local, outline)
        if np.any(costs < 0):
            self.valid = False
            self.last_failure = f"{WHAT} detected collision ahead!"
            return 0.0, 0.0
        return v, w

    def _project(self, v: float, w: float, pose: tuple[float, float, float], carrot_dist: float) -> np.ndarray:
        """Poses (K, 3) along the arc (v, w) from ``pose``, one per costmap-cell of travel (or per 0.05 rad of
        turn), for ``max_allowed_time_to_collision_up_to_carrot`` s and no farther than the carrot."""
        p = self.params
        horizon = p.max_allowed_time_to_collision_up_to_carrot
        if abs(v) > 1e-6:
            dt = SPACING / abs(v)
            horizon = min(horizon, carrot_dist / abs(v)) if carrot_dist > 0 else horizon
        elif abs(w) > 1e-6:
            dt = 0.05 / abs(w)
        else:
            return np.array([[pose[0], pose[1], pose[2]]], dtype=np.float64)
        n = max(1, math.ceil(horizon / dt))
        t = np.arange(1, n + 1) * min(dt, horizon)
        th = pose[2] + w * t
        if abs(w) > 1e-9:
            x = pose[0] + v / w * (np.sin(th) - math.sin(pose[2]))
            y = pose[1] - v / w * (np.cos(th) - math.cos(pose[2]))
        else:
            x = pose[0] + v * t * math.cos(pose[2])
            y = pose[1] + v * t * math.sin(pose[2])
        return np.column_stack([x, y, th])


def _path_length(path: np.ndarray) -> float:
    """Length (m) of a polyline (N, 2)."""
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
