"""The rollout controllers' shared cycle: base_local_planner's TrajectoryPlanner (with its ``dwa`` flag) and
dwa_local_planner's DWAPlanner (``trajectory`` and ``dwa`` hold each planner's own scoring).

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
  max_cost, distances at the rollout's end (in cells; ``meter_scoring`` multiplies the three biases by the
  resolution, as noetic scores after its start-up reconfigure); a rollout that
  leaves the map, is blocked, or passes a cell with no path to the plan or goal is rejected (the first failure
  in time decides the code, -1 or -2). With ``heading_scoring`` every rollout has sim_time / sim_granularity
  steps, the distances count at the step at ``heading_scoring_timestep`` only, and 0.3 x the angle from the
  heading there to the last plan point in clear sight (``headingDiff``) is added. In-place
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

import numpy as np

from navlab.core import read_params
from navlab.grid import Grid
from navlab.navigation.controllers import mapgrid, scene_kernel
from navlab.navigation.controllers.common import (
    ControllerBase,
    GoalLatch,
    LocalFrame,
    OscillationFlags,
    as_plan,
    circle_footprint,
    footprint_outline,
    goal_of,
    prune_plan,
    rotate_to_goal,
    same_goal,
    same_values,
    stop_with_acc_limits,
    stopped,
)
from navlab.navigation.controllers.rollout import outline_reach_max, rollout

_NO_POINTS = np.zeros((0, 2))  # no polygon, no outline (path_scene's typed empties)
_NO_POINTS.flags.writeable = False
_NONE_3, _NONE_2, _NONE_1, _NO_ROLLOUTS = np.zeros((0, 3)), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 0, 3))
for _empty in (_NONE_3, _NONE_2, _NONE_1, _NO_ROLLOUTS):  # a cycle's outputs before it has any (read-only)
    _empty.flags.writeable = False
_NO_FRAME = LocalFrame(0.0, 0.0, 0.0)


def _words(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two C-contiguous arrays of one shape as flat arrays to compare: 8 bytes at a time where the size allows."""
    a, b = a.reshape(-1), b.reshape(-1)
    if a.nbytes % 8 == 0:
        return a.view(np.int64), b.view(np.int64)
    return a, b


# --- the shared cycle ------------------------------------------------------------------------------


@dataclass
class LocalScene:
    """One cycle's inputs in grid-local coordinates: pose, cost array, the plan as ROS's planners get it
    (``plan`` (N, 2), cropped around the robot), its cells and the distance maps to the path and to the local goal
    as waves that compiled lookups grow as far as they need (``mapgrid.wave_to``; ``path_dist`` and ``goal_dist``
    grow them whole)."""

    frame: LocalFrame
    pose: tuple[float, float, float]
    cost: np.ndarray
    resolution: float
    plan: np.ndarray
    path_cells: np.ndarray
    path_wave: mapgrid.Wave
    goal_wave: mapgrid.Wave

    @property
    def path_dist(self) -> np.ndarray:
        """The path distance map (cost's shape), the whole wave."""
        mapgrid.wave_to(self.cost, self.path_wave, -1, -1)
        return self.path_wave[0]

    @property
    def goal_dist(self) -> np.ndarray:
        """The local goal's distance map (cost's shape), the whole wave."""
        mapgrid.wave_to(self.cost, self.goal_wave, -1, -1)
        return self.goal_wave[0]

    @property
    def impossible(self) -> float:
        """MapGrid's obstacle value (cells in the grid): distances at or above it are hopeless."""
        return float(self.cost.size)

    def local_goal(self) -> np.ndarray:
        """Grid-local point (2,): the cropped plan's last pose (``transformed_plan.back()``)."""
        return self.plan[-1].copy()


