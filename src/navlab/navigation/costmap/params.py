"""costmap_2d's parameters: ROS 1 names and defaults, Nav2 spellings accepted where they map.

One costmap's dict is what a ROS 1 user writes under ``global_costmap:`` or ``local_costmap:`` (the
common file merged in): flat costmap parameters, either a ``plugins:`` list of ``{name, type}`` (or
Nav2's list of names with a ``plugin:`` key in each namespace) or none (ROS 1's pre-hydro layout:
``static_map: true`` gives static + obstacle + inflation), a namespace dict per layer
(``inflation_layer: {inflation_radius: 0.3}``, or the dotted ``inflation_layer.inflation_radius``), and
one dict per name in ``observation_sources``. A layer reads the costmap-level value of each of its
parameters unless its namespace sets it. Distances in metres, frequencies in Hz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

from navlab.core import ParamSpec, canonical_params, check_ceiling, check_unknown_key, read_params
from navlab.navigation.errors import NavigationError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

T = TypeVar("T", bound="DataclassInstance")

STATIC = "costmap_2d::StaticLayer"
OBSTACLE = "costmap_2d::ObstacleLayer"
INFLATION = "costmap_2d::InflationLayer"

# Nav2 spelling -> ROS 1 name, for layer and observation-source parameters
ALIASES: dict[str, str] = {
    "obstacle_max_range": "obstacle_range",
    "raytrace_max_range": "raytrace_range",
    "inflate_around_unknown": "inflate_unknown",
}
# accepted and ignored (runtime or Nav2-only settings with no effect on the pure layers)
IGNORED: frozenset[str] = frozenset(
    {
        "use_sim_time",
        "filters",
        "plugin",
        "map_subscribe_transient_local",
        "initial_transform_timeout",
        "clearable_layers",
        "footprint_topic",
        # map_type: voxel's 3-D settings (a planar lidar fills one layer)
        "origin_z",
        "z_resolution",
        "z_voxels",
        "unknown_threshold",
        "mark_threshold",
        "publish_voxel_map",
    }
)


@dataclass
class PluginSpec:
    """One entry of ``plugins:``: the layer's ``name`` (its namespace) and its ROS ``type``."""

    name: str
    type: str


@dataclass
class ObservationSource:
    """One sensor of ``observation_sources`` (ROS 1 obstacle layer names and defaults; ranges in m)."""

    sensor_frame: str = ""
    data_type: str = "LaserScan"
    topic: str = ""
    marking: bool = True
    clearing: bool = False
    obstacle_range: float = 2.5
    raytrace_range: float = 3.0
    obstacle_min_range: float = 0.0
    raytrace_min_range: float = 0.0
    min_obstacle_height: float = 0.0
    max_obstacle_height: float = 2.0
    inf_is_valid: bool = False
    expected_update_rate: float = 0.0
    observation_persistence: float = 0.0
    PARAMS: ClassVar[ParamSpec]


@dataclass
class StaticLayerParams:
    """``costmap_2d::StaticLayer``: how ``/map`` occupancy (-1, 0..100) becomes costs."""

    enabled: bool = True
    map_topic: str = "map"
    first_map_only: bool = False
    subscribe_to_updates: bool = False
    track_unknown_space: bool = False
    use_maximum: bool = False
    lethal_cost_threshold: int = 100
    unknown_cost_value: int = -1
    trinary_costmap: bool = True
    PARAMS: ClassVar[ParamSpec]


@dataclass
class ObstacleLayerParams:
    """``costmap_2d::ObstacleLayer``: marking and clearing from sensor data (ranges in m)."""

    enabled: bool = True
    obstacle_range: float = 2.5
    raytrace_range: float = 3.0
    obstacle_min_range: float = 0.0
    raytrace_min_range: float = 0.0
    max_obstacle_height: float = 2.0
    track_unknown_space: bool = False
    footprint_clearing_enabled: bool = True
    combination_method: int = 1
    observation_sources: str = ""
    # navlab (costmap.hidden_cells; the obstacle layer only, 0 = off: costmap_2d's behaviour): costs (0..252) for
    # never-observed cells likely to be closed: those in a return's laser shadow within occluded_unknown_range m of
    # the sensor (0: the source's raytrace_range) and occluded_unknown_depth m of the return (0: no limit), those
    # within unknown_near_obstacle_distance m of a marked cell
    occluded_unknown_cost: int = 0
    occluded_unknown_range: float = 0.0
    occluded_unknown_depth: float = 0.0
    unknown_near_obstacle_cost: int = 0
    unknown_near_obstacle_distance: float = 0.5
    PARAMS: ClassVar[ParamSpec]


