"""costmap_2d::InflationLayer: costs falling off with the distance to the nearest lethal cell (see ``layer``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Self

import numba
import numpy as np

from navlab.core import read_params
from navlab.grid import COST_FREE, COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.kernels import inflate_box, lethal_changes
from navlab.navigation.costmap.layer import Layer, costmap_of
from navlab.navigation.costmap.params import InflationLayerParams, layer_params
from navlab.plugins import PluginContext


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
        self.params: InflationLayerParams = read_params(InflationLayerParams, params, what=name)
        self.name = name
        self.enabled = self.params.enabled
        self.footprint = footprint or make_footprint()
        # the last inflation: ((origin, resolution, shape), lethal seeds, costs over the whole grid)
        self._inflated: tuple[Any, np.ndarray, np.ndarray] | None = None
        self._costs: tuple[Any, np.ndarray] | None = None  # cost by squared cell distance (see _table)

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        name = context.name or "inflation_layer"
        footprint = context.footprint if isinstance(context.footprint, Footprint) else None
        return cls(
            layer_params(InflationLayerParams, costmap_of(params, context), name), name=name, footprint=footprint
        )

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
        key = (resolution, reach, self.params.inflation_radius, self.params.cost_scaling_factor, self.inscribed_radius)
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
            inflate_box(
                seeds, (o0, o1, p0, p1), (j0, j1, i0, i1), self._table(master.resolution, reach), cost[j0:j1, i0:i1]
            )
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
