"""What drives a robot without move_base: frontier exploration, keyboard/joystick teleop, scripted routes.

The drivers sit above navigation and use its costmap layers, planner heap and pure pursuit controller.
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.drivers.errors import DriverError
    from navlab.drivers.explore import Explore
    from navlab.drivers.frontiers import exploration_costmap, find_frontiers, plan_to_frontier
    from navlab.drivers.routes import RouteFollower, load_route
    from navlab.drivers.teleop import (
        HELP,
        MOVE_BINDINGS,
        SPEED_BINDINGS,
        JoyMapping,
        TeleopKeyboard,
        TeleopState,
        joystick_thread,
        terminal_keys,
    )

_EXPORTS = {
    "HELP": "navlab.drivers.teleop",
    "MOVE_BINDINGS": "navlab.drivers.teleop",
    "SPEED_BINDINGS": "navlab.drivers.teleop",
    "exploration_costmap": "navlab.drivers.frontiers",
    "joystick_thread": "navlab.drivers.teleop",
    "terminal_keys": "navlab.drivers.teleop",
    "DriverError": "navlab.drivers.errors",
    "Explore": "navlab.drivers.explore",
    "JoyMapping": "navlab.drivers.teleop",
    "RouteFollower": "navlab.drivers.routes",
    "TeleopKeyboard": "navlab.drivers.teleop",
    "TeleopState": "navlab.drivers.teleop",
    "find_frontiers": "navlab.drivers.frontiers",
    "load_route": "navlab.drivers.routes",
    "plan_to_frontier": "navlab.drivers.frontiers",
}
__all__ = [
    "HELP",
    "MOVE_BINDINGS",
    "SPEED_BINDINGS",
    "DriverError",
    "Explore",
    "JoyMapping",
    "RouteFollower",
    "TeleopKeyboard",
    "TeleopState",
    "exploration_costmap",
    "find_frontiers",
    "joystick_thread",
    "load_route",
    "plan_to_frontier",
    "terminal_keys",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
