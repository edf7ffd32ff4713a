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
    from navlab.world.clutter import (
        CYLINDER_RADIUS,
        FIELD,
        ClutterWorld,
        barn_score,
        clutter_suite,
        generate_clutter,
        suite_parameters,
    )
    from navlab.world.office import generate_office
    from navlab.world.summary import format_world, world_summary
    from navlab.world.truth import (
        true_map,
        true_occupancy,
        truth_grid,
        unmapped_obstacles,
        visible_surface,
        world_T_map,
    )

_EXPORTS = {
    "true_map": "navlab.world.truth",
    "true_occupancy": "navlab.world.truth",
    "truth_grid": "navlab.world.truth",
    "unmapped_obstacles": "navlab.world.truth",
    "visible_surface": "navlab.world.truth",
    "world_T_map": "navlab.world.truth",
    "CYLINDER_RADIUS": "navlab.world.clutter",
    "ClutterWorld": "navlab.world.clutter",
    "FIELD": "navlab.world.clutter",
    "barn_score": "navlab.world.clutter",
    "clutter_suite": "navlab.world.clutter",
    "format_world": "navlab.world.summary",
    "generate_clutter": "navlab.world.clutter",
    "generate_office": "navlab.world.office",
    "suite_parameters": "navlab.world.clutter",
    "world_summary": "navlab.world.summary",
}

__all__ = [
    "CYLINDER_RADIUS",
    "FIELD",
    "ClutterWorld",
    "ModelSpec",
    "WorldError",
    "WorldModel",
    "barn_score",
    "clutter_suite",
    "extents",
    "format_world",
    "generate_clutter",
    "generate_office",
    "load_model",
    "load_world",
    "occupancy",
    "shape_footprints",
    "suite_parameters",
    "true_map",
    "true_occupancy",
    "truth_grid",
    "unmapped_obstacles",
    "visible_surface",
    "world_T_map",
    "world_summary",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
