"""Worlds: Gazebo-classic SDF ``.world`` files → :class:`WorldModel`, and their true 2-D occupancy.

>>> from navlab.world import load_world, occupancy
>>> world = load_world(navlab.resources.world("room"))
>>> grid = occupancy(world, 0.05, (-5.5, -4.5, 5.5, 4.5))
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.world.errors import WorldError
    from navlab.world.model import ModelSpec, WorldModel
    from navlab.world.occupancy import extents, occupancy, shape_footprints
    from navlab.world.sdf import load_model, load_world

_EXPORTS = {
    "ModelSpec": "navlab.world.model",
    "WorldError": "navlab.world.errors",
    "WorldModel": "navlab.world.model",
    "extents": "navlab.world.occupancy",
    "load_model": "navlab.world.sdf",
    "load_world": "navlab.world.sdf",
    "occupancy": "navlab.world.occupancy",
    "shape_footprints": "navlab.world.occupancy",
}

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
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
