"""Occupancy grids, map_server map files, and SLAM (GMapping-style RBPF and a pose-graph mode)."""

from navlab.grid import FREE, OCCUPIED, UNKNOWN, GridMap
from navlab.mapping.errors import MappingError
from navlab.mapping.mapfile import load_map, read_map_yaml, save_map

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "GridMap", "MappingError", "load_map", "read_map_yaml", "save_map"]
