"""Worlds: Gazebo-classic SDF ``.world`` files → :class:`WorldModel`, and their true 2-D occupancy.

>>> from navlab.world import load_world, occupancy
>>> world = load_world(navlab.resources.world("room"))
>>> grid = occupancy(world, 0.05, (-5.5, -4.5, 5.5, 4.5))

(Imported eagerly: ``occupancy`` is both a submodule and a function, which a lazy export would let the
submodule shadow.)
"""

from navlab.world.errors import WorldError
from navlab.world.model import ModelSpec, WorldModel
from navlab.world.occupancy import extents, occupancy, shape_footprints
from navlab.world.sdf import load_model, load_world

__all__ = [
    "ModelSpec",
    "WorldError",
    "WorldModel",
    "extents",
    "load_model",
    "load_world",
    "occupancy",
    "shape_footprints",
]
