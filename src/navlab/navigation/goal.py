"""A move_base goal's life, as actionlib's SimpleActionClient sees it, and the plan handed to the controller."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

Pose = tuple[float, float, float]
# action_msgs/GoalStatus codes of the states a goal goes through
STATUS = {"PENDING": 1, "ACTIVE": 2, "PREEMPTED": 5, "SUCCEEDED": 4, "ABORTED": 6}


@dataclass
class GoalHandle:
    """One goal's life: ``state`` PENDING -> ACTIVE -> SUCCEEDED | ABORTED | PREEMPTED, with ``reason``."""

    goal: Pose
    frame_id: str
    id: int
    state: str = "PENDING"
    reason: str = ""
    start_s: float = 0.0
    end_s: float | None = None
    feedback: Callable[[Pose], None] | None = None
    on_done: Callable[[GoalHandle], None] | None = field(default=None, repr=False)

    def done(self) -> bool:
        """Whether the goal reached a terminal state."""
        return self.state in ("SUCCEEDED", "ABORTED", "PREEMPTED")


def with_headings(xy: np.ndarray, goal_yaw: float) -> np.ndarray:
    """A plan (N, 3): each pose heads to the next one, the last takes the goal's yaw (as navfn's plan does)."""
    yaw = np.empty(len(xy))
    if len(xy) > 1:
        d = np.diff(xy, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaw[-1] = goal_yaw
    return np.column_stack([xy, yaw])
