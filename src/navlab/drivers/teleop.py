"""Driving the robot by hand: teleop_twist_keyboard's keys and a joystick (teleop_twist_joy).

``TeleopKeyboard``: teleop_twist_keyboard's bindings and defaults (speed 0.5 m/s, turn 1.0 rad/s). Keys come
in through :meth:`TeleopKeyboard.press` (thread-safe), from a terminal or the viewer.
"""

from __future__ import annotations

import contextlib
import functools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from navlab import msgs
from navlab.core import Executor, Node, Publisher
from navlab.drivers.errors import DriverError

# teleop_twist_keyboard: key -> (x, y, z, th) direction, and key -> (speed, turn) multipliers.
MOVE_BINDINGS: dict[str, tuple[int, int, int, int]] = {
    "i": (1, 0, 0, 0),
    "o": (1, 0, 0, -1),
    "j": (0, 0, 0, 1),
    "l": (0, 0, 0, -1),
    "u": (1, 0, 0, 1),
    ",": (-1, 0, 0, 0),
    ".": (-1, 0, 0, 1),
    "m": (-1, 0, 0, -1),
    "O": (1, -1, 0, 0),
    "I": (1, 0, 0, 0),
    "J": (0, 1, 0, 0),
    "L": (0, -1, 0, 0),
    "U": (1, 1, 0, 0),
    "<": (-1, 0, 0, 0),
    ">": (-1, -1, 0, 0),
    "M": (-1, 1, 0, 0),
    "t": (0, 0, 1, 0),
    "b": (0, 0, -1, 0),
}
SPEED_BINDINGS: dict[str, tuple[float, float]] = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1.0),
    "x": (0.9, 1.0),
    "e": (1.0, 1.1),
    "c": (1.0, 0.9),
}

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

    def show_status(self, pose: Callable[[], tuple[float, float, float]] | None = None, period: float = 0.25) -> None:
        """Every ``period`` simulated s, rewrite one status line in place on stderr: simulated time, the command
        being sent, the speeds and, with ``pose``, the robot's (x, y, yaw) in m and rad, as teleop_twist_keyboard
        prints its 'currently:' line."""
        import sys

        def show() -> None:
            st, tw = self.state, self.state.twist()
            where = ""
            if pose is not None:
                x, y, yaw = pose()
                where = f"  robot at ({x:.2f}, {y:.2f}, {yaw:.2f} rad)"
            sys.stderr.write(
                f"\rt={self.executor.now_ns / 1e9:7.1f} s  sending linear.x {tw.linear.x:+.2f} m/s  angular.z "
                f"{tw.angular.z:+.2f} rad/s  (currently: speed {st.speed:.2f} turn {st.turn:.2f}){where}  "
            )
            sys.stderr.flush()

        self.create_timer(period, show)


class TerminalKeys(threading.Thread):
    """Reads single key presses from the terminal (cbreak mode) and hands them to a teleop node.

    :meth:`close` (also on leaving a ``with`` block, and at exit) ends the reader and gives the terminal its
    settings back; end of input (the terminal closed) stops the executor."""

    def __init__(self, teleop: TeleopKeyboard, ex: Executor) -> None:
        import atexit
        import sys
        import termios
        import tty

        super().__init__(name="terminal_keys", daemon=True)
        self.teleop, self.ex = teleop, ex
        self.fd = sys.stdin.fileno()
        self._saved = termios.tcgetattr(self.fd)
        self._closing = threading.Event()
        tty.setcbreak(self.fd)  # keys one at a time, no echo; Ctrl-C still sends SIGINT (ISIG stays on)
        atexit.register(self.close)

    def run(self) -> None:
        import os
        import select

        while not self._closing.is_set():  # polled, not a blocking read: close() ends it within 0.1 s
            if not select.select([self.fd], [], [], 0.1)[0]:
                continue
            try:
                key = os.read(self.fd, 1)
            except OSError:  # the terminal hung up
                key = b""
            if key in (b"", b"\x03"):  # end of input, or Ctrl-C as a byte (a terminal without ISIG)
                self.ex.post(self.ex.stop)
                return
            if ch := key.decode(errors="ignore"):  # keys are ASCII; a byte of anything else is dropped
                self.teleop.press(ch)

    def close(self) -> None:
        """End the reader and restore the terminal (idempotent)."""
        import termios

        if self._closing.is_set():
            return
        self._closing.set()
        if self.is_alive() and self is not threading.current_thread():
            self.join(timeout=1.0)
        with contextlib.suppress(termios.error, OSError):  # the terminal may be gone (closed, hung up)
            termios.tcsetattr(self.fd, termios.TCSADRAIN, self._saved)

    def __enter__(self) -> TerminalKeys:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def terminal_keys(teleop: TeleopKeyboard, ex: Executor) -> TerminalKeys:
    """Read single key presses from the terminal (cbreak mode) and hand them to the teleop node; the reader,
    started (``with terminal_keys(...)``: the terminal is restored at the block's end; else at exit)."""
    keys = TerminalKeys(teleop, ex)
    keys.start()
    return keys


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
        raise DriverError("joystick teleop needs pygame: pip install pygame") from None
    pygame.init()
    pygame.joystick.init()
    if pygame.joystick.get_count() == 0:
        raise DriverError("no joystick found (pygame sees none); use the keyboard: navlab teleop")
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
