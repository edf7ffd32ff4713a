"""Deprecated alias (until the next release) of :mod:`navlab.world.truth`: a world's facts live with the world."""

import warnings

from navlab.deprecation import NavlabDeprecationWarning
from navlab.world import (  # noqa: F401 - re-exported for the old import path
    true_map,
    true_occupancy,
    truth_grid,
    unmapped_obstacles,
    visible_surface,
    world_T_map,
)

warnings.warn(
    "navlab.experiments.truth moved to navlab.world (navlab.world.truth); the old path works until the next release",
    NavlabDeprecationWarning,
    stacklevel=2,
)
