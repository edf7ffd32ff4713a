"""Pieces the local controllers share: parameter spellings, plan checks, grid-local frames, goal and
oscillation logic of base_local_planner (``LatchedStopRotateController``, ``OscillationCostFunction``).

Frames: poses ``(x, y, yaw)`` and plans are in the costmap's frame (``odom`` for a rolling local
costmap). Internally the controllers work in *grid-local* coordinates: the costmap frame moved to the
grid's origin and turned by its yaw, so cell ``(i, j)`` holds ``floor(p / resolution)``. Units: m, rad,
m/s, rad/s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Self

import numba
import numpy as np

from navlab.core import param_error
from navlab.geometry import wrap_angle
from navlab.grid import Grid
from navlab.navigation.errors import NavigationError
from navlab.plugins import ControlResult, PluginContext


def bad(what: str, key: str, value: Any, expected: str) -> NavigationError:
    """The one-line error for a parameter ``key`` = ``value`` that is not ``expected``."""
    return param_error(what, key, value, expected, NavigationError)  # type: ignore[return-value]


def as_plan(path: Any) -> np.ndarray:
    """A global plan as float array (N, 2) or (N, 3), checked (N >= 1, finite values)."""
    arr = np.asarray(path, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] not in (2, 3) or len(arr) == 0:
        raise NavigationError(f"plan: expected an array (N, 2) or (N, 3) with N >= 1, got shape {arr.shape}")
    arr = arr.copy()  # C-contiguous
    if not all_finite(arr.reshape(-1)):
        raise NavigationError("plan: expected finite coordinates, got NaN or inf")
    return arr


@numba.njit(cache=True)
def all_finite(values: np.ndarray) -> bool:  # pragma: no cover - compiled
    """Whether every value of the 1-D float array is finite (``np.all(np.isfinite(...))`` in one pass)."""
    for v in values:  # noqa: SIM110 - a compiled loop that stops at the first (Numba has no all() of a generator)
        if not math.isfinite(v):
            return False
    return True


@numba.njit(cache=True)
def same_values(a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover - compiled
    """Whether two 1-D arrays of one length hold the same values (``np.array_equal`` without its temporaries)."""
    for k in range(a.size):  # noqa: SIM110 - as all_finite
        if a[k] != b[k]:
            return False
    return True


def densify(xy: np.ndarray, step: float) -> np.ndarray:
    """Points (M, 2) along the polyline ``xy`` (N, 2) no more than ``step`` m apart (ends kept).

    base_local_planner's ``adjustPlanResolution``: a plan whose poses skip cells still marks every cell.
    """
    if len(xy) < 2:
        return xy.copy()
    seg = np.diff(xy, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / step).astype(np.int64))
    idx = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    return np.vstack([xy[idx] + seg[idx] * frac[:, None], xy[-1:]])


@dataclass(frozen=True)
class LocalFrame:
    """Grid-local coordinates of a costmap: origin at the grid's corner, axes along its rows/columns."""

    ox: float
    oy: float
    oyaw: float

    @classmethod
    def of(cls, grid: Grid) -> LocalFrame:
        """The grid-local frame of ``grid``."""
        return cls(*grid.origin)

    def points_in(self, xy: np.ndarray) -> np.ndarray:
        """Costmap-frame points (N, 2) -> grid-local (N, 2)."""
        d = np.asarray(xy, dtype=np.float64)[:, :2] - (self.ox, self.oy)
        if self.oyaw == 0.0:
            return d
        c, s = math.cos(self.oyaw), math.sin(self.oyaw)
        return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)

    def pose_in(self, pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """A costmap-frame pose -> grid-local (``points_in``'s arithmetic on one point)."""
        dx, dy = float(pose[0]) - self.ox, float(pose[1]) - self.oy
        if self.oyaw != 0.0:
            c, s = math.cos(self.oyaw), math.sin(self.oyaw)
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        return dx, dy, float(pose[2]) - self.oyaw

    def poses_out(self, poses: np.ndarray) -> np.ndarray:
        """Grid-local poses (N, 3) -> costmap frame (N, 3), yaw wrapped to [-pi, pi)."""
        out = np.array(poses, dtype=np.float64, copy=True).reshape(-1, 3)
        c, s = math.cos(self.oyaw), math.sin(self.oyaw)
        x, y = out[:, 0].copy(), out[:, 1].copy()
        out[:, 0] = self.ox + c * x - s * y
        out[:, 1] = self.oy + s * x + c * y
        out[:, 2] = wrap_angle(out[:, 2] + self.oyaw)
        return out


def footprint_outline(footprint: Any, resolution: float) -> np.ndarray | None:
    """Points (M, 2) along the edges of a polygon footprint (base frame, m), at most resolution/2 apart;
    None for a circular robot (no polygon, or fewer than 3 vertices: costmap_2d's rule)."""
    if footprint is None:
        return None
    poly = np.asarray(footprint, dtype=np.float64)
    if poly.ndim != 2 or poly.shape[1] != 2 or not np.all(np.isfinite(poly)):
        raise NavigationError(f"footprint: expected a polygon [[x, y], ...] in metres, got {footprint!r}")
    if len(poly) < 3:
        return None
    closed = np.vstack([poly, poly[:1]])
    return densify(closed, 0.5 * resolution)[:-1]


def goal_of(plan: np.ndarray) -> tuple[float, float, float | None]:
    """The goal (x, y, yaw or None) of a plan: its last pose; an (N, 2) plan has no goal yaw."""
    last = plan[-1]
    return float(last[0]), float(last[1]), (float(last[2]) if plan.shape[1] == 3 else None)


def same_goal(
    old: tuple[float, float, float | None] | None,
    new: tuple[float, float, float | None],
    xy_tolerance: float,
    yaw_tolerance: float,
) -> bool:
    """Whether a new plan leads to the same goal as before (within the goal tolerances): a plan re-sent
    every cycle, or replanned to the same goal, keeps the goal latch and the oscillation flags."""
    if old is None or math.hypot(new[0] - old[0], new[1] - old[1]) > xy_tolerance:
        return False
    if (old[2] is None) != (new[2] is None):
        return False
    return old[2] is None or new[2] is None or abs(float(wrap_angle(new[2] - old[2]))) <= yaw_tolerance


def prune_plan(plan: np.ndarray, x: float, y: float) -> np.ndarray:
    """Drop the poses before the first one within 1 m of (x, y) (base_local_planner's ``prunePlan``).

    A plan with no pose within 1 m is kept whole (ROS would empty it)."""
    first = _first_near(plan, x, y, 1.0)
    return plan[first:] if first >= 0 else plan


@numba.njit(cache=True)
def _first_near(plan: np.ndarray, x: float, y: float, distance: float) -> int:  # pragma: no cover - compiled
    """Index of the first pose of ``plan`` closer than ``distance`` m to (x, y) (``math.hypot``), -1 if none."""
    for k in range(plan.shape[0]):
        if math.hypot(plan[k, 0] - x, plan[k, 1] - y) < distance:
            return k
    return -1


@numba.njit(cache=True)
def crop_span(plan: np.ndarray, x: float, y: float, radius: float) -> tuple[int, int]:  # pragma: no cover
    """(first, end) of ``crop_plan``'s stretch; (0, 0) when no pose lies within ``radius`` m."""
    r2 = radius * radius
    first = -1
    for k in range(plan.shape[0]):
        dx, dy = plan[k, 0] - x, plan[k, 1] - y
        if dx * dx + dy * dy <= r2:
            if first < 0:
                first = k
        elif first >= 0:
            return first, k + 1
    return (first, plan.shape[0]) if first >= 0 else (0, 0)


def crop_plan(plan: np.ndarray, x: float, y: float, radius: float) -> np.ndarray:
    """The stretch of ``plan`` around (x, y) that base_local_planner's ``transformGlobalPlan`` hands on: from
    the first pose within ``radius`` m (half the local costmap's larger side) up to the first pose beyond it
    again, that one included (ROS's loop keeps it). Empty when no pose is that close (ROS: an empty
    transformed plan, no command)."""
    first, end = crop_span(plan, x, y, radius)
    return plan[first:end]


def circle_footprint(radius: float) -> np.ndarray:
    """The polygon (16, 2) costmap_2d makes from ``robot_radius`` (``makeFootprintFromRadius``: 16 vertices on
    the circle, base frame, m): what base_local_planner and dwa_local_planner check a round robot with."""
    if not (math.isfinite(radius) and radius > 0):
        raise NavigationError(f"robot_radius: expected a positive number (m), got {radius!r}")
    a = np.arange(16) * (2.0 * math.pi / 16)
    return np.column_stack([radius * np.cos(a), radius * np.sin(a)])


def stopped(velocity: tuple[float, float], trans_stopped_vel: float, theta_stopped_vel: float) -> bool:
    """base_local_planner's ``stopped``: |v| and |w| under the thresholds (m/s, rad/s)."""
    return abs(velocity[0]) <= trans_stopped_vel and abs(velocity[1]) <= theta_stopped_vel


def stop_with_acc_limits(
    velocity: tuple[float, float], acc_x: float, acc_theta: float, sim_period: float
) -> tuple[float, float]:
    """The command that slows (v, w) towards zero as fast as the acceleration limits allow in one period."""
    v, w = velocity
    v_new = math.copysign(max(0.0, abs(v) - acc_x * sim_period), v)
    w_new = math.copysign(max(0.0, abs(w) - acc_theta * sim_period), w)
    return v_new, w_new


def rotate_to_goal(
    yaw_error: float, w_now: float, *, max_w: float, min_in_place_w: float, acc_theta: float, sim_period: float
) -> float:
    """The in-place turn rate (rad/s) towards a goal ``yaw_error`` (rad, goal - robot, wrapped) away.

    As base_local_planner's ``rotateToGoal``: at least ``min_in_place_w``, at most ``max_w``, within reach
    of ``w_now`` in one ``sim_period``, slow enough to stop at the goal (sqrt(2 a |err|)); the minimum
    wins over the acceleration limits.
    """
    w = min(max_w, max(min_in_place_w, abs(yaw_error)))
    w = min(max(w, abs(w_now) - acc_theta * sim_period), abs(w_now) + acc_theta * sim_period)
    w = min(w, math.sqrt(2.0 * acc_theta * abs(yaw_error)))
    w = min(max_w, max(min_in_place_w, w))
    return w if yaw_error >= 0.0 else -w


class GoalLatch:
    """xy/yaw goal tolerances with ``latch_xy_goal_tolerance``: once within xy tolerance, stay "arrived"
    (only rotate) until a new plan, if latching is on."""

    def __init__(self, xy_tolerance: float, yaw_tolerance: float, latch: bool) -> None:
        self.xy_tolerance = xy_tolerance
        self.yaw_tolerance = yaw_tolerance
        self.latch = latch
        self.latched = False

    def reset(self) -> None:
        """Forget the latch (a new plan)."""
        self.latched = False

    def xy_reached(self, pose: tuple[float, float, float], goal: tuple[float, float, float | None]) -> bool:
        """Within ``xy_goal_tolerance`` of the goal now, or latched; sets the latch if latching is on."""
        if self.latched:
            return True
        inside = math.hypot(pose[0] - goal[0], pose[1] - goal[1]) <= self.xy_tolerance
        if inside and self.latch:
            self.latched = True
        return inside

    def yaw_error(self, pose: tuple[float, float, float], goal: tuple[float, float, float | None]) -> float:
        """Goal yaw minus robot yaw (rad, wrapped); 0 when the plan has no goal yaw."""
        return 0.0 if goal[2] is None else float(wrap_angle(goal[2] - pose[2]))

    def reached(self, pose: tuple[float, float, float], goal: tuple[float, float, float | None]) -> bool:
        """Both tolerances met (the xy one possibly latched)."""
        return self.xy_reached(pose, goal) and abs(self.yaw_error(pose, goal)) <= self.yaw_tolerance


class OscillationFlags:
    """base_local_planner's oscillation suppression (``OscillationCostFunction``).

    After the chosen command turns one way and then the other while not translating (|v| <=
    ``min_vel_trans``), or drives forward after backward (or back after forward), commands in the old
    direction are forbidden until the robot moved ``reset_dist`` m (or turned ``reset_angle`` rad, if
    that is >= 0) from where the flag was set.
    """

    def __init__(self, reset_dist: float, reset_angle: float = -1.0) -> None:
        self.reset_dist = reset_dist
        self.reset_angle = reset_angle
        self.reset()
        self._where = (0.0, 0.0, 0.0)

    def reset(self) -> None:
        """Clear every flag."""
        self.forward_pos = self.forward_neg = self.rot_pos = self.rot_neg = False
        self.forward_pos_only = self.forward_neg_only = self.rot_pos_only = self.rot_neg_only = False

    def allowed(self, v: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Mask of the (v, w) samples the flags allow."""
        ok = np.ones(np.shape(v), dtype=bool)
        if self.forward_pos_only:
            ok &= v >= 0.0
        if self.forward_neg_only:
            ok &= v <= 0.0
        if self.rot_pos_only:
            ok &= w >= 0.0
        if self.rot_neg_only:
            ok &= w <= 0.0
        return ok

    def _set(self, v: float, w: float, min_vel_trans: float) -> bool:
        flag_set = False
        if v < 0.0:
            flag_set |= self.forward_pos
            self.forward_neg_only |= self.forward_pos
            self.forward_pos, self.forward_neg = False, True
        if v > 0.0:
            flag_set |= self.forward_neg
            self.forward_pos_only |= self.forward_neg
            self.forward_neg, self.forward_pos = False, True
        if abs(v) <= min_vel_trans:
            if w < 0.0:
                flag_set |= self.rot_pos
                self.rot_neg_only |= self.rot_pos
                self.rot_pos, self.rot_neg = False, True
            if w > 0.0:
                flag_set |= self.rot_neg
                self.rot_pos_only |= self.rot_neg
                self.rot_neg, self.rot_pos = False, True
        return flag_set

    def update(self, pose: tuple[float, float, float], v: float, w: float, min_vel_trans: float) -> None:
        """Record the command (v, w) chosen at ``pose``; clear the flags once moved far enough."""
        if self._set(v, w, min_vel_trans):
            self._where = pose
        if self.forward_pos_only or self.forward_neg_only or self.rot_pos_only or self.rot_neg_only:
            moved = math.hypot(pose[0] - self._where[0], pose[1] - self._where[1])
            turned = abs(float(wrap_angle(pose[2] - self._where[2])))
            if moved > self.reset_dist or (self.reset_angle >= 0.0 and turned > self.reset_angle):
                self.reset()


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


class ControllerBase:
    """What the local controllers share behind ``plugins.Controller``: :meth:`compute_velocity` runs the
    controller's ``_command`` and returns its (v, w) with ``valid`` and ``local_plan``; :meth:`from_params` builds
    it from its parameter namespace and the host's context."""

    what = ""
    valid: bool
    local_plan: np.ndarray

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """From the controller's parameter namespace, move_base's ``controller_frequency``, the host's seeded
        ``rng`` and the local costmap's footprint (its polygon, else a round robot's radius)."""
        fp = context.footprint
        return cls(  # type: ignore[call-arg]
            params,
            footprint=None if fp is None else fp.polygon,
            robot_radius=None if fp is None else fp.radius,
            controller_frequency=context.controller_frequency,
            rng=context.rng,
        )

    def compute_velocity(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> ControlResult:
        """The command (v m/s, w rad/s) for the robot at ``pose`` (costmap frame) moving at ``velocity`` (v, w),
        with ``valid`` and the controller's ``local_plan`` (costmap frame)."""
        v, w = self._command(pose, velocity, costmap)
        return ControlResult(v, w, self.valid, self.local_plan)

    def _command(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        raise NotImplementedError

    def _check_call(self, plan: np.ndarray | None, costmap: Grid | None, *, needs_costmap: bool = True) -> None:
        """Refuse a cycle before ``set_plan`` (and, if the controller needs one, without a local costmap)."""
        if plan is None:
            raise NavigationError(f"{self.what}: compute_velocity called before set_plan")
        if needs_costmap and costmap is None:
            raise NavigationError(f"{self.what}: needs a local costmap (got None)")


class Nav2PlanController(ControllerBase):
    """The plan handling of Nav2's controllers (MPPI, Regulated Pure Pursuit): the plan resampled every
    ``spacing`` m, the progress along it kept when a plan to the same goal is sent again, and Nav2's
    SimpleGoalChecker (xy tolerance, latched if ``stateful``, and yaw tolerance)."""

    spacing = 0.05  # m between the resampled plan's points

    def _plan_state(self, xy_goal_tolerance: float, yaw_goal_tolerance: float, stateful: bool) -> None:
        """Start without a plan (call from ``__init__``)."""
        self._latch = GoalLatch(xy_goal_tolerance, yaw_goal_tolerance, stateful)
        self._plan: np.ndarray | None = None
        self._goal: tuple[float, float, float | None] = (0.0, 0.0, None)
        self._progress = 0

    def set_plan(self, path: np.ndarray) -> None:
        """The global plan (N, 2) or (N, 3) in the costmap's frame (resampled at ``spacing``); an (N, 3) plan's last
        yaw is the goal yaw. A plan to a new goal (beyond the goal tolerances) resets the goal latch; one to the same
        goal keeps the progress made along the old one."""
        plan = as_plan(path)
        goal = goal_of(plan)
        dense = densify(plan[:, :2], self.spacing)
        latch = self._latch
        if self._plan is not None and same_goal(self._goal, goal, latch.xy_tolerance, latch.yaw_tolerance):
            anchor = self._plan[self._progress]  # keep the progress along a plan re-sent to the same goal
            self._progress = int(np.argmin(np.hypot(dense[:, 0] - anchor[0], dense[:, 1] - anchor[1])))
        else:
            latch.reset()
            self._progress = 0
        self._goal, self._plan = goal, dense

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float]) -> bool:
        """Nav2's SimpleGoalChecker: within xy tolerance (latched if ``stateful``) and yaw tolerance."""
        if self._plan is None:
            return False
        return self._latch.reached((float(pose[0]), float(pose[1]), float(pose[2])), self._goal)


def inscribed_radius(footprint: np.ndarray | None, robot_radius: float | None) -> float:
    """The footprint's inscribed radius (m): the nearest edge of a polygon to the centre, else the radius."""
    if footprint is None or len(footprint) < 3:
        return float(robot_radius or 0.0)
    a, b = footprint, np.roll(footprint, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", -a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12), 0.0, 1.0)
    nearest = a + t[:, None] * ab
    return float(np.hypot(nearest[:, 0], nearest[:, 1]).min())


def cost_regulated_speeds(
    v_max: float, scaling_dist: float, gain: float, cost_scaling_factor: float, inscribed: float, min_speed: float
) -> np.ndarray:
    """Nav2 RPP's cost-regulated speed for every costmap cost (256,), m/s: the obstacle distance a cost stands for
    (``inscribed - ln(cost / 252) / cost_scaling_factor``, m from the robot's centre, as the inflation layer
    draws it) under ``scaling_dist`` m slows ``v_max`` by ``gain * dist / scaling_dist``, not under
    ``min_speed``; free (0) and unknown (255) cells keep ``v_max``."""
    cost = np.arange(256, dtype=np.float64)
    ratio = np.minimum(cost, 252.0) / 252.0
    with np.errstate(divide="ignore"):
        dist = -np.log(ratio) / cost_scaling_factor + inscribed
    v = np.where(dist < scaling_dist, v_max * gain * dist / scaling_dist, v_max)
    v = np.maximum(np.minimum(v, v_max), min(min_speed, v_max))
    v[0] = v[255] = v_max
    return v
