"""Worlds: Gazebo-classic SDF ``.world`` files → :class:`WorldModel`, and their true 2-D occupancy.

>>> from navlab.world import load_world, occupancy
>>> world = load_world(navlab.resources.world("room"))
>>> grid = occupancy(world, 0.05, (-5.5, -4.5, 5.5, 4.5))

What the world knows for certain (:mod:`navlab.world.truth`: its true map and occupancy, where a SLAM map's
frame lies in it) is exported lazily, so importing the package loads no SciPy. (The rest is imported eagerly:
``occupancy`` is both a submodule and a function, which a lazy export would let the submodule shadow.)
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports
from navlab.world.errors import WorldError
from navlab.world.model import ModelSpec, WorldModel
from navlab.world.occupancy import extents, occupancy, shape_footprints
from navlab.world.sdf import load_model, load_world

if TYPE_CHECKING:
    from navlab.world.truth import (
        true_map,
        true_occupancy,
        truth_grid,
        unmapped_obstacles,
        visible_surface,
        world_T_map,
    )

_TRUTH = ("true_map", "true_occupancy", "truth_grid", "unmapped_obstacles", "visible_surface", "world_T_map")
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_TRUTH, "navlab.world.truth"))

__all__ = [
    "ModelSpec",
    "WorldError",
    "WorldModel",
    "extents",
    "load_model",
    "load_world",
    "occupancy",
    "shape_footprints",
    "true_map",
    "true_occupancy",
    "truth_grid",
    "unmapped_obstacles",
    "visible_surface",
    "world_T_map",
]
