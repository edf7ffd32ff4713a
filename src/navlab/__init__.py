"""navlab: the paper's ROS/Gazebo mobile-robot stack (simulation, SLAM, AMCL, navigation) in one Python package.

The same pipeline as the ``navlab`` command, as a library. Map the paper's room in a notebook::

    import navlab
    from navlab.mapping import save_map

    session = navlab.launch("mapping", world="room")   # simulator + slam_gmapping + frontier exploration
    session.run(60.0)                                   # 60 simulated seconds, as fast as the CPU allows
    slam = session.node("slam_gmapping")
    save_map(slam.current_map(), "room.yaml")           # room.yaml + room.pgm, as map_saver writes them
    x, y, yaw = session.executor.tf.lookup_pose2d("map", "chassis")
    print(f"robot at ({x:.2f}, {y:.2f}) m, {yaw:.2f} rad; {slam.scans_processed} scans mapped")

Top-level names (imported on first use, so ``import navlab`` stays light and loads no physics):

- ``navlab.launch(name_or_file, **args)``: start a launch, a shipped name (``sim``, ``mapping``,
  ``localization``, ``talker_listener``) or a ``.launch.yaml`` file, with its arguments as keywords
  (``map="room.yaml"``); ``seed=`` and ``rate=`` (0 = as fast as possible, 1 = real time) set the run.
  Returns a ``Session``: ``.run(seconds)``, ``.node(name)``, ``.executor`` (``run_until``, ``tf``, ...).
  This is ``navlab.core.launch.start``.
- ``navlab.Executor`` and ``navlab.Node``: the rclpy-like runtime for your own nodes
  (``create_publisher``, ``create_subscription``, ``create_timer``; see docs/core-api.md), with rclpy's
  module functions ``navlab.init`` (``rclpy.init``; ``launch=`` starts a launch in the context),
  ``navlab.shutdown``, ``navlab.ok``, ``navlab.spin``, ``navlab.spin_once``, ``navlab.create_node`` and
  ``navlab.Parameter``; ``navlab.install_ros_imports()`` makes ``from geometry_msgs.msg import Twist`` and
  ``import rclpy`` work without ROS (a real installation is found first).
- ``navlab.msgs``: the ROS 2 message types (``msgs.Twist``, ``msgs.LaserScan``, ...) and helpers
  (``msgs.twist(v, w)``, ``msgs.pose2d(pose)``).
- ``navlab.__version__``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from navlab import msgs
    from navlab.core import Executor, Node
    from navlab.core.launch import start as launch
    from navlab.core.node import Parameter
    from navlab.core.rclpy_api import create_node, init, ok, shutdown, spin, spin_once
    from navlab.core.ros_imports import install as install_ros_imports

__all__ = [
    "Executor",
    "Node",
    "Parameter",
    "__version__",
    "create_node",
    "init",
    "install_ros_imports",
    "launch",
    "msgs",
    "ok",
    "shutdown",
    "spin",
    "spin_once",
]

# name -> (module, attribute or None for the module itself)
_LAZY: dict[str, tuple[str, str | None]] = {
    "launch": ("navlab.core.launch", "start"),
    "Executor": ("navlab.core", "Executor"),
    "Node": ("navlab.core", "Node"),
    "msgs": ("navlab.msgs", None),
    "Parameter": ("navlab.core.node", "Parameter"),
    "init": ("navlab.core.rclpy_api", "init"),
    "shutdown": ("navlab.core.rclpy_api", "shutdown"),
    "ok": ("navlab.core.rclpy_api", "ok"),
    "spin": ("navlab.core.rclpy_api", "spin"),
    "spin_once": ("navlab.core.rclpy_api", "spin_once"),
    "create_node": ("navlab.core.rclpy_api", "create_node"),
    "install_ros_imports": ("navlab.core.ros_imports", "install"),
}


def __getattr__(name: str) -> Any:
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("navlab")
        except PackageNotFoundError:  # running from a source tree that was never installed
            return "0+unknown"
    if name not in _LAZY:
        raise AttributeError(f"module 'navlab' has no attribute {name!r}")
    module, attr = _LAZY[name]
    value = importlib.import_module(module)
    if attr is not None:
        value = getattr(value, attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
