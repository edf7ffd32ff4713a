"""rclpy's time types over navlab's simulated clock: ``Time`` (rclpy.time.Time) and ``Clock``."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

from navlab.msgs import time_from_ns

if TYPE_CHECKING:
    from navlab.core.executor import Executor

__all__ = ["Clock", "Time"]


@dataclasses.dataclass(frozen=True)
class Time:
    """``rclpy.time.Time``: an instant in (simulated) nanoseconds."""

    nanoseconds: int = 0
    seconds: dataclasses.InitVar[float | None] = None

    def __post_init__(self, seconds: float | None) -> None:
        if seconds is not None:
            object.__setattr__(self, "nanoseconds", self.nanoseconds + round(seconds * 1e9))

    def to_msg(self) -> Any:
        """As ``builtin_interfaces/Time``."""
        return time_from_ns(self.nanoseconds)

    def seconds_nanoseconds(self) -> tuple[int, int]:
        """(whole seconds, remaining nanoseconds)."""
        return divmod(self.nanoseconds, 1_000_000_000)

    @property
    def sec(self) -> int:
        """Whole seconds (the message's field)."""
        return self.nanoseconds // 1_000_000_000

    @property
    def nanosec(self) -> int:
        """Nanoseconds past ``sec`` (the message's field)."""
        return self.nanoseconds % 1_000_000_000


class Clock:
    """Simulated-time clock of an executor."""

    def __init__(self, executor: Executor) -> None:
        self._executor = executor

    def now_ns(self) -> int:
        """Current simulated time in nanoseconds."""
        return self._executor.now_ns

    def now(self) -> Time:
        """Current simulated time, as rclpy's ``Time`` (``.nanoseconds``, ``.to_msg()``; ``.sec``/``.nanosec``
        as the message has them)."""
        return Time(nanoseconds=self._executor.now_ns)

    def seconds(self) -> float:
        """Current simulated time in seconds."""
        return self._executor.now_ns / 1e9
