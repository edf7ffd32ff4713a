"""A move_base goal's life, as actionlib's SimpleActionClient sees it, and the plan handed to the controller."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from navlab import msgs

Pose = tuple[float, float, float]


class GoalState(StrEnum):
    """A goal's state as actionlib names it (str-valued: equal to the old strings, JSON writes the name)."""

    PENDING = "PENDING"
    ACTIVE = "ACTIVE"
    SUCCEEDED = "SUCCEEDED"
    ABORTED = "ABORTED"
    PREEMPTED = "PREEMPTED"


class MoveBaseState(StrEnum):
    """move_base's state machine (``MoveBaseState`` of move_base.h; str-valued)."""

    IDLE = "IDLE"
    PLANNING = "PLANNING"
    CONTROLLING = "CONTROLLING"
    CLEARING = "CLEARING"


class RecoveryTrigger(StrEnum):
    """What sent move_base into recovery (move_base's ``RecoveryTrigger``; "" before any)."""

    NONE = ""
    PLANNING = "PLANNING"
    CONTROLLING = "CONTROLLING"
    OSCILLATION = "OSCILLATION"
    PROGRESS = "PROGRESS"  # Nav2's progress checker: the robot stayed near one pose too long

    @property
    def abort_reason(self) -> str:
        """move_base's abort message when the recoveries are used up after this trigger (ROS's words)."""
        what = {"PLANNING": "Failed to find a valid plan.", "CONTROLLING": "Failed to find a valid control."}
        return what.get(self.value, "Robot is oscillating.") + " Even after executing recovery behaviors."


class GoalOutcome(StrEnum):
    """How a navigation trial's goal ended (lower-case, as results files write it); ``TIMEOUT``: navlab stopped
    waiting (and cancels the goal)."""

    SUCCEEDED = "succeeded"
    ABORTED = "aborted"
    PREEMPTED = "preempted"
    TIMEOUT = "timeout"

    @classmethod
    def of(cls, state: GoalState) -> GoalOutcome:
        """The outcome of a goal in ``state`` (a goal not yet finished: ``TIMEOUT``)."""
        return cls(state.lower()) if state in TERMINAL else cls.TIMEOUT


TERMINAL = frozenset({GoalState.SUCCEEDED, GoalState.ABORTED, GoalState.PREEMPTED})
# action_msgs/GoalStatus codes of the states a goal goes through
STATUS = {
    GoalState.PENDING: 1,
    GoalState.ACTIVE: 2,
    GoalState.PREEMPTED: 5,
    GoalState.SUCCEEDED: 4,
    GoalState.ABORTED: 6,
}


@dataclass
class GoalHandle:
    """One goal's life: ``state`` PENDING -> ACTIVE -> SUCCEEDED | ABORTED | PREEMPTED, with ``reason``."""

    goal: Pose
    frame_id: str
    id: int
    state: GoalState = GoalState.PENDING
    reason: str = ""
    start_s: float = 0.0
    end_s: float | None = None
    feedback: Callable[[Pose], None] | None = None
    on_done: Callable[[GoalHandle], None] | None = field(default=None, repr=False)

    def done(self) -> bool:
        """Whether the goal reached a terminal state."""
        return self.state in TERMINAL


def with_headings(xy: np.ndarray, goal_yaw: float) -> np.ndarray:
    """A plan (N, 3): each pose heads to the next one, the last takes the goal's yaw (as navfn's plan does)."""
    yaw = np.empty(len(xy))
    if len(xy) > 1:
        d = np.diff(xy, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
    yaw[-1] = goal_yaw
    return np.column_stack([xy, yaw])


def status_array(handle: GoalHandle | None) -> Any:
    """``action_msgs/GoalStatusArray`` of move_base's current goal (empty without one): its id in the UUID's first
    8 bytes (little-endian), its start stamp and its state's status code."""
    statuses = []
    if handle is not None:
        uuid = np.zeros(16, dtype=np.uint8)
        uuid[:8] = np.frombuffer(int(handle.id).to_bytes(8, "little"), dtype=np.uint8)
        info = msgs.GoalInfo(goal_id=msgs.UUID(uuid=uuid), stamp=msgs.time_from_ns(round(handle.start_s * 1e9)))
        statuses.append(msgs.GoalStatus(goal_info=info, status=STATUS[handle.state]))
    return msgs.GoalStatusArray(status_list=statuses)
