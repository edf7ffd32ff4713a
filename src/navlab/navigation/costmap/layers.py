"""costmap_2d's layers: static (from ``/map``), obstacle (marking and ray clearing from scans), inflation.

Each layer writes uint8 costs (0 free .. 252, 253 inscribed, 254 lethal, 255 unknown) into a master
``Grid`` (origin yaw 0, in the costmap's frame: ``map`` or ``odom``) in the order of ``plugins:``, the
way ROS 1's ``LayeredCostmap::updateMap`` calls ``updateCosts``. Positions are metres in the costmap
frame. Layers are pure: the node feeds them maps and scans and asks the layered costmap for an update.
"""

from __future__ import annotations

import math
from typing import Any, Self

import numba
import numpy as np

from navlab.grid import COST_FREE, COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid, GridMap
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.kernels import combine, inflate_box, lethal_changes, mark_returns
from navlab.navigation.costmap.params import (
    CostmapParams,
    InflationLayerParams,
    ObservationSource,
    ObstacleLayerParams,
    StaticLayerParams,
    layer_params,
)
from navlab.navigation.costmap.raytrace import clear_rays
from navlab.navigation.errors import NavigationError


def _params(cls: type, values: Any, name: str) -> Any:
    if values is None or isinstance(values, cls):
        return values if values is not None else cls()
    if isinstance(values, dict):
        return layer_params(cls, CostmapParams(namespaces={name: values}), name)
    raise NavigationError(f"{name}: parameters must be a dict or {cls.__name__}, got {type(values).__name__}")


def _same_geometry(a: Grid, b: Grid) -> bool:
    return a.data.shape == b.data.shape and a.resolution == b.resolution and a.origin == b.origin


class Layer:
    """A costmap_2d layer: ``match_size`` when the master changes geometry, ``update_origin`` when a rolling
    window moves, ``update_bounds`` with the robot pose each cycle, then ``update_costs`` into the master."""

    name: str = "layer"
    enabled: bool = True

    @classmethod
    def from_costmap_params(cls, name: str, costmap: CostmapParams, footprint: Footprint) -> Self:
        """The layer named ``name`` configured from a parsed costmap parameter set."""
        raise NotImplementedError

    def on_footprint_changed(self, footprint: Footprint) -> None:
        """The robot's (padded) footprint changed."""

    def match_size(self, master: Grid) -> None:
        """The master grid has a new size, resolution or origin (everything the layer holds is reset)."""

    def update_origin(self, master: Grid) -> None:
        """A rolling window moved the master's origin by whole cells; keep what overlaps."""
        self.match_size(master)

    def update_bounds(self, robot_pose: tuple[float, float, float]) -> None:
        """Called once per update with the robot pose (x, y, yaw) in the costmap frame."""

    def update_costs(self, master: Grid) -> None:
        """Write this layer's costs into ``master``."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget everything observed."""


# --- static -------------------------------------------------------------------------------------


class StaticLayer(Layer):
    """``costmap_2d::StaticLayer``: costs from an occupancy map (``nav_msgs/OccupancyGrid`` data, -1/0..100).

    ``trinary_costmap`` (default): occupancy >= ``lethal_cost_threshold`` is lethal, the rest free;
    otherwise costs scale as ``occupancy / lethal_cost_threshold * 254``. ``unknown_cost_value`` cells are
    unknown (255) with ``track_unknown_space``, else free. The layer overwrites the master where the map
    has cells (``use_maximum``: keeps the larger cost).
    """

    def __init__(self, params: StaticLayerParams | dict[str, Any] | None = None, *, name: str = "static_layer") -> None:
        self.params: StaticLayerParams = _params(StaticLayerParams, params, name)
        self.name = name
        self.enabled = self.params.enabled
        self.map: GridMap | None = None
        self.costs: np.ndarray | None = None
        self.map_in_costmap = (0.0, 0.0, 0.0)
        # (geometry key, master cells, map cells, whether that is the identity) of the last master
        self._lookup: tuple[tuple[Any, ...], np.ndarray, np.ndarray, bool] | None = None

    @classmethod
    def from_costmap_params(cls, name: str, costmap: CostmapParams, footprint: Footprint) -> Self:
        return cls(layer_params(StaticLayerParams, costmap, name), name=name)

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


