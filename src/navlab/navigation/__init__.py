"""Navigation as ROS 1 move_base has it: costmap_2d layers, global planners (navfn, Theta*), controllers.

Subpackages: ``costmap`` (layers and the layered master grid), ``planners`` (global planners),
``controllers`` (local planners). Everything here is pure (numpy in, numpy out); nodes come later.
"""

from navlab.navigation.errors import NavigationError

__all__ = ["NavigationError"]
