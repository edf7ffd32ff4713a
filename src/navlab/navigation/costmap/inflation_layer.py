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
from navlab.navigation.costmap.kernels import lethal_diff, reinflate
from navlab.navigation.costmap.layer import Layer, costmap_of, shifted
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

    writes_master_only = True

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
        # the last inflation: ((origin, resolution, shape), lethal seeds, costs over the whole grid, a buffer of
        # changed cells for lethal_diff)
        self._inflated: tuple[Any, np.ndarray, np.ndarray, np.ndarray] | None = None
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
        """Inflate the master's lethal cells into it. After the first update only what changed is recomputed (see
        ``reinflate``): around seeds that appeared or vanished and, in a rolling window, along the edges its move
        uncovered or left; the rest of the last inflation is kept (shifted with the window)."""
        data = master.data
        reach = math.ceil(self.params.inflation_radius / master.resolution) + 1
        reach = min(reach, math.ceil(math.hypot(*data.shape)) + 1)  # no cell is further: the table stays grid-sized
        cached = self._inflated
        shift = None if cached is None else _shift(cached[0], master)
        di, dj = shift or (0, 0)
        seeds = np.empty(data.shape, dtype=np.uint8)
        if cached is None or shift is None:  # afresh: every cell is recomputed, none counts as changed
            then, changes = np.zeros((0, 0), np.uint8), np.empty((2 * data.size, 2), np.int64)
        else:
            then, changes = cached[1], cached[3]
        count, appeared, vanished = lethal_diff(data, np.uint8(COST_LETHAL), seeds, then, di, dj, changes)
        if count == 0:
            return
        table = self._table(master.resolution, reach)
        if cached is None or shift is None:
            cost = np.zeros(data.shape, np.uint8)
            whole = np.array([[0, data.shape[0], 0, data.shape[1]]], np.int64)
            reinflate(seeds, cost, table, reach, changes, 0, 0, whole)
        else:
            cost = cached[2] if shift == (0, 0) else shifted(cached[2], di, dj, 0)
            boxes = _new_edges(data.shape, di, dj)
            if appeared or vanished or len(boxes):
                reinflate(seeds, cost, table, reach, changes, appeared, vanished, boxes)
        self._inflated = ((master.origin, master.resolution, data.shape), seeds, cost, changes)
        _merge(data, cost, bool(self.params.inflate_unknown))


def _shift(then: tuple[Any, float, tuple[int, ...]], master: Grid) -> tuple[int, int] | None:
    """Whole cells (di, dj) the master's origin moved since the inflation ``then`` (origin, resolution, shape) was
    made (a rolling window; (0, 0) for a fixed one); None when its size or resolution differs or it moved by a
    whole window (the inflation starts afresh)."""
    origin, resolution, shape = then
    if shape != master.data.shape or resolution != master.resolution:
        return None
    if origin == master.origin:
        return 0, 0
    di = round((master.origin[0] - origin[0]) / resolution)
    dj = round((master.origin[1] - origin[1]) / resolution)
    return (di, dj) if abs(di) < shape[1] and abs(dj) < shape[0] else None


def _new_edges(shape: tuple[int, ...], di: int, dj: int) -> np.ndarray:
    """The boxes (K, 4) = (j0, j1, i0, i1) of what a rolling window newly covers after moving by (di, dj) cells."""
    h, w = shape
    out = []
    if di:
        out.append((0, h, *((w - di, w) if di > 0 else (0, -di))))
    if dj:
        out.append((*((h - dj, h) if dj > 0 else (0, -dj)), 0, w))
    return np.array(out, np.int64).reshape(-1, 4)


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
