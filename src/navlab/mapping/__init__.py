"""Occupancy grids, map_server map files, and SLAM (GMapping-style RBPF and a pose-graph mode)."""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.grid import FREE, OCCUPIED, UNKNOWN, GridMap
    from navlab.mapping.errors import MappingError
    from navlab.mapping.mapfile import load_map, read_map_yaml, save_map, save_true_map

_EXPORTS = {
    "FREE": "navlab.grid",
    "GridMap": "navlab.grid",
    "MappingError": "navlab.mapping.errors",
    "OCCUPIED": "navlab.grid",
    "UNKNOWN": "navlab.grid",
    "load_map": "navlab.mapping.mapfile",
    "read_map_yaml": "navlab.mapping.mapfile",
    "save_map": "navlab.mapping.mapfile",
    "save_true_map": "navlab.mapping.mapfile",
}
__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "GridMap",
    "MappingError",
    "load_map",
    "read_map_yaml",
    "save_map",
    "save_true_map",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
