"""costmap_2d::StaticLayer: costs from the occupancy map on ``/map`` (see ``layer`` for the interface)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Self

import numpy as np

from navlab.core import read_params
from navlab.geometry import inverse_transform_points2
from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid, GridMap
from navlab.navigation.costmap.layer import Layer, costmap_of
from navlab.navigation.costmap.params import StaticLayerParams, layer_params
from navlab.plugins import PluginContext


class StaticLayer(Layer):
    """``costmap_2d::StaticLayer``: costs from an occupancy map (``nav_msgs/OccupancyGrid`` data, -1/0..100).

    ``trinary_costmap`` (default): occupancy >= ``lethal_cost_threshold`` is lethal, the rest free;
    otherwise costs scale as ``occupancy / lethal_cost_threshold * 254``. ``unknown_cost_value`` cells are
    unknown (255) with ``track_unknown_space``, else free. The layer overwrites the master where the map
    has cells (``use_maximum``: keeps the larger cost).
    """

    writes_master_only = True

    def __init__(self, params: StaticLayerParams | dict[str, Any] | None = None, *, name: str = "static_layer") -> None:
        self.params: StaticLayerParams = read_params(StaticLayerParams, params, what=name)
        self.name = name
        self.enabled = self.params.enabled
        self.map: GridMap | None = None
        self.costs: np.ndarray | None = None
        self.map_in_costmap = (0.0, 0.0, 0.0)
        # (geometry key, master cells, map cells, whether that is the identity) of the last master
        self._lookup: tuple[tuple[Any, ...], np.ndarray, np.ndarray, bool] | None = None

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        name = context.name or "static_layer"
        return cls(layer_params(StaticLayerParams, costmap_of(params, context), name), name=name)

    def interpret(self, occupancy: np.ndarray) -> np.ndarray:
        """Costs (uint8) of occupancy values (-1 unknown, 0..100 %) as costmap_2d's ``interpretValue``."""
        p = self.params
        v = np.asarray(occupancy).astype(np.int16)
        if p.trinary_costmap:
            costs = np.where(v >= p.lethal_cost_threshold, COST_LETHAL, COST_FREE).astype(np.uint8)
        else:
            scaled = np.clip(v, 0, None).astype(np.float64) / p.lethal_cost_threshold * COST_LETHAL
            costs = np.where(v >= p.lethal_cost_threshold, COST_LETHAL, scaled.astype(np.int64)).astype(np.uint8)
        unknown = (v & 0xFF) == (p.unknown_cost_value & 0xFF)  # ROS compares as unsigned char: -1 == 255
        costs[unknown] = COST_UNKNOWN if p.track_unknown_space else COST_FREE
        return costs

    def set_map(self, grid: GridMap, *, map_in_costmap: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        """Take a new map; ``map_in_costmap`` is the pose (x, y, yaw) of the map's frame in the costmap's frame
        (identity for a global costmap in ``map``; map->odom's inverse for a rolling one in ``odom``)."""
        self.map = grid
        self.costs = self.interpret(grid.data)
        mx, my, myaw = map_in_costmap
        self.map_in_costmap = (float(mx), float(my), float(myaw))
        self._lookup = None

    @property
    def map_topic(self) -> str:
        """The topic the map comes on (``map_topic``)."""
        return self.params.map_topic

    def on_map_obstacle(self, xy: tuple[float, float]) -> bool:
        """Whether ``xy`` (m, costmap frame) lies on a map cell at or above ``lethal_cost_threshold``."""
        if self.map is None:
            return False
        local = inverse_transform_points2(self.map_in_costmap, np.array([xy[:2]], dtype=np.float64))
        return int(self.map.value_at(local)[0]) >= self.params.lethal_cost_threshold

    def _cells(self, master: Grid) -> tuple[np.ndarray, np.ndarray]:
        """(flat master indices, flat map indices) of the master cells whose centres fall inside the map."""
        assert self.map is not None
        key = (master.data.shape, master.resolution, master.origin, self.map_in_costmap)
        if self._lookup is not None and self._lookup[0] == key:
            return self._lookup[1], self._lookup[2]
        h, w = master.data.shape
        jj, ii = np.mgrid[0:h, 0:w]
        ij = np.stack([ii.ravel(), jj.ravel()], axis=1)
        xy = master.cell_to_world(ij)
        tx, ty, tyaw = self.map_in_costmap
        if (tx, ty, tyaw) != (0.0, 0.0, 0.0):  # costmap frame -> map frame
            c, s = math.cos(tyaw), math.sin(tyaw)
            dx, dy = xy[:, 0] - tx, xy[:, 1] - ty
            xy = np.stack([c * dx + s * dy, -s * dx + c * dy], axis=1)
        src = self.map.world_to_cell(xy)
        ok = self.map.in_bounds(src)
        dst_flat = np.flatnonzero(ok)
        src_flat = src[ok, 1] * self.map.width + src[ok, 0]
        same = master.data.shape == self.map.data.shape and np.array_equal(dst_flat, src_flat)
        self._lookup = (key, dst_flat, src_flat, same and len(dst_flat) == master.data.size)
        return dst_flat, src_flat

    def update_costs(self, master: Grid) -> None:
        if self.map is None or self.costs is None:
            return
        dst, src = self._cells(master)
        if not self.params.use_maximum and self._lookup is not None and self._lookup[3]:
            np.copyto(master.data, self.costs)  # the master is the map, cell for cell
            return
        out = master.data.reshape(-1)
        vals = self.costs.reshape(-1)[src]
        if self.params.use_maximum:
            old = out[dst]
            take = (vals != COST_UNKNOWN) & ((old == COST_UNKNOWN) | (old < vals))
            out[dst[take]] = vals[take]
        else:
            out[dst] = vals

    def reset(self) -> None:
        """Keep the map: ROS re-reads the latched ``/map`` on reset, which is the same map."""
