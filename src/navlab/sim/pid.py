"""A PID controller as ROS's ``control_toolbox::Pid`` computes it (pure: numbers in, numbers out).

``command = p·e + i_term + d·ė`` where ``i_term`` accumulates ``i·e·dt`` and is clamped to
[``i_clamp_min``, ``i_clamp_max``] (``i_clamp`` sets both, symmetric, as ROS's ``i_clamp`` does), and
``ė`` is the error's rate (given, or differenced from the previous error). Units are the caller's: for
a wheel velocity loop the error is rad/s and the command a torque (N m). ``output_limit`` (> 0) clips
the command (a motor's torque limit); with ``antiwindup`` the integral stops growing while clipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from navlab.errors import did_you_mean
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

    def __post_init__(self) -> None:
        for key in ("p", "i", "d", "i_clamp_max"):
            v = getattr(self, key)
            if not (isinstance(v, int | float) and math.isfinite(v) and v >= 0):
                raise SimError(f"pid gain {key}: expected a finite number >= 0, got {v!r}")
        if not (math.isfinite(self.i_clamp_min) and self.i_clamp_min <= 0):
            raise SimError(f"pid gain i_clamp_min: expected a finite number <= 0, got {self.i_clamp_min!r}")

    @classmethod
    def from_params(cls, params: dict[str, Any], *, where: str = "pid") -> PidGains:
        """Gains from ROS parameters ``{p, i, d, i_clamp}`` (or ``i_clamp_min``/``i_clamp_max``, ``antiwindup``)."""
        known = ("p", "i", "d", "i_clamp", "i_clamp_min", "i_clamp_max", "antiwindup")
        for key in params:
            if key not in known:
                hint = did_you_mean(key, known)
                raise SimError(f"{where}: unknown pid parameter '{key}'{hint} (known: {', '.join(known)})")
        values: dict[str, Any] = {}
        for key in ("p", "i", "d"):
            if key in params:
                values[key] = _number(params[key], f"{where}.{key}")
        clamp = _number(params.get("i_clamp", 0.0), f"{where}.i_clamp")
        if clamp < 0:
            raise SimError(f"{where}.i_clamp: expected a number >= 0, got {clamp!r}")
        values["i_clamp_max"] = _number(params.get("i_clamp_max", clamp), f"{where}.i_clamp_max")
        values["i_clamp_min"] = _number(params.get("i_clamp_min", -clamp), f"{where}.i_clamp_min")
        values["antiwindup"] = bool(params.get("antiwindup", False))
        try:
            return cls(**values)
        except SimError as exc:
            raise SimError(f"{where}: {exc}") from None


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SimError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


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
