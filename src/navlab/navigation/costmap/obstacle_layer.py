"""costmap_2d::ObstacleLayer: marking and ray clearing from laser scans (see ``layer`` for the interface)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Self

import numpy as np

from navlab.core import read_params
from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.hidden_cells import hidden_costs, mark_shadows, write_hidden
from navlab.navigation.costmap.kernels import combine, mark_returns
from navlab.navigation.costmap.layer import Layer, costmap_of, origin_shift, same_geometry, shifted
from navlab.navigation.costmap.params import ObservationSource, ObstacleLayerParams, layer_params
from navlab.navigation.costmap.raytrace import clear_rays, observe_ranges
from navlab.navigation.errors import NavigationError
from navlab.plugins import PluginContext


def observation_layer_args(
    params: Mapping[str, Any] | None, context: PluginContext, kind: type[ObstacleLayerParams]
) -> dict[str, Any]:
    """The constructor arguments of an obstacle or voxel layer named ``context.name`` (its ``plugins:`` name) from
    its namespace ``params`` (ROS names, read as ``kind``), in the costmap ``context.costmap`` (its observation
    sources: the layer's ``observation_sources``, else the costmap's) with the padded ``context.footprint``."""
    name = context.name or "obstacle_layer"
    costmap = costmap_of(params, context)
    settings = layer_params(kind, costmap, name)
    names = (settings.observation_sources or costmap.observation_sources).split()
    return {
        "params": settings,
        "name": name,
        "sources": {n: costmap.sources[n] for n in names if n in costmap.sources},
        "footprint": context.footprint if isinstance(context.footprint, Footprint) else None,
    }


class ObservationLayer(Layer):
    """What costmap_2d's ObstacleLayer and VoxelLayer share: a grid of the master's geometry kept across rolling
    window moves, observation sources by name, footprint clearing, and the combination into the master
    (``combination_method`` 1: maximum, unknown cells of the layer skipped; 0: overwrite). Subclasses add how
    observations mark and clear (and any per-cell state beside the costs: :meth:`_reset_cells`, :meth:`_shift`)."""

    params: ObstacleLayerParams
    params_class: type[ObstacleLayerParams] = ObstacleLayerParams

    def __init__(
        self,
        params: ObstacleLayerParams | dict[str, Any] | None = None,
        *,
        name: str = "obstacle_layer",
        sources: dict[str, ObservationSource] | None = None,
        footprint: Footprint | None = None,
    ) -> None:
        self.params = read_params(self.params_class, params, what=name)
        self.name = name
        self.enabled = self.params.enabled
        self.sources: dict[str, ObservationSource] = dict(sources or {})
        self.footprint = footprint or make_footprint()
        self.grid: Grid | None = None
        self.robot_pose: tuple[float, float, float] | None = None
        self._new_cells((0, 0))

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """The layer named ``context.name`` (its ``plugins:`` name) from its namespace ``params`` (ROS names), in the
        costmap ``context.costmap`` (its observation sources) with the padded ``context.footprint``."""
        return cls(**observation_layer_args(params, context, cls.params_class))

    @property
    def default_value(self) -> int:
        """What a never-observed cell holds: unknown with ``track_unknown_space``, else free."""
        return COST_UNKNOWN if self.params.track_unknown_space else COST_FREE

    def on_footprint_changed(self, footprint: Footprint) -> None:
        self.footprint = footprint

    def match_size(self, master: Grid) -> None:
        data = np.full(master.data.shape, self.default_value, dtype=np.uint8)
        self.grid = Grid(data, master.resolution, master.origin, master.frame_id)
        self._new_cells(data.shape)

    def update_origin(self, master: Grid) -> None:
        shift = origin_shift(self.grid, master)
        if shift is None:
            self.match_size(master)
            return
        assert self.grid is not None
        data = shifted(self.grid.data, *shift, self.default_value)
        self.grid = Grid(data, master.resolution, master.origin, master.frame_id)
        self._shift(*shift)

    def _new_cells(self, shape: tuple[int, ...]) -> None:
        """Per-cell state beside the costs starts afresh for a grid of ``shape`` (rows, columns)."""

    def _shift(self, di: int, dj: int) -> None:
        """Per-cell state beside the costs follows a rolling window's move (new cell (i, j) is old (i + di, j + dj))."""

    def _reset_cells(self, where: Any) -> None:
        """Per-cell state beside the costs forgets the cells ``where`` (a mask or a slice)."""

    def _source_settings(self, source: str | None) -> ObservationSource:
        """Source ``source``'s settings; None: the layer's own ranges and height, marking and clearing."""
        p = self.params
        if source is None:
            return ObservationSource(
                marking=True,
                clearing=True,
                obstacle_range=p.obstacle_range,
                raytrace_range=p.raytrace_range,
                obstacle_min_range=p.obstacle_min_range,
                raytrace_min_range=p.raytrace_min_range,
                max_obstacle_height=p.max_obstacle_height,
            )
        if source not in self.sources:
            known = ", ".join(self.sources) or "none"
            raise NavigationError(f"{self.name}: unknown observation source {source!r} (sources: {known})")
        return self.sources[source]

    def _need_grid(self, call: str) -> Grid:
        """The layer's grid; before ``match_size`` an error naming ``call``."""
        if self.grid is None:
            raise NavigationError(f"{self.name}: no grid yet; call match_size(master) before {call}")
        return self.grid

    def clear_outside(self, xy: tuple[float, float], size: float) -> None:
        """Forget what lies outside the ``size`` x ``size`` m square centred on ``xy`` (m, costmap frame):
        clear_costmap_recovery's reset."""
        g = self.grid
        if g is None:
            return
        cx = g.origin[0] + (np.arange(g.width) + 0.5) * g.resolution
        cy = g.origin[1] + (np.arange(g.height) + 0.5) * g.resolution
        outside = (np.abs(cx[None, :] - xy[0]) > size / 2) | (np.abs(cy[:, None] - xy[1]) > size / 2)
        g.data[outside] = self.default_value
        self._reset_cells(outside)

    def update_bounds(self, robot_pose: tuple[float, float, float]) -> None:
        self.robot_pose = (float(robot_pose[0]), float(robot_pose[1]), float(robot_pose[2]))

    def prepare_costs(self, master: Grid) -> None:
        """Follow the master's geometry and clear the cells under the robot (``footprint_clearing_enabled``)."""
        if self.grid is None:
            return
        if not same_geometry(self.grid, master):
            self.update_origin(master)
        if self.params.footprint_clearing_enabled and self.robot_pose is not None:
            self.footprint.fill(self.grid, self.robot_pose, COST_FREE)

    def update_costs(self, master: Grid) -> None:
        if self.grid is None:
            return
        self.prepare_costs(master)  # (again after the layered costmap's call: the same cells, a no-op)
        assert self.grid is not None
        combine(master.data, self.grid.data, self.params.combination_method != 0)

    def reset(self) -> None:
        if self.grid is not None:
            self.grid.data[:] = self.default_value
            self._reset_cells(slice(None))


