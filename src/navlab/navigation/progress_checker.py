"""Nav2's progress checker (``nav2_controller::SimpleProgressChecker``) and what a stuck robot is.

The checker keeps a baseline pose; whenever the robot moves more than ``required_movement_radius`` m from
it, the baseline becomes the current pose and its clock restarts. The robot is *stuck* when the baseline is
older than ``movement_time_allowance`` s. navlab's extension (off unless ``goal_progress_time_allowance`` > 0):
progress *toward the goal* — a robot that drives in and out of one pocket moves all the time yet gets no
nearer; it is stuck too when its closest distance to the goal has not shrunk by ``required_goal_progress`` m
for ``goal_progress_time_allowance`` s. move_base uses it beside ROS 1's oscillation timeout: no
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
        "progress_checker",
        NavigationError,
        at_least={
            "required_movement_radius": 0.0,
            "movement_time_allowance": 0.0,
            "required_goal_progress": 0.0,
            "goal_progress_time_allowance": 0.0,
        },
    )
    required_movement_radius: float = 0.5  # m
    movement_time_allowance: float = 10.0  # s; 0 switches the checker off
    plugin: str = "nav2_controller::SimpleProgressChecker"
    required_goal_progress: float = 0.5  # m nearer the goal (navlab extension)
    goal_progress_time_allowance: float = 0.0  # s; 0: no check of progress toward the goal (Nav2's checker)


class SimpleProgressChecker:
    """``nav2_controller::SimpleProgressChecker``: ``check(pose, t)`` is False once the robot has stayed within
    ``required_movement_radius`` of one pose for more than ``movement_time_allowance`` s."""

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = read_params(ProgressCheckerParams, params)
        self.baseline: Pose | None = None
        self.baseline_t = 0.0
        self.closest: float | None = None  # m: the goal distance to beat, and since when (s)
        self.closest_t = 0.0
        self.toward_goal = False  # the last check failed for want of progress toward the goal
        self.progressed = False  # the last check saw progress (toward the goal when that is checked)

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
        self.closest, self.closest_t = None, t

    def restart_clocks(self, t: float) -> None:
        """Give the robot its allowances again from ``t`` (after a recovery), keeping the baselines."""
        self.baseline_t = self.closest_t = t

    def check(self, pose: Pose, t: float, goal: Any = None) -> bool:
        """Whether the robot is making progress at ``pose`` at time ``t`` (s); ``goal``: where the goal is (x, y
        in the pose's frame; None: not known, no check toward the goal)."""
        p = self.params
        self.toward_goal = self.progressed = False
        toward = p.goal_progress_time_allowance > 0 and goal is not None
        if toward:
            goal_distance = math.dist(pose[:2], goal[:2])
            if self.closest is None or goal_distance < self.closest - p.required_goal_progress:
                self.closest, self.closest_t, self.progressed = goal_distance, t, True
            elif t - self.closest_t > p.goal_progress_time_allowance:
                self.toward_goal = True
                return False
        if self.baseline is None or math.dist(pose[:2], self.baseline[:2]) > p.required_movement_radius:
            self.baseline, self.baseline_t = pose, t
            self.progressed = self.progressed or not toward
            return True
        return not self.enabled or t - self.baseline_t <= p.movement_time_allowance

    def stuck_reason(self, t: float) -> str:
        """Why a goal ends ``stuck`` at ``t`` when the recoveries did not help: what the checker saw last."""
        p = self.params
        if self.toward_goal:
            saw = f"the robot came no nearer the goal by {p.required_goal_progress:g} m in {t - self.closest_t:.1f} s"
        else:
            saw = f"the robot moved less than {p.required_movement_radius:g} m in {self.idle_s(t):.1f} s"
        return f"{STUCK_PREFIX}: {saw}, even after executing recovery behaviors."

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
