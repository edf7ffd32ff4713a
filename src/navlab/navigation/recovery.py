"""move_base's recovery behaviors: clear costmaps, rotate in place, back up.

Each behavior is a small state machine that move_base ticks at ``controller_frequency``: ``start`` once,
then ``step(pose, costmaps)`` returns a velocity command (v m/s, w rad/s) or None when it is done. Poses
are the robot in the local costmap's frame (odom). ROS 1 names and defaults.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from navlab.core import ParamSpec, read_params
from navlab.geometry import compose2, wrap_angle
from navlab.grid import COST_INSCRIBED, COST_LETHAL
from navlab.navigation.errors import NavigationError
from navlab.plugins import BuiltFromParams

Pose = tuple[float, float, float]


def _collides(costmaps: dict[str, Any], pose: Pose, move: Pose = (0.0, 0.0, 0.0)) -> bool:
    """Whether the footprint at ``pose`` (local costmap frame) moved by ``move`` (x m, y m, yaw rad in the robot's
    frame) covers a lethal or unknown cell of the local costmap, or a lethal cell of a global costmap in the same
    frame (mapless navigation's rolling map in odom). That one keeps what the laser saw: after the local window was
    cleared, the obstacles behind a 270° laser are only there (its unknown cells do not block: a rolling map has not
    seen everything around). A global costmap in ``map`` is not asked: it would add amcl's error to the check."""
    local, g = costmaps["local"], costmaps.get("global")
    at = compose2(pose, move)
    if local.footprint_cost(at) >= COST_INSCRIBED + 1:
        return True
    return (
        g is not None
        and g is not local
        and g.global_frame == local.global_frame
        and g.footprint_cost(at) == COST_LETHAL
    )


@dataclass
class ClearCostmapParams:
    """clear_costmap_recovery: obstacles farther than ``reset_distance``/2 (m, square) are forgotten."""

    reset_distance: float = 3.0
    layer_names: tuple[str, ...] = ("obstacle_layer",)
    force_updating: bool = False
    affected_maps: str = "both"
    PARAMS: ClassVar[ParamSpec] = ParamSpec(
        "clear_costmap_recovery",
        NavigationError,
        at_least={"reset_distance": 0.0},
        choices={"affected_maps": ("global", "local", "both")},
    )


class ClearCostmapRecovery(BuiltFromParams):
    """``clear_costmap_recovery/ClearCostmapRecovery``: clears the costmaps' obstacle layers outside a square
    of side ``reset_distance`` around the robot; takes one cycle."""

    def __init__(self, params: dict[str, Any] | None = None, *, default_reset: float = 3.0) -> None:
        self.params = read_params(ClearCostmapParams, {"reset_distance": default_reset, **(params or {})})

    def start(self, pose: Pose) -> None:
        """Nothing to remember."""

    def step(self, pose: Pose, costmaps: dict[str, Any]) -> tuple[float, float] | None:
        """Clear, then done."""
        which = ("global", "local") if self.params.affected_maps == "both" else (self.params.affected_maps,)
        for name in which:
            costmaps[name].clear_outside(self.params.reset_distance)
        return None


@dataclass
class RotateParams:
    """rotate_recovery (ROS 1): ``sim_granularity`` (rad) and the local planner's rotation limits."""

    sim_granularity: float = 0.017
    frequency: float = 20.0
    max_rotational_vel: float = 1.0
    min_in_place_rotational_vel: float = 0.4
    acc_lim_th: float = 3.2
    tolerance: float = 0.10
    PARAMS: ClassVar[ParamSpec] = ParamSpec("rotate_recovery", NavigationError, above={"max_rotational_vel": 0.0})


class RotateRecovery(BuiltFromParams):
    """``rotate_recovery/RotateRecovery``: turn 360° in place (counter-clockwise), stopping early if the
    footprint would hit a lethal cell of the local costmap."""

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = read_params(RotateParams, params)
        self._start_yaw = 0.0
        self._turned = 0.0
        self._last = 0.0

    def start(self, pose: Pose) -> None:
        """Remember where the turn began."""
        self._start_yaw = self._last = pose[2]
        self._turned = 0.0

    def step(self, pose: Pose, costmaps: dict[str, Any]) -> tuple[float, float] | None:
        """The next turning command, or None once a full turn is done or a collision is ahead."""
        p = self.params
        self._turned += abs(float(wrap_angle(pose[2] - self._last)))
        self._last = pose[2]
        left = 2 * math.pi - self._turned
        if left < p.tolerance:
            return None
        if _collides(costmaps, pose, (0.0, 0.0, min(left, 0.3))):
            return None  # ROS: "Rotation in place would collide"
        w = min(p.max_rotational_vel, max(p.min_in_place_rotational_vel, math.sqrt(2 * p.acc_lim_th * left)))
        return 0.0, w


@dataclass
class BackUpParams:
    """Nav2's BackUp behavior: drive ``backup_dist`` m straight back at ``backup_speed`` m/s."""

    backup_dist: float = 0.3
    backup_speed: float = 0.1
    time_allowance: float = 10.0
    PARAMS: ClassVar[ParamSpec] = ParamSpec("back_up", NavigationError, above={"backup_dist": 0.0, "backup_speed": 0.0})


class BackUpRecovery(BuiltFromParams):
    """``nav2_behaviors/BackUp``: reverse a short distance, stopping if the footprint behind is lethal."""

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = read_params(BackUpParams, params)
        self._start: Pose = (0.0, 0.0, 0.0)
        self._steps = 0

    def start(self, pose: Pose) -> None:
        """Remember the start."""
        self._start, self._steps = pose, 0

    def step(self, pose: Pose, costmaps: dict[str, Any]) -> tuple[float, float] | None:
        """Reverse until far enough, blocked, or out of time (at 20 Hz ticks)."""
        p = self.params
        self._steps += 1
        if math.dist(pose[:2], self._start[:2]) >= p.backup_dist or self._steps > p.time_allowance * 20:
            return None
        if _collides(costmaps, pose, (-0.1, 0.0, 0.0)):
            return None
        return -p.backup_speed, 0.0


# ROS 1's default recovery_behaviors, then navlab's back-up.
DEFAULT_RECOVERIES: tuple[dict[str, str], ...] = (
    {"name": "conservative_reset", "type": "clear_costmap_recovery/ClearCostmapRecovery"},
    {"name": "rotate_recovery", "type": "rotate_recovery/RotateRecovery"},
    {"name": "aggressive_reset", "type": "clear_costmap_recovery/ClearCostmapRecovery"},
    {"name": "rotate_recovery", "type": "rotate_recovery/RotateRecovery"},
    {"name": "back_up", "type": "nav2_behaviors/BackUp"},
)