class ObstacleLayer(ObservationLayer):
    """``costmap_2d::ObstacleLayer``: marks scan endpoints nearer than ``obstacle_range`` as lethal and clears
    the cells along each ray up to ``raytrace_range`` (Bresenham, Numba); clears the cells under the robot's
    footprint (``footprint_clearing_enabled``); combines into the master by maximum (``combination_method``
    1, unknown cells of the layer skipped) or overwrite (0). Call :meth:`match_size` (the layered costmap
    does) before :meth:`add_scan`.

    navlab's opt-in prices for never-observed cells likely to be closed (``occluded_unknown_cost``,
    ``unknown_near_obstacle_cost``: ``hidden_cells``): the layer then keeps never-observed cells unknown (whatever
    ``track_unknown_space`` says; the master's own default is unchanged, unknown layer cells are not combined), keeps
    where returns cast shadows (:attr:`shadow`) and writes those prices into the master after its own cells.
    """

    writes_master_only = True
    shadow: np.ndarray | None = None  # (H, W) uint8: 1 where a return's shadow fell (occluded_unknown_cost only)

    @property
    def prices_hidden(self) -> bool:
        """Whether the layer prices never-observed cells (``occluded_unknown_cost`` or
        ``unknown_near_obstacle_cost`` set)."""
        return self.params.occluded_unknown_cost > 0 or self.params.unknown_near_obstacle_cost > 0

    @property
    def default_value(self) -> int:
        """What a never-observed cell holds: unknown with ``track_unknown_space`` or hidden-cell prices, else free."""
        return COST_UNKNOWN if self.prices_hidden else super().default_value

    def _new_cells(self, shape: tuple[int, ...]) -> None:
        self.shadow = np.zeros(shape, np.uint8) if self.params.occluded_unknown_cost > 0 else None

    def _shift(self, di: int, dj: int) -> None:
        if self.shadow is not None:
            self.shadow = shifted(self.shadow, di, dj, 0)

    def _reset_cells(self, where: Any) -> None:
        if self.shadow is not None:
            self.shadow[where] = 0

    def update_costs(self, master: Grid) -> None:
        super().update_costs(master)
        if self.grid is None or not self.prices_hidden:
            return
        p = self.params
        costs = hidden_costs(
            self.grid.data,
            self.shadow,
            occluded_cost=p.occluded_unknown_cost,
            near_cost=p.unknown_near_obstacle_cost,
            near_cells=p.unknown_near_obstacle_distance / self.grid.resolution,
        )
        write_hidden(master.data, costs)

    def _mark_shadows(
        self, origin: tuple[float, float], pts: np.ndarray, ok: np.ndarray, src: ObservationSource
    ) -> None:
        """Where the real returns ``pts`` (N, 2, m; ``ok`` (N,)) seen from ``origin`` (m) cast shadows, out to
        ``occluded_unknown_range`` (0: the source's ``raytrace_range``) from the sensor and at most
        ``occluded_unknown_depth`` (0: no limit) past the return."""
        if self.shadow is None or self.grid is None:
            return
        g = self.grid
        reach = self.params.occluded_unknown_range or src.raytrace_range
        ox, oy, res = g.origin[0], g.origin[1], g.resolution
        cells = np.ascontiguousarray((pts - (ox, oy)) / res)
        depth = self.params.occluded_unknown_depth / res
        mark_shadows(self.shadow, (origin[0] - ox) / res, (origin[1] - oy) / res, cells, ok, reach / res, depth)

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
        g = self._need_grid("add_scan")
        pts = np.asarray(endpoints_xy, dtype=np.float64).reshape(-1, 2)
        ok = np.ones(len(pts), bool) if valid is None else np.asarray(valid, bool).reshape(-1)
        if len(ok) != len(pts):
            raise NavigationError(f"{self.name}.add_scan: valid has {len(ok)} entries for {len(pts)} endpoints")
        o = np.asarray(origin_xy, dtype=np.float64).reshape(-1)[:2]
        if not np.isfinite(o).all():
            raise NavigationError(f"{self.name}.add_scan: sensor origin must be finite, got {o.tolist()}")
        src = self._source_settings(source)
        res, (ox, oy, _) = g.resolution, g.origin
        finite = np.isfinite(pts).all(axis=1)
        if src.clearing:
            cells = (pts[finite] - (ox, oy)) / res
            clear_rays(
                g.data,
                (o[0] - ox) / res,
                (o[1] - oy) / res,
                np.ascontiguousarray(cells),
                src.raytrace_range / res,
                src.raytrace_min_range / res,
                np.uint8(COST_FREE),
            )
        if src.marking:
            mark_returns(
                g.data,
                pts,
                ok,
                float(o[0]),
                float(o[1]),
                ox,
                oy,
                res,
                src.obstacle_min_range,
                src.obstacle_range,
                np.uint8(COST_LETHAL),
            )
        if self.shadow is not None:
            self._mark_shadows((float(o[0]), float(o[1])), pts, ok & finite, src)

    def add_ranges(
        self,
        sensor_pose: tuple[float, float, float] | np.ndarray,
        ranges: np.ndarray,
        beams: tuple[np.ndarray, np.ndarray],
        limits: tuple[float, float, float],
        *,
        source: str | None = None,
    ) -> None:
        """:meth:`add_scan` of a laser scan as it comes, in one compiled call: the sensor at ``sensor_pose`` (x m,
        y m, yaw rad, costmap frame), ``ranges`` (N,) m along the ``beams`` (cosines, sinuses of the beam angles,
        sensor frame); ``limits`` = (range_min, range_max, clear_to m): the readings in [range_min, range_max) are
        returns, the others (inf, at or over range_max) only clear, out to clear_to; NaN readings are left out.
        Gives the grid :meth:`add_scan` gives for the same endpoints, bit for bit."""
        g = self._need_grid("add_ranges")
        x, y, yaw = (float(v) for v in sensor_pose)
        if not (math.isfinite(x) and math.isfinite(y)):
            raise NavigationError(f"{self.name}.add_ranges: sensor origin must be finite, got {[x, y]}")
        src = self._source_settings(source)
        observe_ranges(
            g.data,
            ranges,
            beams[0],
            beams[1],
            (float(limits[0]), float(limits[1]), float(limits[2])),
            (x, y, math.cos(yaw), math.sin(yaw)),
            (float(g.origin[0]), float(g.origin[1]), float(g.resolution)),
            (bool(src.clearing), float(src.raytrace_range), float(src.raytrace_min_range), np.uint8(COST_FREE)),
            (bool(src.marking), float(src.obstacle_min_range), float(src.obstacle_range), np.uint8(COST_LETHAL)),
        )
        if self.shadow is not None:
            r = np.asarray(ranges, dtype=np.float64)
            ok = np.isfinite(r) & (r >= limits[0]) & (r < limits[1])
            c, s = math.cos(yaw), math.sin(yaw)
            lx, ly = r[ok] * beams[0][ok], r[ok] * beams[1][ok]
            pts = np.stack([x + c * lx - s * ly, y + s * lx + c * ly], axis=1)
            self._mark_shadows((x, y), pts, np.ones(len(pts), bool), src)
