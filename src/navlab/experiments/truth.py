"""Deprecated alias (until the next release) of :mod:`navlab.world.truth`: a world's facts live with the world."""

import warnings

from navlab.deprecation import NavlabDeprecationWarning
from navlab.lazy import lazy_exports

_MOVED = ("true_map", "true_occupancy", "truth_grid", "unmapped_obstacles", "visible_surface", "world_T_map")
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_MOVED, "navlab.world.truth"))

warnings.warn(
    "navlab.experiments.truth moved to navlab.world (navlab.world.truth); the old path works until the next release",
    NavlabDeprecationWarning,
    stacklevel=2,
)
