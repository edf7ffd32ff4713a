"""A scenario's obstacles, placed as an experimenter would: never on the start, a goal or the robot.

An obstacle dropped in while the robot drives is a test of navigation only if the goal stays reachable. Each
obstacle keeps :func:`keep_clear_m` (its own reach + the robot's collision reach + ``SAFETY_DISTANCE_M``, so a
robot standing on the goal is still the safety distance from it) between its origin and the start, every goal
and the robot at the moment it appears:

- ``frame: world`` obstacles (a fixed place): one that covers the start or a goal is a scenario error
  (:func:`check_fixed_obstacles`); one that would land on the robot waits until the robot has moved off it.
- ``frame: robot`` obstacles (``x`` m ahead of the robot at a time drawn in ``[lo, hi]``): the spot ahead moves
  with the robot, towards the goal it drives to. The obstacle appears at the drawn time, or earlier (not before
  ``lo``) at the last moment the spot is still clear of the goal, so it never lands on the goal the robot is about
  to reach. The place is checked every ``ASK_EVERY_S`` s from ``lo``, on a grid that holds the drawn time.

An obstacle that finds no clear moment within ``WAIT_MAX_S`` s after ``hi`` is not placed (the trial says so).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from navlab.experiments.errors import ExperimentError
from navlab.experiments.navigate_monitor import SAFETY_DISTANCE_M
from navlab.experiments.scenario import Scenario

ASK_EVERY_S = 0.05  # s between checks of a deferred placement (move_base's controller period)
WAIT_MAX_S = 10.0  # s after the window's end an obstacle may wait for a clear place, then it is left out


def model_reach(model: Any) -> float:
    """How far (m) a model's collision shapes reach from its own origin, seen from above (at any height)."""
    from navlab.world import WorldModel, shape_footprints

    fps = shape_footprints(
        WorldModel("reach", [replace(model, pose=(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))]), z_min=-math.inf, z_max=math.inf
    )
    reach = 0.0
    for fp in fps:
        if fp.kind == "disc":
            reach = max(reach, float(np.hypot(*fp.points[0])) + fp.radius)
        else:
            pts = fp.triangles.reshape(-1, 3)[:, :2] if fp.triangles is not None else fp.points
            reach = max(reach, float(np.hypot(pts[:, 0], pts[:, 1]).max()))
    return reach


def robot_reach(robot: str) -> float:
    """How far (m) the robot's collision geometry reaches from its base frame's origin."""
    from navlab.description import collision_reach, load_robot_named

    return collision_reach(load_robot_named(robot))


def keep_clear_m(model: Any, reach_robot: float) -> float:
    """The distance (m) ``model``'s origin keeps from the start, the goals and the robot: its reach + the robot's
    collision reach + the safety distance."""
    return model_reach(model) + reach_robot + SAFETY_DISTANCE_M


def keep_clear_points(sc: Scenario) -> np.ndarray:
    """The start and every goal (K, 2) in the world frame (mapless goals are in odom, which starts at the start)."""
    from navlab.geometry import compose2

    goals = [compose2(sc.start, g)[:2] if sc.map == "none" else g[:2] for g in sc.goals]
    return np.array([sc.start[:2], *goals], dtype=np.float64)


def check_fixed_obstacles(sc: Scenario, reach_robot: float) -> None:
    """One error line for a ``frame: world`` obstacle that covers the start or a goal (see the module docstring)."""
    from navlab.sim import parse_spawn_spec

    points = keep_clear_points(sc)
    names = ["the start", *(f"goal {k + 1}" for k in range(len(sc.goals)))]
    for k, ob in enumerate(sc.obstacles):
        if ob.get("frame", "world") != "world":
            continue
        model = parse_spawn_spec(ob["spec"], default_name=f"obstacle_{k}")[0]
        need = keep_clear_m(model, reach_robot)
        d = np.hypot(*(points - np.asarray(model.pose[:2])).T)
        if d.min() < need:
            j = int(d.argmin())
            raise ExperimentError(
                f"{sc.name}: obstacles[{k}] at ({model.pose[0]:g}, {model.pose[1]:g}) is {d[j]:.2f} m from "
                f"{names[j]}: keep it at least {need:.2f} m away (its reach + the robot's + {SAFETY_DISTANCE_M:g} m) "
                "so the robot can stand there"
            )