@dataclass
class InflationLayerParams:
    """``costmap_2d::InflationLayer``: ``inflation_radius`` (m) and the decay ``cost_scaling_factor`` (1/m)."""

    enabled: bool = True
    inflation_radius: float = 0.55
    cost_scaling_factor: float = 10.0
    inflate_unknown: bool = False
    PARAMS: ClassVar[ParamSpec]


@dataclass
class CostmapParams:
    """costmap_2d's costmap-level parameters (ROS 1 names and defaults) plus the parsed structure.

    ``footprint`` is ROS's string form ("[[x, y], ...]", "[]" = use ``robot_radius``); a YAML list is accepted.
    ``plugins``, ``sources`` and ``namespaces`` are filled by :func:`costmap_params`.
    """

    global_frame: str = "map"
    robot_base_frame: str = "base_link"
    update_frequency: float = 5.0
    publish_frequency: float = 0.0
    transform_tolerance: float = 0.2
    static_map: bool = True
    rolling_window: bool = False
    always_send_full_costmap: bool = False
    map_type: str = "costmap"
    width: float = 10.0
    height: float = 10.0
    resolution: float = 0.05
    origin_x: float = 0.0
    origin_y: float = 0.0
    # defaults the layers inherit
    map_topic: str = "map"
    track_unknown_space: bool = False
    lethal_cost_threshold: int = 100
    unknown_cost_value: int = -1
    trinary_costmap: bool = True
    use_maximum: bool = False
    obstacle_range: float = 2.5
    raytrace_range: float = 3.0
    max_obstacle_height: float = 2.0
    observation_sources: str = ""
    inflation_radius: float = 0.55
    cost_scaling_factor: float = 10.0
    # the robot
    footprint: str = "[]"
    robot_radius: float = 0.46
    footprint_padding: float = 0.01
    # structure (not flat parameters)
    plugins: list[PluginSpec] = field(default_factory=list)
    sources: dict[str, ObservationSource] = field(default_factory=dict)
    namespaces: dict[str, dict[str, Any]] = field(default_factory=dict)
    PARAMS: ClassVar[ParamSpec]

    def validate(self) -> None:
        """Raise ``NavigationError`` naming the first bad parameter, its value and what was expected."""
        for name in (
            "update_frequency",
            "publish_frequency",
            "transform_tolerance",
            "width",
            "height",
            "obstacle_range",
            "raytrace_range",
            "inflation_radius",
            "cost_scaling_factor",
        ):
            _non_negative("costmap", name, getattr(self, name))
        for name in ("width", "height", "resolution"):
            if getattr(self, name) <= 0:
                raise NavigationError(f"costmap parameter {name}: expected > 0, got {getattr(self, name)}")
        for name in ("origin_x", "origin_y", "robot_radius", "footprint_padding"):
            _finite("costmap", name, getattr(self, name))
        for name in ("update_frequency", "publish_frequency"):
            check_ceiling(NavigationError, "costmap", name, getattr(self, name), "rate")
        check_ceiling(
            NavigationError,
            "costmap",
            "width x height / resolution²",
            (self.width / self.resolution) * (self.height / self.resolution),
            "grid_cells",
        )
        for name in ("robot_radius", "footprint_padding"):
            check_ceiling(NavigationError, "costmap", name, abs(getattr(self, name)), "footprint_m")
        if self.map_type not in ("costmap", "voxel"):
            raise NavigationError(f"costmap parameter map_type: expected 'costmap' or 'voxel', got {self.map_type!r}")


def _finite(what: str, name: str, value: float) -> None:
    if not math.isfinite(value):
        raise NavigationError(f"{what} parameter {name}: expected a finite number, got {value!r}")


def _non_negative(what: str, name: str, value: float) -> None:
    _finite(what, name, value)
    if value < 0:
        raise NavigationError(f"{what} parameter {name}: expected >= 0, got {value}")


