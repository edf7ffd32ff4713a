"""Driving the robot by hand or by script: teleop_twist_keyboard's keys, a joystick, scripted routes.

- ``TeleopKeyboard``: teleop_twist_keyboard's bindings and defaults (speed 0.5 m/s, turn 1.0 rad/s).
  Keys come in through :meth:`TeleopKeyboard.press` (thread-safe), from a terminal or the viewer.
- ``RouteFollower``: a repeatable route for mapping runs, from a YAML file of velocity segments
  (``{linear, angular, duration}``) and/or waypoints (``[x, y]`` in the odom frame).
"""

from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, Publisher, TfError
from navlab.core.params import read_yaml
from navlab.mapping.errors import MappingError
from navlab.mapping.follow import PurePursuit

# teleop_twist_keyboard: key -> (x, y, z, th) direction, and key -> (speed, turn) multipliers.
MOVE_BINDINGS: dict[str, tuple[int, int, int, int]] = {
    "i": (1, 0, 0, 0), "o": (1, 0, 0, -1), "j": (0, 0, 0, 1), "l": (0, 0, 0, -1),
    "u": (1, 0, 0, 1), ",": (-1, 0, 0, 0), ".": (-1, 0, 0, 1), "m": (-1, 0, 0, -1),
    "O": (1, -1, 0, 0), "I": (1, 0, 0, 0), "J": (0, 1, 0, 0), "L": (0, -1, 0, 0),
    "U": (1, 1, 0, 0), "<": (-1, 0, 0, 0), ">": (-1, -1, 0, 0), "M": (-1, 1, 0, 0),
    "t": (0, 0, 1, 0), "b": (0, 0, -1, 0),
}  # fmt: skip
SPEED_BINDINGS: dict[str, tuple[float, float]] = {
    "q": (1.1, 1.1), "z": (0.9, 0.9), "w": (1.1, 1.0), "x": (0.9, 1.0), "e": (1.0, 1.1), "c": (1.0, 0.9),
}  # fmt: skip

HELP = """Moving around:   u i o / j k l / m , .
q/z: all speeds +/-10%   w/x: linear only   e/c: angular only
k or any other key: stop   CTRL-C: quit"""


@dataclass
class TeleopState:
    """The keyboard teleop's state: direction and speeds (teleop_twist_keyboard semantics)."""

    speed: float = 0.5
    turn: float = 1.0
    x: int = 0
    y: int = 0
    z: int = 0
    th: int = 0

    def key(self, k: str) -> None:
        """Apply one key press."""
        if k in MOVE_BINDINGS:
            self.x, self.y, self.z, self.th = MOVE_BINDINGS[k]
        elif k in SPEED_BINDINGS:
            s, t = SPEED_BINDINGS[k]
            self.speed *= s
            self.turn *= t
        else:
            self.x = self.y = self.z = self.th = 0

    def twist(self) -> Any:
        """The ``geometry_msgs/Twist`` this state commands."""
        t = msgs.twist(self.x * self.speed, self.th * self.turn, self.y * self.speed)
        t.linear.z = float(self.z * self.speed)
        return t