class Placement:
    """When and where one obstacle appears: ``__call__(sim)`` (called by ``run_navigation`` at ``first_s`` and
    at each time it returns) gives the model to spawn, a later time (s) to be asked again, or None (left out)."""

    def __init__(
        self, model: Any, t: float, window: tuple[float, float], robot_frame: bool, points: np.ndarray, clear: float
    ) -> None:
        self.model, self.t, (self.lo, self.hi), self.robot_frame = model, t, window, robot_frame
        self.points, self.clear = points, clear
        # checks at t - k ASK_EVERY_S from the window's start: an early placement keeps the drawn time's phase
        self._step = -math.floor((t - self.lo) / ASK_EVERY_S + 1e-9) if robot_frame else 0  # checks before t: < 0
        self.first_s = self._at_step()
        self.placed: tuple[float, float, float] | None = None  # (t s, x m, y m) where and when it appeared
        self._margin_before: float | None = None

    def where(self, robot: tuple[float, float, float]) -> Any:
        """The model at its place for the robot's true pose (x, y, yaw; world frame)."""
        from navlab.geometry import compose2

        if not self.robot_frame:
            return self.model
        m = self.model
        x, y, yaw = compose2(robot, (m.pose[0], m.pose[1], m.pose[5]))
        return replace(m, pose=(x, y, m.pose[2], m.pose[3], m.pose[4], yaw))

    def __call__(self, sim: Any) -> Any:
        now = self._at_step()
        robot = sim.base_pose2d()
        model = self.where(robot)
        xy = np.asarray(model.pose[:2])
        margin = min(
            float(np.hypot(*(self.points - xy).T).min()) - self.clear,  # off the start and the goals
            math.dist(xy, robot[:2]) - self.clear,  # and off the robot
        )
        before, self._margin_before = self._margin_before, margin
        # the spot drifts onto a goal by the next check (linear guess from the last one): now is its last clear moment
        closing = before is not None and margin - (before - margin) < 0.0 <= margin
        if margin >= 0.0 and (now >= self.t - 1e-9 or closing):
            self.placed = (now, float(xy[0]), float(xy[1]))
            return model
        if now >= self.hi + WAIT_MAX_S - 1e-9:
            return None
        self._step += 1
        return self._at_step()

    def _at_step(self) -> float:
        """The time (s) of check number ``_step`` (0 at the drawn time: exactly ``t``)."""
        return self.t + self._step * ASK_EVERY_S


def placements(sc: Scenario, seed: int) -> list[Placement]:
    """The scenario's obstacles for the trial with ``seed``: a ``[lo, hi]`` time drawn from ``seed`` (its own
    random stream), each kept clear of the start, the goals and the robot (see the module docstring)."""
    from navlab.sim import parse_spawn_spec

    if not sc.obstacles:
        return []
    rng = np.random.default_rng([seed, 0x0B57])  # its own stream: the run's seed stays the simulator's
    reach_robot = robot_reach(sc.robot)
    points = keep_clear_points(sc)
    out = []
    for k, ob in enumerate(sc.obstacles):
        model = parse_spawn_spec(ob["spec"], default_name=f"obstacle_{k}")[0]
        window = (float(ob["t"][0]), float(ob["t"][1])) if isinstance(ob["t"], list) else (ob["t"], ob["t"])
        t = float(rng.uniform(*window)) if isinstance(ob["t"], list) else float(ob["t"])
        clear = keep_clear_m(model, reach_robot)
        out.append(Placement(model, t, window, ob.get("frame", "world") == "robot", points, clear))
    return out
