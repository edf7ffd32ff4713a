"""The plugin contract, as pluginlib and Nav2 have it: Protocols, one constructor shape, entry points.

A parameter file picks an algorithm by its ROS plugin name (``base_global_planner: navfn/NavfnROS``,
``base_local_planner: dwa_local_planner/DWAPlannerROS``, a costmap ``plugins:`` entry's ``type:
costmap_2d::InflationLayer``, a ``recovery_behaviors`` entry's ``type``, slam_gmapping's ``mode``,
amcl's ``odom_model_type`` and ``laser_model_type``). Each kind of plugin is one Python entry-point group
(pluginlib's plugin description files): navlab declares its own in ``pyproject.toml``, and any installed
package may add more under the same groups, found by name with no change to navlab::

    [project.entry-points."navlab.controllers"]
    "my_pkg/MyController" = "my_pkg.controller:MyController"

Every class plugin is built the same way: ``cls.from_params(params, *, context)``, ``params`` the
plugin's ROS parameter namespace (a dict; missing keys take ROS defaults) and ``context`` a
:class:`PluginContext` (what the hosting node gives every plugin: its name, seeded RNG, footprint, ...).
AMCL's motion models are plain functions and are used as they are. Short aliases (``dwa``) live here.
:func:`navlab.navigation.plugin_check.check_plugin` checks a plugin against its Protocol (docs/plugins.md).

Every implementation is pure (numpy in, numpy out; no topics, no clock); its node holds parameters.
Units: metres, radians, seconds; poses ``(x, y, yaw)``; paths ``(N, 2)`` or ``(N, 3)`` arrays in the
costmap's frame. This module is a leaf: it imports nothing of navlab but errors and types.
"""

from __future__ import annotations

import functools
import importlib
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from importlib import metadata
from typing import TYPE_CHECKING, Any, Protocol, Self, runtime_checkable

import numpy as np

from navlab.deprecation import NavlabDeprecationWarning
from navlab.errors import NavlabError, did_you_mean

if TYPE_CHECKING:
    from navlab.grid import Grid, GridMap

Pose = tuple[float, float, float]


class PluginError(NavlabError):
    """An unknown plugin name, or a registered plugin that cannot be imported or breaks its Protocol."""


# --- what a host hands every plugin -----------------------------------------------------------------


@runtime_checkable
class FootprintLike(Protocol):
    """A robot footprint (padded): a circle of ``radius`` m (``polygon`` None) or a polygon (N, 2) in the base
    frame (m); costmap_2d's ``Footprint``."""

    @property
    def radius(self) -> float | None: ...

    @property
    def polygon(self) -> np.ndarray | None: ...


@dataclass(frozen=True)
class PluginContext:
    """What a host gives a plugin besides its parameters (Nav2's ``configure(parent, name, tf, costmap_ros)``).

    ``name``: the plugin's instance name (its parameter namespace: ``DWAPlannerROS``, ``inflation_layer``);
    ``rng``: the node's seeded generator (every random draw); ``footprint``: the costmap's padded footprint;
    ``controller_frequency``: move_base's (Hz; ROS planners search the parameter upward); ``costmap``: the
    parsed parameters of the costmap a layer belongs to (``CostmapParams``); ``map_field``: AMCL's
    precomputed map (``MapField``) for laser models. A host leaves out what a kind does not use.
    """

    name: str = ""
    rng: np.random.Generator | None = None
    footprint: FootprintLike | None = None
    controller_frequency: float | None = None
    costmap: Any = None
    map_field: Any = None