class TeleopKeyboard(Node):
    """Publishes ``cmd_vel`` from key presses, repeated at ``repeat_rate`` Hz while a key holds."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "teleop_twist_keyboard",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.state = TeleopState(self.declare_parameter("speed", 0.5), self.declare_parameter("turn", 1.0))
        rate = self.declare_parameter("repeat_rate", 10.0)
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self.create_timer(1.0 / rate, lambda: self.pub.publish(self.state.twist()))

    def press(self, key: str) -> None:
        """Thread-safe: apply a key press before the next event."""
        self.executor.post(lambda: self.state.key(key))


def terminal_keys(teleop: TeleopKeyboard, ex: Executor) -> threading.Thread:
    """Read single key presses from the terminal (cbreak mode) and hand them to the teleop node."""
    import sys
    import termios
    import tty

    def loop() -> None:
        fd = sys.stdin.fileno()
        old = termios.tcgetattr(fd)
        try:
            tty.setcbreak(fd)
            while True:
                ch = sys.stdin.read(1)
                if not ch or ch == "\x03":
                    ex.post(ex.stop)
                    return
                teleop.press(ch)
        finally:
            termios.tcsetattr(fd, termios.TCSADRAIN, old)

    t = threading.Thread(target=loop, daemon=True)
    t.start()
    return t


def load_route(path: str | Path) -> tuple[list[tuple[float, float, float]], np.ndarray]:
    """A route file (or a shipped route's name, ``room``): ``segments: [{linear, angular, duration}]`` and/or
    ``waypoints: [[x, y], ...]``."""
    text = str(path)
    if not Path(text).exists() and not Path(text).suffix and "/" not in text:
        from navlab import resources

        path = resources.route(text)
    data = read_yaml(path)
    if not isinstance(data, dict) or not ({"segments", "waypoints"} & set(data)):
        raise MappingError(f"{path}: a route file needs 'segments' and/or 'waypoints'")
    segments = []
    raw_segments = data.get("segments") or []
    if not isinstance(raw_segments, list):
        raise MappingError(f"{path}: segments: expected a list of {{linear, angular, duration}}, got {raw_segments!r}")
    for k, seg in enumerate(raw_segments):
        try:
            values = [seg.get("linear", 0.0), seg.get("angular", 0.0), seg["duration"]]
            if any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
                raise TypeError
            lin, ang, dur = (float(v) for v in values)
        except (KeyError, TypeError, ValueError, AttributeError):
            raise MappingError(f"{path}: segments[{k}]: expected {{linear, angular, duration}} numbers") from None
        if not (math.isfinite(lin) and math.isfinite(ang) and math.isfinite(dur) and dur > 0):
            raise MappingError(f"{path}: segments[{k}]: expected finite speeds and a duration > 0 s, got {seg!r}")
        segments.append((lin, ang, dur))
    raw = data.get("waypoints") or []
    if not isinstance(raw, list) or not all(
            isinstance(w, list) and len(w) == 2 and all(isinstance(v, int | float) and not isinstance(v, bool)
                                                       and math.isfinite(v) for v in w) for w in raw):
        raise MappingError(f"{path}: waypoints: expected a list of [x, y] pairs of finite numbers, got {raw!r}")
    return segments, np.array(raw, dtype=float).reshape(-1, 2)


class RouteFollower(Node):
    """Drives a scripted route: velocity segments first, then waypoints (pure pursuit, ``PurePursuit``).

    Parameters: ``segments`` (list of {linear, angular, duration}), ``waypoints`` (list of [x, y] in
    ``odom_frame``), ``base_frame``, ``odom_frame``, ``max_vel_x``, ``rate``, ``loop`` (drive the waypoints
    round and round), ``pose_topic`` (steer on a ``nav_msgs/Odometry`` topic such as
    ``/ground_truth/odom`` instead of tf; its frame is then the waypoints' frame), ``waypoint_tolerance``
    (m). ``done`` becomes True at the end of a route that does not loop.
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "route_follower",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        raw_segments = self.declare_parameter("segments", [])
        self.waypoints = np.array(self.declare_parameter("waypoints", []), dtype=float).reshape(-1, 2)
        self.base_frame = self.declare_parameter("base_frame", "chassis")
        self.odom_frame = self.declare_parameter("odom_frame", "odom")
        self.max_v = self.declare_parameter("max_vel_x", 0.3)
        self.loop = self.declare_parameter("loop", False)
        self.tolerance = self.declare_parameter("waypoint_tolerance", 0.1)
        pose_topic = self.declare_parameter("pose_topic", "")
        rate = self.declare_parameter("rate", 10.0)
        self.segments = [
            (float(s.get("linear", 0)), float(s.get("angular", 0)), float(s["duration"])) for s in raw_segments
        ]
        self.follower = PurePursuit(lookahead=0.05, max_vel_x=self.max_v, xy_goal_tolerance=0.0)
        self.done = False
        self.index = 0  # the waypoint driven to
        self._seg_end: int | None = None
        self._topic_pose: tuple[float, float, float] | None = None
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        if pose_topic:
            self.create_subscription(msgs.Odometry, pose_topic, self._on_pose, 10)
        self._use_topic = bool(pose_topic)
        self.create_timer(1.0 / rate, self._tick)

    def _on_pose(self, msg: Any) -> None:
        self._topic_pose = msgs.pose2d(msg.pose.pose)

    def _pose(self) -> tuple[float, float, float] | None:
        if self._use_topic:
            return self._topic_pose
        try:
            return self.executor.tf.lookup_pose2d(self.odom_frame, self.base_frame)
        except TfError:
            return None

    def _tick(self) -> None:
        if self.done:
            return
        now = self.executor.now_ns
        if self.segments:
            if self._seg_end is None:
                self._seg_end = now + round(self.segments[0][2] * 1e9)
            if now < self._seg_end:
                v, w, _ = self.segments[0]
                self.pub.publish(msgs.twist(v, w))
                return
            self.segments.pop(0)
            self._seg_end = None
            self._tick()
            return
        if self.index >= len(self.waypoints):
            if self.loop and len(self.waypoints):
                self.index = 0
            else:
                self.done = True
                self.pub.publish(msgs.twist(0.0, 0.0))
                return
        pose = self._pose()
        if pose is None:
            return
        target = self.waypoints[self.index]
        if math.hypot(target[0] - pose[0], target[1] - pose[1]) < self.tolerance:
            self.index += 1
            self._tick()
            return
        self.follower.set_plan(np.array([pose[:2], target]))
        self.pub.publish(msgs.twist(*self.follower.compute_velocity(pose)))


@dataclass
class JoyMapping:
    """teleop_twist_joy's parameters and defaults: which axes drive, their scales, the deadman button."""

    axis_linear: int = 1
    axis_angular: int = 0
    scale_linear: float = 0.5
    scale_angular: float = 0.5
    enable_button: int = 0
    require_enable_button: bool = True

    def twist(self, axes: list[float], buttons: list[int]) -> Any:
        """``geometry_msgs/Twist`` for one joystick reading (zero unless the enable button is held)."""
        enabled = not self.require_enable_button or (
            0 <= self.enable_button < len(buttons) and bool(buttons[self.enable_button])
        )
        if not enabled:
            return msgs.twist(0.0, 0.0)

        def axis(k: int) -> float:
            return float(axes[k]) if 0 <= k < len(axes) else 0.0

        # pygame's stick y axis is +1 when pulled back; ROS joy reports forward as +1
        return msgs.twist(-axis(self.axis_linear) * self.scale_linear, -axis(self.axis_angular) * self.scale_angular)


def joystick_thread(ex: Executor, pub: Publisher, mapping: JoyMapping, rate: float = 20.0) -> threading.Thread:
    """Read the first joystick with pygame and publish ``cmd_vel`` from it; a clear error without one."""
    import os
    import time

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    try:
        import pygame
    except ImportError:
        raise MappingError("joystick teleop needs pygame: pip install pygame") from None
    pygame.init()
    pygame.joystick.init()
    if pygame.joystick.get_count() == 0:
        raise MappingError("no joystick found (pygame sees none); use the keyboard: navlab teleop")
    joy = pygame.joystick.Joystick(0)
    joy.init()

    def loop() -> None:
        while True:
            pygame.event.pump()
            axes = [joy.get_axis(i) for i in range(joy.get_numaxes())]
            buttons = [joy.get_button(i) for i in range(joy.get_numbuttons())]
            msg = mapping.twist(axes, buttons)
            ex.post(functools.partial(pub.publish, msg))
            time.sleep(1.0 / rate)

    t = threading.Thread(target=loop, daemon=True)
    t.start()
    return t
