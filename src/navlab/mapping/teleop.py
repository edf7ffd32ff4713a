"""Deprecated (one release): teleop moved to ``navlab.drivers.teleop``, routes to ``navlab.drivers.routes``."""

from navlab.lazy import moved_exports

__getattr__ = moved_exports(
    __name__,
    {
        "HELP": "navlab.drivers.teleop",
        "MOVE_BINDINGS": "navlab.drivers.teleop",
        "SPEED_BINDINGS": "navlab.drivers.teleop",
        "TeleopState": "navlab.drivers.teleop",
        "TeleopKeyboard": "navlab.drivers.teleop",
        "terminal_keys": "navlab.drivers.teleop",
        "JoyMapping": "navlab.drivers.teleop",
        "joystick_thread": "navlab.drivers.teleop",
        "load_route": "navlab.drivers.routes",
        "RouteFollower": "navlab.drivers.routes",
    },
)