@dataclass(frozen=True, eq=False)
class ControlResult:
    """A controller's answer for one cycle (Nav2's ``computeVelocityCommands``).

    ``v`` (m/s) and ``w`` (rad/s) the command; ``valid`` False when no valid command was found (ROS's
    ``computeVelocityCommands`` returning false: move_base's cue for recovery, the command is then a stop);
    ``local_plan`` (N, 3) the trajectory chosen (x, y, yaw in the costmap frame; empty when there is none)
    for ``~local_plan``. It unpacks and indexes as the ``(v, w)`` pair controllers returned before
    (``v, w = result``, ``result[0]``), so code written for that keeps working.
    """

    v: float
    w: float
    valid: bool = True
    local_plan: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __iter__(self) -> Iterator[float]:
        return iter((self.v, self.w))

    def __len__(self) -> int:
        return 2

    def __getitem__(self, index: int) -> float:
        return (self.v, self.w)[index]

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ControlResult):
            return (self.v, self.w, self.valid) == (other.v, other.w, other.valid) and np.array_equal(
                self.local_plan, other.local_plan
            )
        if isinstance(other, tuple | list):
            return (self.v, self.w) == tuple(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    @classmethod
    def of(cls, out: Any) -> ControlResult:
        """``out`` as a ControlResult: itself, or a controller's old ``(v, w)`` tuple (deprecated, one release)."""
        if isinstance(out, ControlResult):
            return out
        warnings.warn(
            "a controller returning (v, w) is deprecated: return navlab.plugins.ControlResult",
            NavlabDeprecationWarning,
            stacklevel=3,
        )
        v, w = out
        return cls(float(v), float(w))


class BuiltFromParams:
    """A mixin for plugins whose constructor takes their parameter namespace alone: ``from_params`` is
    ``cls(params)`` (the context is not needed)."""

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        return cls(params)  # type: ignore[call-arg]


# --- the Protocols ----------------------------------------------------------------------------------


@runtime_checkable
class Plugin(Protocol):
    """Every class plugin: built from its ROS parameter namespace and the host's context."""

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self: ...


@runtime_checkable
class SlamBackend(Plugin, Protocol):
    """Online SLAM over laser scans: slam_gmapping's ``mode`` (``gmapping``, ``graph``).

    ``params`` maps slam_gmapping parameter names to values (a mode's own parameters under its name,
    ``graph.voxel``); names left out take their defaults, which :meth:`parameters` lists for the node to
    declare. ``context.rng`` drives every random draw (required).
    """

    params: Any  # the mode's parameter object (e.g. ``GMappingParams``)

    @classmethod
    def parameters(cls) -> dict[str, Any]:
        """Every parameter name the mode reads, with its ROS default."""
        ...

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_laser: np.ndarray,
        *,
        range_max: float | None = None,
        stamp_ns: int | None = None,
    ) -> np.ndarray | None:
        """Process one scan (ranges m; inf/NaN = no return) taken with the laser at ``odom_laser`` (x, y, yaw
        in the odom frame) at ``stamp_ns`` (ns; None for a log's scans); returns the laser's pose in the map
        frame, or None when the scan only moved the estimate and did not update the map. ``range_max``:
        the sensor's (m), or None to take the ranges as they are."""
        ...

    def due(self, odom_laser: np.ndarray, stamp_ns: int) -> bool:
        """Whether a node should hand this scan to :meth:`add_scan` (slam_gmapping's linearUpdate,
        angularUpdate, temporalUpdate gating for modes that do not gate in ``add_scan`` themselves)."""
        ...

    def trajectory(self) -> np.ndarray:
        """Laser poses (M, 3) in the map frame now, one per scan for which ``add_scan`` returned a pose."""
        ...

    def current_map(self, *, frame_id: str = "map") -> GridMap | None:
        """The occupancy grid now, or None before the first scan."""
        ...

    def finish(self) -> np.ndarray:
        """Final laser poses (N, 3) in the map frame, one per ``add_scan`` call."""
        ...

    def stats(self) -> dict[str, int]:
        """Counters for a run's summary (updates, resamples, loop closures, ...)."""
        ...


class MotionModel(Protocol):
    """AMCL's ``odom_model_type`` (a function, no state): move particles (N, 3; x, y m, yaw rad; map frame) in
    place by the odometry step from ``odom_old`` to ``odom_new`` (robot poses in the odom frame), with noise
    ``alphas`` = odom_alpha1..4 drawn from ``rng``."""

    def __call__(
        self,
        particles: np.ndarray,
        odom_old: Pose,
        odom_new: Pose,
        alphas: tuple[float, float, float, float],
        rng: np.random.Generator,
    ) -> None: ...


@runtime_checkable
class LaserModel(Plugin, Protocol):
    """AMCL's ``laser_model_type``: a score per particle for one scan (ROS amcl's ``1 + sum(pz**3)``).

    ``params``: amcl's parameters (a dict or ``AmclParams``); ``context.map_field``: the map's ``MapField``.
    """

    def weights(self, particles: np.ndarray, beams: Any, laser_pose: Pose) -> np.ndarray:
        """Scores (N,) of particles (N, 3; map frame) for the chosen ``beams`` (``models.Beams``) of a laser
        at ``laser_pose`` (x, y, yaw in the robot base frame)."""
        ...


