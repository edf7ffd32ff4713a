"""Pure pursuit with turn-in-place: the controller the drivers (exploration, scripted routes) follow paths with.

``follow_path`` is the pure control law; ``PurePursuit`` wraps it behind the ``plugins.Controller``
seam (``navlab/PurePursuit``): set a plan, ask for (v, w) at a pose, know when the goal is reached.
Poses (x, y, yaw) and paths (N, 2) share one frame (odom, map or world); m, rad, m/s, rad/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from navlab.core import ParamSpec, read_params
from navlab.navigation.errors import NavigationError
from navlab.plugins import BuiltFromParams, ControlResult


def follow_path(
    pose: tuple[float, float, float],
    path: np.ndarray,
    *,
    lookahead: float = 0.4,
    max_v: float = 0.35,
    max_w: float = 1.2,
    min_front_range: float = float("inf"),
    stop_distance: float = 0.35,
) -> tuple[float, float, int]:
    """Pure pursuit toward the point ``lookahead`` ahead on ``path``; returns (v m/s, w rad/s, index reached).

    Turns in place when the target is more than ~60° off the heading; stops forward motion when the
    closest scan return ahead (``min_front_range``) is under ``stop_distance``.
    """
    x, y, yaw = pose
    d = np.hypot(path[:, 0] - x, path[:, 1] - y)
    nearest = int(np.argmin(d))
    ahead = np.nonzero(d[nearest:] >= lookahead)[0]
    k = nearest + int(ahead[0]) if len(ahead) else len(path) - 1
    tx, ty = path[k]
    dx, dy = tx - x, ty - y
    c, s = math.cos(yaw), math.sin(yaw)
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    heading_err = math.atan2(ly, lx)
    w = float(min(max(2.0 * heading_err, -max_w), max_w))  # np.clip's value, without its cost on a scalar
    if abs(heading_err) > 1.0:
        return 0.0, w, nearest
    v = max_v * max(0.0, math.cos(heading_err))
    v = min(v, 0.8 * math.hypot(dx, dy) + 0.05)
    if min_front_range < stop_distance:
        v = 0.0
    return float(v), w, nearest


@dataclass
class PurePursuitParams:
    """Parameters of the follower (m, m/s, rad/s)."""

    lookahead: float = 0.4
    max_vel_x: float = 0.35
    max_vel_theta: float = 1.2
    xy_goal_tolerance: float = 0.1
    stop_distance: float = 0.35
    PARAMS: ClassVar[ParamSpec] = ParamSpec(
        "PurePursuit",
        NavigationError,
        above={"lookahead": 0.0},
        at_least={"max_vel_x": 0.0, "max_vel_theta": 0.0, "xy_goal_tolerance": 0.0, "stop_distance": 0.0},
    )


class PurePursuit(BuiltFromParams):
    """``navlab/PurePursuit`` (a ``plugins.Controller``) over :func:`follow_path`; ``min_front_range`` (m) is the
    nearest return ahead, set by the caller from its scans (the follower then stops short of obstacles)."""

    def __init__(self, params: PurePursuitParams | dict[str, Any] | None = None, **overrides: Any) -> None:
        if overrides:  # keyword parameters over a dict or an instance's values
            params = {**(vars(params) if isinstance(params, PurePursuitParams) else params or {}), **overrides}
        self.params = read_params(PurePursuitParams, params)
        self.path = np.zeros((0, 2))
        self.min_front_range = math.inf

    def set_plan(self, path: np.ndarray) -> None:
        """Follow ``path`` (N, 2+) from now on."""
        self.path = np.asarray(path, dtype=np.float64)[:, :2].reshape(-1, 2)

    def compute_velocity(
        self, pose: tuple[float, float, float], velocity: tuple[float, float] = (0.0, 0.0), costmap: Any = None
    ) -> ControlResult:
        """The command (v m/s, w rad/s) toward the plan; a stop without a plan or once the goal is reached."""
        if len(self.path) == 0 or self.is_goal_reached(pose, velocity):
            return ControlResult(0.0, 0.0)
        p = self.params
        v, w, _ = follow_path(
            pose,
            self.path,
            lookahead=p.lookahead,
            max_v=p.max_vel_x,
            max_w=p.max_vel_theta,
            min_front_range=self.min_front_range,
            stop_distance=p.stop_distance,
        )
        return ControlResult(v, w)

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float] = (0.0, 0.0)) -> bool:
        """Within ``xy_goal_tolerance`` of the plan's last point."""
        if len(self.path) == 0:
            return False
        gx, gy = self.path[-1]
        return math.hypot(gx - pose[0], gy - pose[1]) < self.params.xy_goal_tolerance