# --- obstacles ----------------------------------------------------------------------------------


class ObstacleLayer(Layer):
    """``costmap_2d::ObstacleLayer``: marks scan endpoints nearer than ``obstacle_range`` as lethal and clears
    the cells along each ray up to ``raytrace_range`` (Bresenham, Numba); clears the cells under the robot's
    footprint (``footprint_clearing_enabled``); combines into the master by maximum (``combination_method``
    1, unknown cells of the layer skipped) or overwrite (0). Call :meth:`match_size` (the layered costmap
    does) before :meth:`add_scan`.
    """

    def __init__(
        self,
        params: ObstacleLayerParams | dict[str, Any] | None = None,
        *,
        name: str = "obstacle_layer",
        sources: dict[str, ObservationSource] | None = None,
        footprint: Footprint | None = None,
    ) -> None:
        self.params: ObstacleLayerParams = _params(ObstacleLayerParams, params, name)
        self.name = name
        self.enabled = self.params.enabled
        self.sources = dict(sources or {})
        self.footprint = footprint or make_footprint()
        self.grid: Grid | None = None
        self.robot_pose: tuple[float, float, float] | None = None

    @classmethod
    def from_costmap_params(cls, name: str, costmap: CostmapParams, footprint: Footprint) -> Self:
        params = layer_params(ObstacleLayerParams, costmap, name)
        names = (params.observation_sources or costmap.observation_sources).split()
        return cls(params, name=name, sources={n: costmap.sources[n] for n in names if n in costmap.sources},
                   footprint=footprint)

    @property
    def default_value(self) -> int:
        """What a never-observed cell holds: unknown with ``track_unknown_space``, else free."""
        return COST_UNKNOWN if self.params.track_unknown_space else COST_FREE

    def on_footprint_changed(self, footprint: Footprint) -> None:
        self.footprint = footprint

    def match_size(self, master: Grid) -> None:
        data = np.full(master.data.shape, self.default_value, dtype=np.uint8)
        self.grid = Grid(data, master.resolution, master.origin, master.frame_id)

    def update_origin(self, master: Grid) -> None:
        old = self.grid
        if old is None or old.data.shape != master.data.shape or old.resolution != master.resolution:
            self.match_size(master)
            return
        shift = np.rint((np.array(master.origin[:2]) - np.array(old.origin[:2])) / master.resolution).astype(int)
        di, dj = int(shift[0]), int(shift[1])
        h, w = old.data.shape
        new = np.full((h, w), self.default_value, dtype=np.uint8)
        # new cell (i, j) is old cell (i + di, j + dj)
        i0, i1 = max(0, -di), min(w, w - di)
        j0, j1 = max(0, -dj), min(h, h - dj)
        if i0 < i1 and j0 < j1:
            new[j0:j1, i0:i1] = old.data[j0 + dj : j1 + dj, i0 + di : i1 + di]
        self.grid = Grid(new, master.resolution, master.origin, master.frame_id)

    def _source_settings(self, source: str | None) -> ObservationSource:
        p = self.params
        if source is None:
            return ObservationSource(marking=True, clearing=True, obstacle_range=p.obstacle_range,
                                     raytrace_range=p.raytrace_range, obstacle_min_range=p.obstacle_min_range,
                                     raytrace_min_range=p.raytrace_min_range)
        if source not in self.sources:
            known = ", ".join(self.sources) or "none"
            raise NavigationError(f"{self.name}: unknown observation source {source!r} (sources: {known})")
        return self.sources[source]

    def add_scan(
        self,
        origin_xy: tuple[float, float] | np.ndarray,
        endpoints_xy: np.ndarray,
        valid: np.ndarray | None = None,
        *,
        source: str | None = None,
    ) -> None:
        """Apply one scan in the costmap frame: the sensor at ``origin_xy`` (m) and ray endpoints (N, 2) (m).

        ``valid`` (N,) marks real returns; the others (max-range rays, inf projected to a distance) only clear.
        Without ``source`` the layer's own ranges apply and the scan both marks and clears; with a source name
        its ``marking``, ``clearing`` and ranges apply. Clearing runs first, then marking.
        """
        if self.grid is None:
            raise NavigationError(f"{self.name}: no grid yet; call match_size(master) before add_scan")
        pts = np.asarray(endpoints_xy, dtype=np.float64).reshape(-1, 2)
        ok = np.ones(len(pts), bool) if valid is None else np.asarray(valid, bool).reshape(-1)
        if len(ok) != len(pts):
            raise NavigationError(f"{self.name}.add_scan: valid has {len(ok)} entries for {len(pts)} endpoints")
        o = np.asarray(origin_xy, dtype=np.float64).reshape(-1)[:2]
        if not np.isfinite(o).all():
            raise NavigationError(f"{self.name}.add_scan: sensor origin must be finite, got {o.tolist()}")
        src = self._source_settings(source)
        g = self.grid
        res, (ox, oy, _) = g.resolution, g.origin
        finite = np.isfinite(pts).all(axis=1)
        if src.clearing:
            cells = (pts[finite] - (ox, oy)) / res
            clear_rays(g.data, (o[0] - ox) / res, (o[1] - oy) / res, np.ascontiguousarray(cells),
                       src.raytrace_range / res, src.raytrace_min_range / res, np.uint8(COST_FREE))
        if src.marking:
            mark_returns(g.data, pts, ok, float(o[0]), float(o[1]), ox, oy, res, src.obstacle_min_range,
                         src.obstacle_range, np.uint8(COST_LETHAL))

    def update_bounds(self, robot_pose: tuple[float, float, float]) -> None:
        self.robot_pose = (float(robot_pose[0]), float(robot_pose[1]), float(robot_pose[2]))

    def update_costs(self, master: Grid) -> None:
        if self.grid is None:
            return
        if not _same_geometry(self.grid, master):
            self.update_origin(master)
        g = self.grid
        if self.params.footprint_clearing_enabled and self.robot_pose is not None:
            ij = self.footprint.cells(g, self.robot_pose)
            g.data[ij[:, 1], ij[:, 0]] = COST_FREE
        combine(master.data, g.data, self.params.combination_method != 0)

    def reset(self) -> None:
        if self.grid is not None:
            self.grid.data[:] = self.default_value


