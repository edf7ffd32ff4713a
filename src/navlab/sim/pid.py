"""A PID controller as ROS's ``control_toolbox::Pid`` computes it (pure: numbers in, numbers out).

``command = p·e + i_term + d·ė`` where ``i_term`` accumulates ``i·e·dt`` and is clamped to
[``i_clamp_min``, ``i_clamp_max``] (``i_clamp`` sets both, symmetric, as ROS's ``i_clamp`` does), and
``ė`` is the error's rate (given, or differenced from the previous error). Units are the caller's: for
a wheel velocity loop the error is rad/s and the command a torque (N m). ``output_limit`` (> 0) clips
the command (a motor's torque limit); with ``antiwindup`` the integral stops growing while clipped.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from navlab.core import ParamSpec, param_error, read_params, typed_value
from navlab.sim.errors import SimError


@dataclass(frozen=True)
class PidGains:
    """``control_toolbox`` gains: p, i, d (>= 0) and the integral term's clamp (>= 0; 0 = no integral)."""

    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp_max: float = 0.0
    i_clamp_min: float = 0.0
    antiwindup: bool = False

    PARAMS: ClassVar[ParamSpec]

    def __post_init__(self) -> None:
        read_params(type(self), self)  # the ranges of PARAMS

    @classmethod
    def from_params(cls, params: Mapping[str, Any], *, where: str = "pid") -> PidGains:
        """Gains from ROS parameters ``{p, i, d, i_clamp}`` (or ``i_clamp_min``/``i_clamp_max``, ``antiwindup``):
        ``i_clamp`` (>= 0) sets the ends not given, symmetric, as ``control_toolbox`` does."""
        values = dict(params)
        if "i_clamp" in values:
            clamp = typed_value(float, "i_clamp", values.pop("i_clamp"), what=where, error=SimError)
            if not clamp >= 0:
                raise param_error(where, "i_clamp", clamp, ">= 0", SimError)
            values.setdefault("i_clamp_max", clamp)
            values.setdefault("i_clamp_min", -clamp)
        return read_params(cls, values, what=where)


PidGains.PARAMS = ParamSpec(
    "pid",
    SimError,
    at_least={"p": 0.0, "i": 0.0, "d": 0.0, "i_clamp_max": 0.0},
    at_most={"i_clamp_min": 0.0},
    strict=True,
)


class Pid:
    """One PID loop; ``compute(error, dt)`` returns the command. ``reset()`` clears the integral and history."""

    def __init__(self, gains: PidGains, *, output_limit: float = 0.0) -> None:
        if not (math.isfinite(output_limit) and output_limit >= 0):
            raise SimError(f"pid output_limit: expected a finite number >= 0 (0 = none), got {output_limit!r}")
        self.gains = gains
        self.output_limit = float(output_limit)
        self.i_term = 0.0
        self.p_error_last: float | None = None
        self.command = 0.0

    def reset(self) -> None:
        """Forget the integral and the last error."""
        self.i_term = 0.0
        self.p_error_last = None
        self.command = 0.0

    def compute(self, error: float, dt: float, error_dot: float | None = None) -> float:
        """The command for ``error`` after ``dt`` s (``dt`` <= 0 or non-finite input: 0, as ROS does)."""
        g = self.gains
        if dt <= 0 or not math.isfinite(error) or (error_dot is not None and not math.isfinite(error_dot)):
            return 0.0
        if error_dot is None:
            error_dot = 0.0 if self.p_error_last is None else (error - self.p_error_last) / dt
        self.p_error_last = error
        p_term = g.p * error
        i_prev = self.i_term
        self.i_term = min(max(self.i_term + g.i * error * dt, g.i_clamp_min), g.i_clamp_max)
        cmd = p_term + self.i_term + g.d * error_dot
        limit = self.output_limit
        if limit > 0 and abs(cmd) > limit:
            if g.antiwindup and abs(self.i_term) > abs(i_prev):
                self.i_term = i_prev  # clipped: do not wind the integral further
                cmd = p_term + self.i_term + g.d * error_dot
            cmd = max(-limit, min(limit, cmd))
        self.command = cmd
        return cmd