class RolloutController(ControllerBase):
    """What TrajectoryPlannerROS and DWAPlannerROS share: plan, goal handling, outputs.

    ``params``: the planner's ROS 1 parameter dict (old and new spellings) or its ``params_class``;
    ``footprint``: polygon [[x, y], ...] (m, base frame), else ``robot_radius`` (m: costmap_2d's 16-gon), else a
    point robot (centre cell); ``controller_frequency``: move_base's (Hz), used unless ``params`` sets it.
    ``rng`` is accepted for a uniform constructor and not used (the planners are deterministic).

    After each :meth:`compute_velocity`: ``local_plan`` (N, 3) chosen rollout (costmap frame; empty when
    stopping, turning at the goal or failing), ``samples`` (S, 2) the (v, w) tried, ``costs`` (S,) their
    costs (< 0: rejected), ``valid`` False when no valid command was found (ROS's ``computeVelocityCommands``
    returning false: move_base's cue for recovery).
    """

    params_class: type[Any]
    params: Any
    _stopped_vel = (0.01, 0.01)
    _accelerate = True

    def __init__(
        self,
        params: Mapping[str, Any] | Any | None = None,
        *,
        footprint: Any = None,
        robot_radius: float | None = None,
        controller_frequency: float | None = None,
        rng: np.random.Generator | None = None,
    ) -> None:
        if controller_frequency is not None and (params is None or isinstance(params, Mapping)):
            params = {"controller_frequency": controller_frequency, **(params or {})}  # its own value wins
        self.params = read_params(self.params_class, params)
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64)
        if footprint_outline(self.footprint, 0.05) is None:  # validate now; no polygon: the round robot's 16-gon
            self.footprint = None if robot_radius is None else circle_footprint(float(robot_radius))
        p = self.params
        self._latch = GoalLatch(p.xy_goal_tolerance, p.yaw_goal_tolerance, p.latch_xy_goal_tolerance)
        self._osc = OscillationFlags(p.oscillation_reset_dist, getattr(p, "oscillation_reset_angle", -1.0))
        self._plan: np.ndarray | None = None
        self._given: np.ndarray | None = None  # the plan as set_plan last checked it (before pruning)
        self._given_array: Any = None  # the object it came as
        self._last_frame: tuple[tuple[float, float, float], LocalFrame] | None = None  # the grid-local frame seen
        self._rotating_to_goal = False
        self._outlines: dict[tuple[float, bytes | None], np.ndarray | None] = {}
        self._near: tuple[np.ndarray, np.ndarray | None, np.ndarray] | None = None  # (outline, costs, reach max)
        self._goal_map: tuple[np.ndarray | None, tuple[int, int], mapgrid.Wave] | None = None  # costs, goal cell, wave
        self._costs_seen: np.ndarray | None = None  # the local costs last seen (see _note_costs)
        self._clear_outputs()
        self._setup()

    def _setup(self) -> None:
        """The planner's own state (called at the end of ``__init__``)."""

    def _clear_outputs(self) -> None:
        self.local_plan, self.samples, self.costs, self._traj = _NONE_3, _NONE_2, _NONE_1, _NO_ROLLOUTS
        self._frame = _NO_FRAME
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
        given = self._given
        if path is self._given_array and not path.flags.writeable and path.flags.owndata:
            self._plan = given  # the very array checked last time, read-only: unchanged (move_base's, each cycle)
            return
        same_kind = isinstance(path, np.ndarray) and path.dtype == np.float64
        if given is not None and same_kind and path.shape == given.shape:
            bits = np.ascontiguousarray(path).reshape(-1).view(np.int64)
            if same_values(bits, given.reshape(-1).view(np.int64)):  # bit for bit (the sign of zero too)
                self._plan, self._given_array = given, path  # the plan sent again: checked, to the same goal
                return
        plan = as_plan(path)
        p = self.params
        if self._plan is None or not same_goal(
            goal_of(self._plan), goal_of(plan), p.xy_goal_tolerance, p.yaw_goal_tolerance
        ):
            self._latch.reset()
            self._osc.reset()
            self._rotating_to_goal = False
            self._new_goal()
        self._plan = self._given = plan  # never changed in place (pruning takes a view of its rows)
        self._given_array = path

    def _new_goal(self) -> None:
        """Forget per-goal state (subclasses add theirs)."""

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float]) -> bool:
        """Within xy (possibly latched) and yaw tolerance of the plan's last pose."""
        if self._plan is None:
            return False
        return self._latch.reached(tuple(map(float, pose)), goal_of(self._plan))  # type: ignore[arg-type]

    def _command(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        self._check_call(self._plan, costmap)
        assert self._plan is not None and costmap is not None
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
        return self._drive(scene, pose, velocity)

    # --- pieces -----------------------------------------------------------------------------------

    def _scene(self, pose: tuple[float, float, float], costmap: Grid) -> LocalScene | None:
        assert self._plan is not None
        last = self._last_frame  # (the origin tuple it was made from, the frame): kept while the window stays
        if last is None or last[0] is not costmap.origin:
            last = self._last_frame = (costmap.origin, LocalFrame.of(costmap))
        frame = last[1]
        self._frame = frame
        cost = np.ascontiguousarray(costmap.data, dtype=np.uint8)
        res = costmap.resolution
        pose_l = frame.pose_in(pose)
        self._note_costs(cost)
        mode, polygon, edges = self._free_mode(res)
        plan, cells, wave = scene_kernel.path_scene(
            cost,
            np.ascontiguousarray(self._plan),  # (N, 2) or (N, 3): path_scene reads the first two columns
            frame.ox,
            frame.oy,
            frame.oyaw,
            res,
            pose_l,
            0.5 * res * max(cost.shape),
            mode,
            _NO_POINTS if polygon is None else polygon,
            _NO_POINTS if edges is None else edges,
        )
        if len(plan) == 0:
            return None  # ROS: an empty transformed plan (no pose of the plan near the robot)
        if len(cells) == 0:
            return None  # ROS: "None of the points of the global plan were in the local costmap"
        return LocalScene(frame, pose_l, cost, res, plan, cells, wave, self._goal_wave(cost, cells[-1]))

    def _note_costs(self, cost: np.ndarray) -> None:
        """Keep a copy of the local costs in ``_costs_seen``, a new one only when they changed: what is computed
        from them (the goal's distance map, the footprint's reach maximum) is kept with that copy and reused while
        it is still the one (the costmap updates less often than the controller runs)."""
        seen = self._costs_seen
        if seen is None or seen.shape != cost.shape or not same_values(*_words(seen, cost)):
            self._costs_seen = cost.copy()

    def _goal_wave(self, cost: np.ndarray, goal: np.ndarray) -> mapgrid.Wave:
        """The local goal cell's (i, j) distance wave, kept (and grown further as lookups need) while the costs and
        that cell stay the same (the robot moves a few cells per costmap update; the goal cell moves less often)."""
        cell = (int(goal[0]), int(goal[1]))
        cached = self._goal_map
        if cached is not None and cached[0] is self._costs_seen and cached[1] == cell:
            return cached[2]
        none = np.zeros(0, dtype=np.int64)
        wave = mapgrid.wave_start(cost, goal[:1].copy(), goal[1:].copy(), none, none)
        self._goal_map = (self._costs_seen, cell, wave)
        return wave

    def _free_mode(self, res: float) -> tuple[int, np.ndarray | None, np.ndarray | None]:
        """Which cells never block the path map's wave, as ``scene_kernel.path_scene`` takes it: (0 none | 1 the
        centre cell | 2 the cells under the polygon, the polygon (K, 2) (base frame, m), its outline at ``res``)."""
        return 0, None, None

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
        if cached is not None and cached[0] is outline and cached[1] is self._costs_seen:
            return cached[2]
        near = outline_reach_max(scene.cost, scene.resolution, outline)
        self._near = (outline, self._costs_seen, near)
        return near

    def _stop_rotate(
        self,
        pose: tuple[float, float, float],
        velocity: tuple[float, float],
        goal: tuple[float, float, float | None],
        scene: LocalScene | None,
    ) -> tuple[float, float]:
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
            cmd = (
                0.0,
                rotate_to_goal(
                    err,
                    velocity[1],
                    max_w=max_w,
                    min_in_place_w=min_w,
                    acc_theta=p.acc_lim_theta,
                    sim_period=p.sim_period,
                ),
            )
        if scene is not None and not self._command_valid(scene, velocity, cmd):
            self.valid = False
            return 0.0, 0.0
        return cmd

    def _in_place_limits(self, err: float) -> tuple[float, float]:
        raise NotImplementedError

    def _command_valid(self, scene: LocalScene, velocity: tuple[float, float], cmd: tuple[float, float]) -> bool:
        """Whether rolling ``cmd`` out for sim_time scores as a legal trajectory (ROS's ``checkTrajectory``)."""
        targets = np.array([cmd])
        return bool(self._check(scene, targets, self._rollout(scene, velocity, targets, self._steps(targets)))[0] >= 0)

    def _rollout(
        self, scene: LocalScene, velocity: tuple[float, float], targets: np.ndarray, steps: np.ndarray
    ) -> np.ndarray:
        """The samples ``targets`` (S, 2) rolled out from the scene's pose at ``velocity`` in ``steps`` (S,) steps over
        sim_time, within the acceleration limits as the planner applies them."""
        p = self.params
        acc = (p.acc_lim_x, p.acc_lim_theta)
        return rollout(scene.pose, velocity, targets, steps, p.sim_time, acc, accelerate=self._accelerate)

    def _check(self, scene: LocalScene, targets: np.ndarray, traj: np.ndarray) -> np.ndarray:
        """Costs (S,) of rollouts checked outside the sampling loop (< 0: illegal)."""
        raise NotImplementedError

    def _steps(self, targets: np.ndarray) -> np.ndarray:
        """Rollout steps (S,) of each sample, as the ROS planner counts them."""
        raise NotImplementedError

    def _finish(
        self,
        scene: LocalScene,
        targets: np.ndarray,
        traj: np.ndarray,
        costs: np.ndarray,
        best: int,
        pose: tuple[float, float, float],
    ) -> tuple[float, float]:
        """Store the cycle's outputs; command sample ``best`` (or stop and flag failure if it is -1)."""
        self.samples, self.costs, self._traj = targets, costs, traj
        if best < 0:
            self.valid = False
            return 0.0, 0.0
        path = traj[best]
        f = scene.frame
        c, s = math.cos(f.oyaw), math.sin(f.oyaw)
        self.local_plan = scene_kernel.poses_out(path, scene_kernel.moved_length(path), f.ox, f.oy, f.oyaw, c, s)
        return float(targets[best, 0]), float(targets[best, 1])

    def _drive(
        self, scene: LocalScene, pose: tuple[float, float, float], velocity: tuple[float, float]
    ) -> tuple[float, float]:
        """One sampling cycle away from the goal: the command of the best rollout (``_finish``)."""
        raise NotImplementedError
