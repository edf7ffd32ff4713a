"""Nav2's velocity smoother (``nav2_velocity_smoother``): commands within the robot's speed and acceleration limits.

At ``smoothing_frequency`` Hz the latest command (``cmd_vel``) is clamped to [``min_velocity``,
``max_velocity``] and moved toward from the last output no faster than ``max_accel`` (speeding up) and
``max_decel`` (slowing down) allow (``[x, y, theta]`` each, m/s, m/s², rad/s, rad/s²); with
``scale_velocities`` the axes are slowed together so the command keeps its curvature. ``feedback``
``OPEN_LOOP`` starts from the last output, ``CLOSED_LOOP`` from the odometry's velocity. Below
``deadband_velocity`` an axis is 0; after ``velocity_timeout`` s without a command the output ramps to a stop.
The output goes to ``cmd_vel_smoothed``. :class:`VelocitySmoother` is the algorithm (pure);
:class:`VelocitySmootherNode` the node. Nav2's names and defaults.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

from navlab import msgs
from navlab.core import Executor, Node, ParamSpec, read_params
from navlab.navigation.errors import NavigationError


@dataclass
class SmootherParams:
    """nav2_velocity_smoother's parameters ([x, y, theta] lists)."""

    PARAMS: ClassVar[ParamSpec] = ParamSpec("velocity_smoother", NavigationError)
    smoothing_frequency: float = 20.0
    scale_velocities: bool = False
    feedback: str = "OPEN_LOOP"
    max_velocity: list[float] = field(default_factory=lambda: [0.5, 0.0, 2.5])
    min_velocity: list[float] = field(default_factory=lambda: [-0.5, 0.0, -2.5])
    max_accel: list[float] = field(default_factory=lambda: [2.5, 0.0, 3.2])
    max_decel: list[float] = field(default_factory=lambda: [-2.5, 0.0, -3.2])
    deadband_velocity: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    velocity_timeout: float = 1.0
    odom_topic: str = "odom"
    odom_duration: float = 0.1

    def validate(self) -> None:
        """One-line errors for values the smoother cannot use."""
        if self.smoothing_frequency <= 0:
            raise NavigationError(
                f"velocity_smoother parameter smoothing_frequency: expected > 0 Hz, got {self.smoothing_frequency}"
            )
        if self.feedback not in ("OPEN_LOOP", "CLOSED_LOOP"):
            raise NavigationError(
                f"velocity_smoother parameter feedback: expected OPEN_LOOP or CLOSED_LOOP, got {self.feedback!r}"
            )
        for key in ("max_velocity", "min_velocity", "max_accel", "max_decel", "deadband_velocity"):
            if len(getattr(self, key)) != 3:
                raise NavigationError(
                    f"velocity_smoother parameter {key}: expected [x, y, theta], got {getattr(self, key)!r}"
                )
        if any(a <= 0 for a in (self.max_accel[0], self.max_accel[2])) or any(
            d >= 0 for d in (self.max_decel[0], self.max_decel[2])
        ):
            raise NavigationError(
                "velocity_smoother parameters max_accel (> 0) and max_decel (< 0) expected for x "
                f"and theta, got {self.max_accel} and {self.max_decel}"
            )


class VelocitySmoother:
    """The smoothing rule of ``nav2_velocity_smoother`` for a planar base (x and theta; y is 0)."""

    def __init__(self, params: dict[str, Any] | SmootherParams | None = None) -> None:
        self.params = read_params(SmootherParams, params)
        self.last = (0.0, 0.0)

    def _limits(self, axis: int, current: float, target: float, dt: float) -> float:
        """How far (signed) the axis may move toward ``target`` from ``current`` in ``dt`` s."""
        p = self.params
        speeding_up = abs(target) > abs(current) and target * current >= 0
        rate = p.max_accel[axis] if speeding_up else -p.max_decel[axis]
        return max(-rate * dt, min(rate * dt, target - current))

    def step(
        self, target: tuple[float, float], dt: float, current: tuple[float, float] | None = None
    ) -> tuple[float, float]:
        """The next (v, w) toward ``target`` after ``dt`` s, from ``current`` (CLOSED_LOOP) or the last output."""
        p = self.params
        now = self.last if current is None else current
        goal = [
            min(max(target[0], p.min_velocity[0]), p.max_velocity[0]),
            min(max(target[1], p.min_velocity[2]), p.max_velocity[2]),
        ]
        dv = self._limits(0, now[0], goal[0], dt)
        dw = self._limits(2, now[1], goal[1], dt)
        if p.scale_velocities:  # slow both axes by the most limited one's ratio (keeps the curvature)
            ratios = [d / (g - c) for d, g, c in ((dv, goal[0], now[0]), (dw, goal[1], now[1])) if abs(g - c) > 1e-9]
            k = min(ratios, default=1.0)
            dv, dw = (goal[0] - now[0]) * k, (goal[1] - now[1]) * k
        v, w = now[0] + dv, now[1] + dw
        v = 0.0 if abs(v) < p.deadband_velocity[0] else v
        w = 0.0 if abs(w) < p.deadband_velocity[2] else w
        self.last = (v, w)
        return self.last


def as_list(value: Any) -> Any:
    """A launch file's list given as text (``"[2.0, 0.0, 2.5]"``) as the list; anything else as it is."""
    if isinstance(value, str) and value.strip().startswith("["):
        import yaml

        return yaml.safe_load(value)
    return value


class VelocitySmootherNode(Node):
    """``nav2_velocity_smoother``'s node: ``cmd_vel`` in, ``cmd_vel_smoothed`` out at ``smoothing_frequency``."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "velocity_smoother",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        values = {k: as_list(self.declare_parameter(k, v)) for k, v in vars(SmootherParams()).items()}
        self.smoother = VelocitySmoother(values)
        self.check_parameters()
        p = self.smoother.params
        self.target: tuple[float, float] | None = None
        self.target_ns = 0
        self.odom_velocity = (0.0, 0.0)
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel_smoothed", 1)
        self.create_subscription(msgs.Twist, "cmd_vel", self._on_cmd, 1)
        if p.feedback == "CLOSED_LOOP":
            self.create_subscription(msgs.Odometry, p.odom_topic, self._on_odom, 1)
        self.create_timer(1.0 / p.smoothing_frequency, self._tick)

    def _on_cmd(self, msg: Any) -> None:
        self.target = (float(msg.linear.x), float(msg.angular.z))
        self.target_ns = self.executor.now_ns

    def _on_odom(self, msg: Any) -> None:
        t = msg.twist.twist
        self.odom_velocity = (float(t.linear.x), float(t.angular.z))

    def _tick(self) -> None:
        p = self.smoother.params
        if self.target is None:
            return
        if (self.executor.now_ns - self.target_ns) / 1e9 > p.velocity_timeout:
            self.target = (0.0, 0.0)  # Nav2: no command for velocity_timeout s -> stop (within the decel limits)
            if self.smoother.last == (0.0, 0.0):
                self.target = None
                self.pub.publish(msgs.twist(0.0, 0.0))
                return
        current = self.odom_velocity if p.feedback == "CLOSED_LOOP" else None
        v, w = self.smoother.step(self.target, 1.0 / p.smoothing_frequency, current)
        self.pub.publish(msgs.twist(v, w))
