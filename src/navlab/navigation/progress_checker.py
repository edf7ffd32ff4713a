"""Nav2's progress checker (``nav2_controller::SimpleProgressChecker``) and what a stuck robot is.

The checker keeps a baseline pose; whenever the robot moves more than ``required_movement_radius`` m from
it, the baseline becomes the current pose and its clock restarts. The robot is *stuck* when the baseline is
older than ``movement_time_allowance`` s. move_base uses it beside ROS 1's oscillation timeout: no
progress triggers the next recovery, and when the recoveries are used up with still no progress the goal
ends ``stuck`` (an ABORTED goal whose reason says so). Poses (x, y, yaw) in any one fixed frame; times s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from navlab.core import ParamSpec, read_params
from navlab.navigation.errors import NavigationError

Pose = tuple[float, float, float]
STUCK_PREFIX = "stuck"  # an ABORTED goal's reason starts with this when the robot made no progress


@dataclass
class ProgressCheckerParams:
    """Nav2's ``progress_checker`` namespace (``plugin: nav2_controller::SimpleProgressChecker``)."""

    PARAMS: ClassVar[ParamSpec] = ParamSpec(
        "progress_checker", NavigationError, at_least={"required_movement_radius": 0.0, "movement_time_allowance": 0.0}
    )
    required_movement_radius: float = 0.5  # m
    movement_time_allowance: float = 10.0  # s; 0 switches the checker off
    plugin: str = "nav2_controller::SimpleProgressChecker"


class SimpleProgressChecker:
    """``nav2_controller::SimpleProgressChecker``: ``check(pose, t)`` is False once the robot has stayed within
    ``required_movement_radius`` of one pose for more than ``movement_time_allowance`` s."""

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = read_params(ProgressCheckerParams, params)
        self.baseline: Pose | None = None
        self.baseline_t = 0.0

    @classmethod
    def from_params(cls, params: dict[str, Any] | None, *, context: Any = None) -> SimpleProgressChecker:
        """The plugin contract's constructor (``context`` is not used)."""
        return cls(params)

    @property
    def enabled(self) -> bool:
        """Whether the checker can report no progress at all (``movement_time_allowance`` > 0)."""
        return self.params.movement_time_allowance > 0

    def reset(self, pose: Pose | None = None, t: float = 0.0) -> None:
        """Start over from ``pose`` at ``t`` (None: from the next pose checked)."""
        self.baseline, self.baseline_t = pose, t

    def check(self, pose: Pose, t: float) -> bool:
        """Whether the robot is making progress at ``pose`` at time ``t`` (s)."""
        if self.baseline is None or math.dist(pose[:2], self.baseline[:2]) > self.params.required_movement_radius:
            self.reset(pose, t)
            return True
        return not self.enabled or t - self.baseline_t <= self.params.movement_time_allowance

    def idle_s(self, t: float) -> float:
        """How long (s) the robot has stayed near the baseline at ``t``."""
        return 0.0 if self.baseline is None else t - self.baseline_t


def stuck_window(path: Any, window_s: float, radius_m: float) -> bool:
    """Whether a true path (rows ``(t s, x m, y m)``) stayed within ``radius_m`` of its last point for its last
    ``window_s`` s (a run too short to cover the window is not stuck)."""
    rows = [tuple(r) for r in path]
    if not rows or rows[-1][0] - rows[0][0] < window_s:
        return False
    t1, x1, y1 = rows[-1][:3]
    return all(math.hypot(x - x1, y - y1) <= radius_m for t, x, y in (r[:3] for r in rows) if t >= t1 - window_s)