@runtime_checkable
class CostmapLayer(Plugin, Protocol):
    """A costmap_2d layer (``costmap_2d::StaticLayer``, ``ObstacleLayer``, ``InflationLayer``, ...).

    Built with ``context.name`` (its ``plugins:`` name), ``context.costmap`` (the costmap's parsed
    parameters) and ``context.footprint``. The layered costmap calls ``match_size`` when the master changes
    geometry, ``update_origin`` when a rolling window moves, then each cycle ``update_bounds`` with the robot
    pose and ``update_costs`` (costs uint8, 0..254, 255 unknown, written into ``master`` over the whole
    grid) in the order of the ``plugins:`` list.
    """

    name: str
    enabled: bool

    def on_footprint_changed(self, footprint: Any) -> None: ...

    def match_size(self, master: Grid) -> None: ...

    def update_origin(self, master: Grid) -> None: ...

    def update_bounds(self, robot_pose: Pose) -> None: ...

    def update_costs(self, master: Grid) -> None: ...

    def reset(self) -> None: ...


@runtime_checkable
class MapLayer(Protocol):
    """A layer that takes ``/map`` (a capability; ``costmap_2d::StaticLayer``) on ``map_topic``."""

    @property
    def map_topic(self) -> str: ...

    def set_map(self, grid: GridMap, *, map_in_costmap: Pose = (0.0, 0.0, 0.0)) -> None:
        """A new map; ``map_in_costmap`` the pose of the map's frame in the costmap's frame."""
        ...

    def on_map_obstacle(self, xy: tuple[float, float]) -> bool:
        """Whether the point (m, costmap frame) lies on an occupied cell of the map."""
        ...


@runtime_checkable
class ScanLayer(Protocol):
    """A layer that takes laser scans (a capability; ``costmap_2d::ObstacleLayer``). ``sources``: its
    observation sources by name."""

    sources: Mapping[str, Any]

    def add_scan(
        self, origin_xy: Any, endpoints_xy: np.ndarray, valid: np.ndarray | None = None, *, source: str | None = None
    ) -> None:
        """One scan in the costmap frame: the sensor at ``origin_xy`` (m), ray endpoints (N, 2) (m), ``valid``
        (N,) real returns (the others only clear); ``source`` one of ``sources`` (None: the layer's own)."""
        ...

    def clear_outside(self, xy: tuple[float, float], size: float) -> None:
        """Forget what lies outside the ``size`` x ``size`` m square centred on ``xy`` (clear_costmap_recovery)."""
        ...


@runtime_checkable
class GlobalPlanner(Plugin, Protocol):
    """``base_global_planner``: a path from ``start`` to ``goal`` over a costmap, or None if there is none
    (``last_failure`` then says why; "" after a success)."""

    last_failure: str

    def make_plan(self, costmap: Grid, start: Pose, goal: Pose) -> np.ndarray | None: ...


@runtime_checkable
class Controller(Plugin, Protocol):
    """``base_local_planner``: velocity commands that follow a global plan around what the costmap shows.

    ``context``: ``rng``, ``footprint`` (the local costmap's) and ``controller_frequency``.
    """

    def set_plan(self, path: np.ndarray) -> None:
        """The global plan to follow: (N, 2) or (N, 3) in the controller's frame."""
        ...

    def compute_velocity(self, pose: Pose, velocity: tuple[float, float], costmap: Grid | None) -> ControlResult:
        """The command for the robot at ``pose`` moving at ``velocity`` (v m/s, w rad/s)."""
        ...

    def is_goal_reached(self, pose: Pose, velocity: tuple[float, float]) -> bool: ...


@runtime_checkable
class Recovery(Plugin, Protocol):
    """A ``recovery_behaviors`` entry: ``start`` once, then ``step`` at ``controller_frequency`` until it
    returns None. ``costmaps``: ``{"global": ..., "local": ...}`` (``Costmap2DROS``); poses in the local
    costmap's frame."""

    def start(self, pose: Pose) -> None: ...

    def step(self, pose: Pose, costmaps: dict[str, Any]) -> tuple[float, float] | None: ...


# --- the registry: entry points -------------------------------------------------------------------