# --- inflation ----------------------------------------------------------------------------------


class InflationLayer(Layer):
    """``costmap_2d::InflationLayer``: costs falling off with the distance ``d`` (m) to the nearest lethal cell.

    254 on the obstacle, 253 for ``d <= inscribed_radius`` (the robot's centre there means a collision),
    ``floor(252 * exp(-cost_scaling_factor * (d - inscribed_radius)))`` for ``inscribed < d <=
    inflation_radius`` (ROS's ``(INSCRIBED_INFLATED_OBSTACLE - 1) * factor``), nothing beyond. Distances are
    exact Euclidean distances between cell centres (a distance transform). A cell keeps the larger of its
    cost and the inflation; an unknown cell is overwritten only by inscribed or lethal costs (by any positive
    inflation cost with ``inflate_unknown``).
    """

    def __init__(
        self,
        params: InflationLayerParams | dict[str, Any] | None = None,
        *,
        name: str = "inflation_layer",
        footprint: Footprint | None = None,
    ) -> None:
        self.params: InflationLayerParams = _params(InflationLayerParams, params, name)
        self.name = name
        self.enabled = self.params.enabled
        self.footprint = footprint or make_footprint()
        # the last inflation: ((origin, resolution, shape), lethal seeds, costs over the whole grid)
        self._inflated: tuple[Any, np.ndarray, np.ndarray] | None = None
        self._costs: tuple[Any, np.ndarray] | None = None  # cost by squared cell distance (see _table)

    @classmethod
    def from_costmap_params(cls, name: str, costmap: CostmapParams, footprint: Footprint) -> Self:
        return cls(layer_params(InflationLayerParams, costmap, name), name=name, footprint=footprint)

    @property
    def inscribed_radius(self) -> float:
        """The padded footprint's inscribed radius (m)."""
        return self.footprint.inscribed_radius

    def on_footprint_changed(self, footprint: Footprint) -> None:
        self.footprint = footprint
        self._inflated = None

    def cost_at(self, distance_m: np.ndarray | float) -> np.ndarray:
        """Inflation cost (uint8) at ``distance_m`` (m) from the nearest obstacle cell's centre (0 = on it)."""
        d = np.asarray(distance_m, dtype=np.float64)
        r_in = self.inscribed_radius
        with np.errstate(over="ignore"):
            decay = np.floor((COST_INSCRIBED - 1) * np.exp(-self.params.cost_scaling_factor * (d - r_in)))
        cost = np.where(d <= r_in, COST_INSCRIBED, np.clip(decay, 0, COST_INSCRIBED - 1))
        cost = np.where(d > self.params.inflation_radius + 1e-9, 0, cost)
        return np.where(d <= 0.0, COST_LETHAL, cost).astype(np.uint8)

    def _table(self, resolution: float, reach: int) -> np.ndarray:
        """Costs (uint8) by squared distance in cells, 0 .. reach² (0 from there on): ``cost_at`` of the distance
        a distance transform gives (sqrt of the squared cell distance, times the resolution)."""
        key = (resolution, reach, self.params.inflation_radius, self.params.cost_scaling_factor,
               self.inscribed_radius)
        if self._costs is None or self._costs[0] != key:
            d2 = np.arange(reach * reach + 1, dtype=np.float64)
            self._costs = (key, self.cost_at(np.sqrt(d2) * resolution))
        return self._costs[1]

    def update_costs(self, master: Grid) -> None:
        data = master.data
        reach = math.ceil(self.params.inflation_radius / master.resolution) + 1
        reach = min(reach, math.ceil(math.hypot(*data.shape)) + 1)  # no cell is further: the table stays grid-sized
        key = (master.origin, master.resolution, data.shape)
        cached = self._inflated
        fresh = cached is None or cached[0] != key
        seeds = np.empty(data.shape, dtype=np.bool_)
        previous = np.zeros((0, 0), np.bool_) if fresh or cached is None else cached[1]  # none: every seed is new
        count, *changed = lethal_changes(data, np.uint8(COST_LETHAL), seeds, previous)
        if count == 0:
            return
        cost = self._inflation(master, seeds, reach, key, changed)
        _merge(data, cost, bool(self.params.inflate_unknown))

    def _inflation(self, master: Grid, seeds: np.ndarray, reach: int, key: Any, changed: list[int]) -> np.ndarray:
        """Inflation costs (uint8, the master's shape; 0 beyond ``inflation_radius``) of the lethal ``seeds``.

        A cell's cost depends only on the seeds within ``reach`` cells of it, so after the first update only
        the cells within ``reach`` of a seed that appeared or vanished (``changed``: their bounding rows and
        columns) are recomputed, from the seeds within ``reach`` of those (exactly what a transform of the whole
        grid gives them)."""
        cached = self._inflated
        if cached is None or cached[0] != key:
            cost = np.zeros(seeds.shape, dtype=np.uint8)
        else:
            cost = cached[2]
            if changed[1] == 0:
                return cost  # the same obstacles as last update: the same inflation (skips the transform)
        h, w = seeds.shape
        j0, j1 = max(0, changed[0] - reach), min(h, changed[1] + reach)
        i0, i1 = max(0, changed[2] - reach), min(w, changed[3] + reach)
        o0, o1 = max(0, j0 - reach), min(h, j1 + reach)
        p0, p1 = max(0, i0 - reach), min(w, i1 + reach)
        if seeds[o0:o1, p0:p1].any():  # the squared distance (cells) to each cell's nearest seed, its cost
            inflate_box(seeds, (o0, o1, p0, p1), (j0, j1, i0, i1), self._table(master.resolution, reach),
                        cost[j0:j1, i0:i1])
        else:  # no obstacle within reach of the box: nothing to inflate there
            cost[j0:j1, i0:i1] = 0
        self._inflated = (key, seeds, cost)
        return cost


@numba.njit(cache=True)
def _merge(data: np.ndarray, cost: np.ndarray, inflate_unknown: bool) -> None:  # pragma: no cover - compiled
    """Inflation into the master: the larger cost; an unknown cell only takes inscribed or lethal costs (any
    positive cost with ``inflate_unknown``)."""
    for j in range(data.shape[0]):
        for i in range(data.shape[1]):
            d, c = data[j, i], cost[j, i]
            if d == COST_UNKNOWN:
                if c >= COST_INSCRIBED or (inflate_unknown and c > COST_FREE):
                    data[j, i] = c
            elif c > d:
                data[j, i] = c