def _split_dotted(values: dict[str, Any]) -> dict[str, Any]:
    """``{"inflation_layer.inflation_radius": 0.3}`` -> ``{"inflation_layer": {"inflation_radius": 0.3}}``."""
    out: dict[str, Any] = {}
    for key, val in values.items():
        if isinstance(key, str) and "." in key:
            head, _, tail = key.partition(".")
            sub = out.setdefault(head, {})
            if not isinstance(sub, dict):
                raise NavigationError(f"costmap parameter {head}: both a value and a namespace ({key})")
            _merge(sub, _split_dotted({tail: val}))
        elif isinstance(val, dict) and isinstance(out.get(key), dict):
            _merge(out[key], val)
        else:
            out[key] = val
    return out


def _merge(into: dict[str, Any], values: dict[str, Any]) -> None:
    """Deep update: ``a.b.c`` and ``a.b.d`` both land in ``a: {b: {c, d}}`` (a shallow update kept the last)."""
    for key, val in values.items():
        if isinstance(val, dict) and isinstance(into.get(key), dict):
            _merge(into[key], val)
        else:
            into[key] = val


def _parse_plugins(raw: Any, namespaces: dict[str, Any]) -> list[PluginSpec]:
    """ROS 1's ``[{name, type}, ...]`` or Nav2's ``[name, ...]`` with ``name: {plugin: type}``."""
    if not isinstance(raw, list):
        raise NavigationError(f"costmap parameter plugins: expected a list of {{name, type}}, got {raw!r}")
    out = []
    for k, item in enumerate(raw):
        if isinstance(item, dict):
            unknown = set(item) - {"name", "type"}
            if unknown or "name" not in item or "type" not in item:
                raise NavigationError(f"costmap parameter plugins[{k}]: expected {{name: .., type: ..}}, got {item!r}")
            out.append(PluginSpec(str(item["name"]), str(item["type"])))
        elif isinstance(item, str):
            ns = namespaces.get(item)
            if not isinstance(ns, dict) or "plugin" not in ns:
                raise NavigationError(
                    f"costmap parameter plugins[{k}] {item!r}: Nav2 style needs "
                    f"'{item}: {{plugin: <type>}}' (or write {{name: {item}, type: <type>}})"
                )
            out.append(PluginSpec(item, str(ns["plugin"])))
        else:
            raise NavigationError(f"costmap parameter plugins[{k}]: expected {{name, type}} or a name, got {item!r}")
    names = [p.name for p in out]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise NavigationError(f"costmap parameter plugins: layer names must be unique, {sorted(dup)} repeated")
    return out


def default_plugins(static_map: bool) -> list[PluginSpec]:
    """ROS 1's layers when there is no ``plugins:`` key: [static] + obstacle + inflation."""
    out = [PluginSpec("static_layer", STATIC)] if static_map else []
    return [*out, PluginSpec("obstacle_layer", OBSTACLE), PluginSpec("inflation_layer", INFLATION)]


def costmap_params(values: dict[str, Any] | None = None) -> CostmapParams:
    """Parse one costmap's parameter dict (see the module docstring) into validated ``CostmapParams``."""
    values = _split_dotted(dict(values or {}))
    flat: dict[str, Any] = {}
    namespaces: dict[str, dict[str, Any]] = {}
    for key, val in values.items():
        if key in IGNORED:
            continue
        if isinstance(val, dict):
            namespaces[str(key)] = dict(val)
        elif key in ("sources", "namespaces"):
            raise NavigationError(f"unknown costmap parameter '{key}'")
        elif key != "plugins":
            flat[key] = val
    if isinstance(flat.get("footprint"), list | tuple):
        flat["footprint"] = str([list(map(float, p)) for p in flat["footprint"]])
    if isinstance(flat.get("observation_sources"), list | tuple):
        flat["observation_sources"] = " ".join(map(str, flat["observation_sources"]))
    params = read_params(CostmapParams, flat)
    if "plugins" in values:
        params.plugins = _parse_plugins(values["plugins"], namespaces)
    else:
        params.plugins = default_plugins(params.static_map)
    # observation sources are named in the obstacle layers' (or the costmap's) observation_sources
    owner: dict[str, dict[str, Any]] = {src: {} for src in params.observation_sources.split()}
    for plugin in params.plugins:
        ns = namespaces.get(plugin.name, {})
        listed = ns.get("observation_sources", "")
        for src in listed.split() if isinstance(listed, str) else list(map(str, listed)):
            owner[src] = ns
    for src, ns in owner.items():
        raw = namespaces.get(src, ns.get(src))  # ROS 1: costmap level; Nav2: inside the layer's namespace
        if not isinstance(raw, dict):
            raise NavigationError(
                f"costmap parameter observation_sources names {src!r} but there is no "
                f"'{src}: {{topic: ..., data_type: LaserScan, ...}}'"
            )
        params.sources[src] = observation_source(
            raw, params, name=src, layer=canonical_params(ns, LAYER_SPEC, what=src)
        )
    known = {p.name for p in params.plugins} | set(params.sources)
    for key, ns in namespaces.items():
        if key not in known:  # another plugin's section (ROS ignores it) or a misspelt layer: check_unknown_key
            check_unknown_key(
                key, sorted(known) + [f.name for f in fields(CostmapParams)], what="costmap", error=NavigationError
            )
            continue
        params.namespaces[key] = ns
    return params