# kind -> (entry-point group, Protocol)
KINDS: dict[str, tuple[str, Any]] = {
    "controller": ("navlab.controllers", Controller),
    "global_planner": ("navlab.planners", GlobalPlanner),
    "costmap_layer": ("navlab.costmap_layers", CostmapLayer),
    "recovery": ("navlab.recoveries", Recovery),
    "slam_backend": ("navlab.slam_backends", SlamBackend),
    "laser_model": ("navlab.laser_models", LaserModel),
    "motion_model": ("navlab.motion_models", MotionModel),
}

# kind -> {short alias: registered name} (the names navlab's CLI takes, e.g. ``--controller dwa``)
ALIASES: dict[str, dict[str, str]] = {
    "controller": {
        "trajectory": "base_local_planner/TrajectoryPlannerROS",
        "dwa": "dwa_local_planner/DWAPlannerROS",
        "dwb": "nav2_dwb_controller/DWBLocalPlanner",
        "mppi": "nav2_mppi_controller::MPPIController",
        "rpp": "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController",
    },
    "global_planner": {
        "navfn": "navfn/NavfnROS",
        "global_planner": "global_planner/GlobalPlanner",
        "theta_star": "nav2_theta_star_planner/ThetaStarPlanner",
        "smac_hybrid": "nav2_smac_planner/SmacPlannerHybrid",
    },
}


def _group(kind: str) -> str:
    if kind not in KINDS:
        raise PluginError(f"unknown kind of plugin {kind!r} (kinds: {', '.join(KINDS)})")
    return KINDS[kind][0]


@functools.cache
def _entry_points(group: str) -> dict[str, metadata.EntryPoint]:
    """The installed entry points of ``group`` by name (read once; :func:`refresh_plugins` re-reads)."""
    found = {ep.name: ep for ep in metadata.entry_points(group=group)}
    if not found:
        raise PluginError(
            f"no {group} entry points are installed: navlab's own install is out of date "
            "(run `make install` or `pip install -e .` in the checkout)"
        )
    return found


def refresh_plugins() -> None:
    """Forget the entry points read so far (after installing or removing a plugin package in this process)."""
    importlib.invalidate_caches()
    _entry_points.cache_clear()


def plugin_names(kind: str) -> list[str]:
    """The registered names of a kind of plugin (every installed package's), without the short aliases."""
    return sorted(_entry_points(_group(kind)))


def resolve_name(kind: str, name: str) -> str:
    """The registered name ``name`` stands for: itself, or what a short alias (``dwa``) names."""
    return ALIASES.get(kind, {}).get(name, name)


def load_plugin(kind: str, name: str, *, param: str | None = None) -> Any:
    """The class or function registered as ``name`` (or a short alias) for ``kind``; an unknown name says
    "did you mean". ``param`` names the parameter the user set (for the error message)."""
    table = _entry_points(_group(kind))
    ep = table.get(resolve_name(kind, name))
    if ep is None:
        known = sorted(table) + sorted(ALIASES.get(kind, {}))
        hint = did_you_mean(name, known, template="did you mean {!r}? ", cutoff=0.5)
        what = f"{param} {name!r}" if param else f"{kind} {name!r}"
        raise PluginError(f"unknown {what} ({hint}known: {', '.join(known)})")
    try:
        return ep.load()
    except (ImportError, AttributeError) as exc:
        raise PluginError(f"{kind} {name!r}: cannot load {ep.value} ({exc})") from None


def make_plugin(
    kind: str,
    name: str,
    params: Mapping[str, Any] | None = None,
    *,
    context: PluginContext | None = None,
    param: str | None = None,
) -> Any:
    """An instance of the plugin registered as ``name``: ``cls.from_params(params, context=context)``."""
    cls = load_plugin(kind, name, param=param)
    build = getattr(cls, "from_params", None)
    if build is None:
        raise PluginError(
            f"{kind} {name!r}: {cls.__module__}.{cls.__qualname__} has no from_params(params, *, context) classmethod"
        )
    return build(params, context=context or PluginContext())


def __getattr__(name: str) -> Any:
    if name == "REGISTRY":  # the dict of navlab <= 0.x; one release of read-only compatibility
        warnings.warn(
            "navlab.plugins.REGISTRY is deprecated: plugins are entry points (plugin_names, load_plugin)",
            NavlabDeprecationWarning,
            stacklevel=2,
        )
        return {kind: {n: ep.value for n, ep in _entry_points(group).items()} for kind, (group, _) in KINDS.items()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
