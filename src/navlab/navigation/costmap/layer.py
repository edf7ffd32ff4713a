"""costmap_2d's layer interface (``costmap_2d::Layer``): what every costmap layer plugin implements.

Each layer writes uint8 costs (0 free .. 252, 253 inscribed, 254 lethal, 255 unknown) into a master
``Grid`` (origin yaw 0, in the costmap's frame: ``map`` or ``odom``) in the order of ``plugins:``, the
way ROS 1's ``LayeredCostmap::updateMap`` calls ``updateCosts``. Positions are metres in the costmap
frame. Layers are pure: the node feeds them maps and scans and asks the layered costmap for an update.
The layers themselves live one per file: ``static_layer``, ``obstacle_layer``, ``inflation_layer``.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping
from typing import Any, Self

import numpy as np

from navlab.deprecation import NavlabDeprecationWarning
from navlab.grid import Grid
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.params import CostmapParams
from navlab.plugins import PluginContext


def costmap_of(params: Mapping[str, Any] | None, context: PluginContext) -> CostmapParams:
    """The parsed costmap parameters a layer named ``context.name`` reads: its costmap's (``context.costmap``;
    inherited keys such as ``track_unknown_space`` and the observation sources) with ``params`` as the
    layer's own namespace."""
    base = context.costmap if isinstance(context.costmap, CostmapParams) else CostmapParams()
    if params is None or base.namespaces.get(context.name) == params:
        return base
    return dataclasses.replace(base, namespaces={**base.namespaces, context.name: dict(params)})


def same_geometry(a: Grid, b: Grid) -> bool:
    """Whether two grids have the same shape, resolution and origin."""
    return a.data.shape == b.data.shape and a.resolution == b.resolution and a.origin == b.origin


def origin_shift(old: Grid | None, master: Grid) -> tuple[int, int] | None:
    """Whole cells (di, dj) a rolling master's origin moved from ``old``'s; None when there is no ``old`` or its
    size or resolution differs (the layer starts afresh: ``match_size``)."""
    if old is None or old.data.shape != master.data.shape or old.resolution != master.resolution:
        return None
    res = master.resolution
    return round((master.origin[0] - old.origin[0]) / res), round((master.origin[1] - old.origin[1]) / res)


def shifted(data: np.ndarray, di: int, dj: int, fill: Any) -> np.ndarray:
    """A copy of ``data`` (H, W) whose cell (i, j) is ``data``'s cell (i + di, j + dj); ``fill`` where that lies
    outside (what a rolling window newly covers)."""
    h, w = data.shape
    new = np.full((h, w), fill, dtype=data.dtype)
    i0, i1 = max(0, -di), min(w, w - di)
    j0, j1 = max(0, -dj), min(h, h - dj)
    if i0 < i1 and j0 < j1:
        new[j0:j1, i0:i1] = data[j0 + dj : j1 + dj, i0 + di : i1 + di]
    return new


class Layer:
    """A costmap_2d layer: ``match_size`` when the master changes geometry, ``update_origin`` when a rolling
    window moves, ``update_bounds`` with the robot pose each cycle, then ``update_costs`` into the master."""

    name: str = "layer"
    enabled: bool = True
    # update_costs only writes the master (and caches of its own), after prepare_costs' side effects on the layer:
    # the layered costmap may then write the master when it is read rather than at every update
    writes_master_only: bool = False

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """The layer named ``context.name`` from its parameter namespace ``params`` (ROS names), in the costmap
        ``context.costmap`` (parsed ``CostmapParams``) with the robot's padded ``context.footprint``."""
        if getattr(cls.from_costmap_params, "__func__", None) is _OLD_HOOK:
            raise NotImplementedError(f"{cls.__name__} has no from_params(params, *, context)")
        warnings.warn(
            f"{cls.__name__}.from_costmap_params is deprecated: implement from_params(params, *, context)",
            NavlabDeprecationWarning,
            stacklevel=2,
        )  # a layer written for the old hook: one release
        footprint = context.footprint if isinstance(context.footprint, Footprint) else make_footprint()
        return cls.from_costmap_params(context.name, costmap_of(params, context), footprint)

    @classmethod
    def from_costmap_params(cls, name: str, costmap: CostmapParams, footprint: Footprint) -> Self:
        """Deprecated (one release): ``from_params`` with the layer's namespace and a ``PluginContext``."""
        warnings.warn(
            "Layer.from_costmap_params is deprecated: use from_params(params, *, context)",
            NavlabDeprecationWarning,
            stacklevel=2,
        )
        context = PluginContext(name=name, footprint=footprint, costmap=costmap)
        return cls.from_params(costmap.namespaces.get(name), context=context)

    def on_footprint_changed(self, footprint: Footprint) -> None:
        """The robot's (padded) footprint changed."""

    def match_size(self, master: Grid) -> None:
        """The master grid has a new size, resolution or origin (everything the layer holds is reset)."""

    def update_origin(self, master: Grid) -> None:
        """A rolling window moved the master's origin by whole cells; keep what overlaps."""
        self.match_size(master)

    def update_bounds(self, robot_pose: tuple[float, float, float]) -> None:
        """Called once per update with the robot pose (x, y, yaw) in the costmap frame."""

    def prepare_costs(self, master: Grid) -> None:
        """What ``update_costs`` does to the layer itself before it writes ``master`` (a layer that
        ``writes_master_only`` does it here; the layered costmap calls it at every update, ``update_costs``
        maybe later)."""

    def update_costs(self, master: Grid) -> None:
        """Write this layer's costs into ``master``."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget everything observed."""


_OLD_HOOK = vars(Layer)["from_costmap_params"].__func__  # the base's: a layer that overrides neither has no constructor