def _layer_keys(values: dict[str, Any]) -> dict[str, Any]:
    """A layer's or source's own keys: its nested sections (a source inside its layer) dropped, a YAML list of
    ``observation_sources`` joined into ROS's space-separated string."""
    out = {key: val for key, val in values.items() if not isinstance(val, dict)}
    if isinstance(out.get("observation_sources"), list | tuple):
        out["observation_sources"] = " ".join(map(str, out["observation_sources"]))
    return out


_RANGES = dict.fromkeys(("obstacle_range", "raytrace_range", "obstacle_min_range", "raytrace_min_range"), 0.0)
LAYER_SPEC = ParamSpec("layer", NavigationError, aliases=ALIASES, ignored=IGNORED, prepare=_layer_keys)
StaticLayerParams.PARAMS = replace(
    LAYER_SPEC, what="static_layer", at_least={"lethal_cost_threshold": 1}, at_most={"lethal_cost_threshold": 100}
)
_HIDDEN_COSTS = dict.fromkeys(("occluded_unknown_cost", "unknown_near_obstacle_cost"), 0)
ObstacleLayerParams.PARAMS = replace(
    LAYER_SPEC,
    what="obstacle_layer",
    at_least={
        **_RANGES,
        **_HIDDEN_COSTS,
        "occluded_unknown_range": 0.0,
        "occluded_unknown_depth": 0.0,
        "unknown_near_obstacle_distance": 0.0,
    },
    at_most=dict.fromkeys(_HIDDEN_COSTS, 252),
    choices={"combination_method": (0, 1)},  # overwrite, maximum
)
InflationLayerParams.PARAMS = replace(
    LAYER_SPEC, what="inflation_layer", at_least={"inflation_radius": 0.0, "cost_scaling_factor": 0.0}
)
ObservationSource.PARAMS = replace(LAYER_SPEC, what="observation source", at_least=_RANGES)
CostmapParams.PARAMS = ParamSpec("costmap", NavigationError)


def observation_source(
    values: dict[str, Any], costmap: CostmapParams, *, name: str, layer: dict[str, Any] | None = None
) -> ObservationSource:
    """One observation source; its ranges default to its layer's (else the costmap's) ``obstacle_range``,
    ``raytrace_range`` and ``max_obstacle_height``."""
    inherited = {
        key: (layer or {}).get(key, getattr(costmap, key))
        for key in ("obstacle_range", "raytrace_range", "max_obstacle_height")
    }
    what = f"observation source {name}"
    own = canonical_params(values, LAYER_SPEC, what=what)
    src = read_params(ObservationSource, {**inherited, **own}, what=what)
    if src.min_obstacle_height > src.max_obstacle_height:
        raise NavigationError(
            f"observation source {name} parameters min_obstacle_height {src.min_obstacle_height} > "
            f"max_obstacle_height {src.max_obstacle_height}: expected min <= max"
        )
    if src.data_type not in ("LaserScan", "PointCloud", "PointCloud2"):
        raise NavigationError(
            f"observation source {name} parameter data_type: expected LaserScan, PointCloud or "
            f"PointCloud2, got {src.data_type!r}"
        )
    return src


def layer_params(cls: type[T], costmap: CostmapParams, name: str) -> T:
    """A layer's parameters: the costmap-level value of each of its fields, overridden by its namespace ``name``."""
    own = {f.name for f in fields(cls)}
    inherited = {f.name: getattr(costmap, f.name) for f in fields(CostmapParams) if f.name in own}
    ns = canonical_params(costmap.namespaces.get(name, {}), getattr(cls, "PARAMS", LAYER_SPEC), what=name)
    return read_params(cls, {**inherited, **ns}, what=name)
