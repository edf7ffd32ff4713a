"""Occupancy grids, map_server map files, and SLAM (GMapping-style RBPF and a pose-graph mode)."""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.grid import FREE, OCCUPIED, UNKNOWN, GridMap
    from navlab.mapping.errors import MappingError
    from navlab.mapping.mapfile import load_map, read_map_yaml, save_map, save_true_map
    from navlab.mapping.scanmatch import warmup
    from navlab.mapping.simlog import OdometryNoise, office_log, record_log
    from navlab.mapping.slam import run_offline, write_outputs
    from navlab.mapping.slam_node import SlamGMapping

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
    "OdometryNoise": "navlab.mapping.simlog",
    "SlamGMapping": "navlab.mapping.slam_node",
    "office_log": "navlab.mapping.simlog",
    "record_log": "navlab.mapping.simlog",
    "run_offline": "navlab.mapping.slam",
    "warmup": "navlab.mapping.scanmatch",
    "write_outputs": "navlab.mapping.slam",
}
__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "GridMap",
    "MappingError",
    "OdometryNoise",
    "SlamGMapping",
    "load_map",
    "office_log",
    "read_map_yaml",
    "record_log",
    "run_offline",
    "save_map",
    "save_true_map",
    "warmup",
    "write_outputs",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
