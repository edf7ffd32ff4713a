"""ROS 1's ``LayeredCostmap``: a master grid of costs that ordered layers write into on each update.

The global costmap lives in ``map`` and takes its size from the static layer's map; the local one is a
rolling window in ``odom`` (``rolling_window: true``, ``width`` x ``height`` m) that re-centres on the
robot and keeps the cells it still covers. The node calls :meth:`set_map`, :meth:`add_scan` and
:meth:`update_map` at ``update_frequency``; everything here is pure (metres, radians, costmap frame).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab.grid import COST_FREE, COST_UNKNOWN, Grid, GridMap
from navlab.navigation.costmap.footprint import Footprint, make_footprint
from navlab.navigation.costmap.layer import Layer
from navlab.navigation.costmap.params import CostmapParams, costmap_params
from navlab.navigation.errors import NavigationError
from navlab.plugins import MapLayer, PluginContext, ScanLayer, make_plugin


class LayeredCostmap:
    """A costmap_2d costmap: master ``Grid`` (uint8 costs, ``frame_id`` = ``global_frame``) plus its layers.

    ``params``: a costmap's parameter dict as a ROS user writes it (see ``costmap.params``) or parsed
    ``CostmapParams``. Layers come from ``plugins:`` (loaded through the ``costmap_layer`` registry) or, with
    no ``plugins:`` key, ROS 1's default: static (if ``static_map``) + obstacle + inflation.
    """

    def __init__(self, params: CostmapParams | dict[str, Any] | None = None) -> None:
        self.params = params if isinstance(params, CostmapParams) else costmap_params(params)
        p = self.params
        self.footprint: Footprint = make_footprint(
            robot_radius=p.robot_radius, footprint=p.footprint, footprint_padding=p.footprint_padding
        )
        w, h = self._cells(p.width), self._cells(p.height)
        default = COST_UNKNOWN if p.track_unknown_space else COST_FREE
        frame = p.global_frame.lstrip("/") or "map"
        self.master = Grid(np.full((h, w), default, np.uint8), p.resolution, (p.origin_x, p.origin_y, 0.0), frame)
        self.layers: list[Layer] = []
        for k, spec in enumerate(p.plugins):
            context = PluginContext(name=spec.name, footprint=self.footprint, costmap=p)
            layer = make_plugin(
                "costmap_layer",
                spec.type,
                p.namespaces.get(spec.name),
                context=context,
                param=f"plugins[{k}] ({spec.name}) type",
            )
            layer.match_size(self.master)
            self.layers.append(layer)
        # the layers that take a map, and those that take scans (capabilities, by what they implement)
        self.map_layers: list[MapLayer] = [x for x in self.layers if isinstance(x, MapLayer)]
        self.scan_layers: list[ScanLayer] = [x for x in self.layers if isinstance(x, ScanLayer)]
        self.robot_pose: tuple[float, float, float] | None = None
        self._deferred = False  # an update whose writing of the master waits for someone to read it

    def _cells(self, metres: float) -> int:
        return max(1, round(metres / self.params.resolution))

    # --- geometry ---------------------------------------------------------------------------------

    @property
    def costmap(self) -> Grid:
        """The master grid (updated in place by :meth:`update_map`; a deferred update is written now)."""
        self._flush()
        return self.master

    def _flush(self) -> None:
        """Write the master of a deferred update now (see :meth:`update_map`)."""
        if self._deferred:
            self._write_master()

    @property
    def rolling(self) -> bool:
        """Whether this is a rolling window."""
        return self.params.rolling_window

    @property
    def default_value(self) -> int:
        """What the master is reset to before the layers write: unknown with ``track_unknown_space``, else free."""
        return COST_UNKNOWN if self.params.track_unknown_space else COST_FREE

    @property
    def inscribed_radius(self) -> float:
        """Padded footprint's inscribed radius (m)."""
        return self.footprint.inscribed_radius

    @property
    def circumscribed_radius(self) -> float:
        """Padded footprint's circumscribed radius (m)."""
        return self.footprint.circumscribed_radius

    def resize(self, width: int, height: int, resolution: float, origin: tuple[float, float]) -> None:
        """New master geometry (``width`` x ``height`` cells, m/cell, lower-left corner in m); layers reset."""
        self._flush()  # before what the layers hold changes
        if width < 1 or height < 1 or not (math.isfinite(resolution) and resolution > 0):
            raise NavigationError(
                f"costmap resize: expected positive size and resolution, got {width} x {height} at {resolution} m/cell"
            )
        self.master = Grid(
            np.full((height, width), self.default_value, np.uint8),
            resolution,
            (float(origin[0]), float(origin[1]), 0.0),
            self.master.frame_id,
        )
        for layer in self.layers:
            layer.match_size(self.master)

    def set_footprint(self, footprint: Footprint) -> None:
        """A new (padded) footprint for every layer."""
        self._flush()  # before what the layers hold changes
        self.footprint = footprint
        for layer in self.layers:
            layer.on_footprint_changed(footprint)

    def layer(self, name: str) -> Layer:
        """The layer named ``name`` in ``plugins:``."""
        for layer in self.layers:
            if layer.name == name:
                return layer
        raise NavigationError(f"costmap has no layer {name!r} (layers: {', '.join(x.name for x in self.layers)})")

    # --- inputs -----------------------------------------------------------------------------------

    def set_map(self, grid: GridMap, *, map_in_costmap: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        """A new ``/map`` for the static layers. Not rolling: the master takes the map's size, resolution and
        origin (as costmap_2d does). ``map_in_costmap``: pose of the map frame in the costmap frame."""
        self._flush()  # before what the layers hold changes
        statics = self.map_layers
        if not statics:
            raise NavigationError(
                "costmap has no static layer to take a map (set static_map: true or add "
                "costmap_2d::StaticLayer to plugins)"
            )
        if grid.origin[2] != 0.0:
            raise NavigationError(f"map origin yaw must be 0 for a costmap, got {grid.origin[2]}")
        if not self.rolling:
            same = (
                self.master.data.shape == grid.data.shape
                and self.master.resolution == grid.resolution
                and self.master.origin[:2] == grid.origin[:2]
            )
            if not same:
                self.resize(grid.width, grid.height, grid.resolution, grid.origin[:2])
        for layer in statics:
            layer.set_map(grid, map_in_costmap=map_in_costmap)

    def add_scan(
        self,
        origin_xy: tuple[float, float] | np.ndarray,
        endpoints_xy: np.ndarray,
        valid: np.ndarray | None = None,
        *,
        source: str | None = None,
        layer: str | None = None,
    ) -> None:
        """Give one scan (sensor origin and endpoints (N, 2), m, costmap frame) to the obstacle layers
        (or to the one named ``layer``); see ``ObstacleLayer.add_scan``."""
        self._flush()  # before what the layers hold changes
        for target in self.scan_targets(source, layer):
            target.add_scan(origin_xy, endpoints_xy, valid, source=source)

    def scan_targets(self, source: str | None = None, layer: str | None = None) -> list[ScanLayer]:
        """The layers a scan of ``source`` goes to (see :meth:`add_scan`): the one named ``layer``, else every
        obstacle layer observing ``source`` (every one without a source)."""
        if layer:
            target = self.layer(layer)
            if not isinstance(target, ScanLayer):
                raise NavigationError(f"costmap layer {layer!r} is not an obstacle layer")
            return [target]
        return [t for t in self.scan_layers if source is None or source in t.sources]

    # --- the update -------------------------------------------------------------------------------

    def update_origin(self, robot_xy: tuple[float, float]) -> None:
        """Rolling window: re-centre on the robot, moving the origin by whole cells (layers keep overlap)."""
        g = self.master
        res = g.resolution
        want_x = robot_xy[0] - g.width * res / 2.0
        want_y = robot_xy[1] - g.height * res / 2.0
        di = math.floor((want_x - g.origin[0]) / res + 0.5)
        dj = math.floor((want_y - g.origin[1]) / res + 0.5)
        if di == 0 and dj == 0:
            return
        self.master = Grid(g.data, res, (g.origin[0] + di * res, g.origin[1] + dj * res, 0.0), g.frame_id)
        for layer in self.layers:
            layer.update_origin(self.master)

    def update_map(self, robot_pose: tuple[float, float, float], *, defer: bool = False) -> Grid:
        """One costmap update with the robot at ``robot_pose`` (x, y, yaw) in the costmap frame: re-centre a
        rolling window, reset the master, let each enabled layer write in order. Returns the master grid.

        ``defer``: when every enabled layer only writes the master (``Layer.writes_master_only``: the static,
        obstacle and inflation layers), the layers do their own part now (``prepare_costs``) and the master is
        written when :attr:`costmap` is next read, unless a later update comes first (the same grid either way:
        it is a function of what the layers hold). Then the returned master is not written yet: read
        :attr:`costmap`."""
        pose = (float(robot_pose[0]), float(robot_pose[1]), float(robot_pose[2]))
        if not all(math.isfinite(v) for v in pose):
            raise NavigationError(f"costmap update: robot pose must be finite, got {robot_pose}")
        self.robot_pose = pose
        if self.rolling:
            self.update_origin(pose[:2])
        for layer in self.layers:
            if layer.enabled:
                layer.update_bounds(pose)
        if defer and all(vars(type(x)).get("writes_master_only", False) for x in self.layers if x.enabled):
            for layer in self.layers:
                if layer.enabled:
                    layer.prepare_costs(self.master)
            self._deferred = True
            return self.master
        self._write_master()
        return self.master

    def _write_master(self) -> None:
        """Reset the master and let each enabled layer write in order."""
        self._deferred = False
        self.master.data[:] = self.default_value
        for layer in self.layers:
            if layer.enabled:
                layer.update_costs(self.master)

    def footprint_at(self, pose: tuple[float, float, float]) -> np.ndarray:
        """The footprint polygon (N, 2) at ``pose`` in the costmap frame (a 16-gon for a circular robot)."""
        poly = self.footprint.oriented(pose)
        if poly is not None:
            return poly
        a = np.linspace(0.0, 2 * math.pi, 16, endpoint=False)
        r = self.footprint.circumscribed_radius
        return np.stack([pose[0] + r * np.cos(a), pose[1] + r * np.sin(a)], axis=1)

    def reset(self) -> None:
        """Forget every layer's observations (costmap_2d's ``resetLayers``)."""
        self._flush()  # before what the layers hold changes
        for layer in self.layers:
            layer.reset()
            layer.match_size(self.master)
        self.master.data[:] = self.default_value
