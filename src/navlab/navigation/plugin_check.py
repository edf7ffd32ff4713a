"""``check_plugin(kind, name)``: does a registered plugin keep the contract of ``navlab.plugins``?

As Gymnasium's environment checker: it builds the plugin the way its host does (``from_params`` with an
empty parameter namespace, so ROS defaults, and the context the host gives), checks it against its
kind's Protocol, and runs one call on a tiny world: a 3 m x 3 m free costmap at 5 cm for controllers,
planners, layers and recoveries, a square room's scan for SLAM backends and laser models, one odometry
step for motion models. It raises ``PluginError`` naming the plugin and what broke, and returns the
instance it built. It lives here, above mapping and localization, because it builds their inputs.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab.core import Executor, Node
from navlab.errors import NavlabError
from navlab.grid import COST_FREE, COST_LETHAL, Grid, GridMap
from navlab.localization import AmclParams, Beams, field_from_map
from navlab.navigation.costmap.footprint import make_footprint
from navlab.navigation.costmap.params import costmap_params
from navlab.navigation.costmap_ros import Costmap2DROS
from navlab.navigation.move_base import short_name
from navlab.plugins import KINDS, ControlResult, MapLayer, PluginContext, PluginError, ScanLayer, load_plugin

RES = 0.05  # m/cell of the check's grids
SIZE = 60  # cells a side (3 m)
ORIGIN = (-1.5, -1.5, 0.0)  # the grids' lower-left corner (m): the robot starts at the centre


def check_plugin(kind: str, name: str) -> Any:
    """Build the plugin registered as ``name`` for ``kind``, check its Protocol, run one call; return it."""
    if kind not in KINDS:
        raise PluginError(f"unknown kind of plugin {kind!r} (kinds: {', '.join(KINDS)})")
    target = load_plugin(kind, name)
    try:
        return _CHECKS[kind](target, name)
    except PluginError:
        raise
    except (NavlabError, TypeError, ValueError, AttributeError, AssertionError) as exc:
        raise PluginError(f"{kind} {name!r} ({_where(target)}) fails its check: {exc}") from exc


def _where(target: Any) -> str:
    return f"{getattr(target, '__module__', '?')}:{getattr(target, '__qualname__', target)}"


def _build(target: Any, kind: str, name: str, params: Any, context: PluginContext) -> Any:
    if not callable(getattr(target, "from_params", None)):
        raise PluginError(f"{kind} {name!r} ({_where(target)}): no from_params(params, *, context) classmethod")
    instance = target.from_params(params, context=context)
    protocol = KINDS[kind][1]
    if not isinstance(instance, protocol):
        missing = [m for m in _members(protocol) if not hasattr(instance, m)]
        raise PluginError(
            f"{kind} {name!r} ({_where(target)}) does not implement {protocol.__name__}: missing {', '.join(missing)}"
        )
    return instance


def _members(protocol: type) -> list[str]:
    """The public names a Protocol declares (methods and annotated attributes, its bases' included)."""
    names: set[str] = set()
    for base in protocol.__mro__:
        if base.__module__ != "typing" and base is not object:
            names |= {k for k in [*vars(base), *vars(base).get("__annotations__", {})] if not k.startswith("_")}
    return sorted(names)


def _expect(ok: bool, what: str) -> None:
    if not ok:
        raise AssertionError(what)


def _free_grid(frame: str = "odom") -> Grid:
    return Grid(np.full((SIZE, SIZE), COST_FREE, np.uint8), RES, ORIGIN, frame)


def _room() -> GridMap:
    """The 3 m x 3 m map with a wall all round (occupancy %, ``map`` frame)."""
    data = np.zeros((SIZE, SIZE), np.int8)
    data[[0, -1], :] = 100
    data[:, [0, -1]] = 100
    return GridMap(data, RES, ORIGIN, frame_id="map")


def _room_scan(n: int = 90) -> tuple[np.ndarray, float, float]:
    """Ranges (m) from the centre of the room's walls (1.45 m away) over 360°: ranges, angle_min, increment."""
    a = -math.pi + 2 * math.pi * np.arange(n) / n
    return np.minimum(1.45 / np.maximum(np.abs(np.cos(a)), np.abs(np.sin(a))), 10.0), -math.pi, 2 * math.pi / n


def _controller(target: Any, name: str) -> Any:
    context = PluginContext(
        name=short_name(name),
        rng=np.random.default_rng(0),
        footprint=make_footprint(robot_radius=0.2),
        controller_frequency=20.0,
    )
    ctrl = _build(target, "controller", name, {}, context)
    ctrl.set_plan(np.column_stack([np.linspace(0.0, 1.2, 25), np.zeros(25), np.zeros(25)]))
    out = ctrl.compute_velocity((0.0, 0.0, 0.0), (0.0, 0.0), _free_grid())
    _expect(isinstance(out, ControlResult), f"compute_velocity returned {type(out).__name__}, not a ControlResult")
    _expect(math.isfinite(out.v) and math.isfinite(out.w), f"command ({out.v}, {out.w}) is not finite")
    plan = np.asarray(out.local_plan)
    _expect(plan.ndim == 2 and plan.shape[1] == 3, f"local_plan has shape {plan.shape}, expected (N, 3)")
    _expect(isinstance(ctrl.is_goal_reached((0.0, 0.0, 0.0), (0.0, 0.0)), bool), "is_goal_reached is not a bool")
    return ctrl


def _planner(target: Any, name: str) -> Any:
    planner = _build(
        target, "global_planner", name, {}, PluginContext(name=short_name(name), rng=np.random.default_rng(0))
    )
    start, goal = (-1.0, -1.0, 0.0), (1.0, 1.0, 0.0)
    path = planner.make_plan(_free_grid("map"), start, goal)
    _expect(path is not None, f"no path across a free grid ({planner.last_failure!r})")
    path = np.asarray(path, dtype=np.float64)
    _expect(path.ndim == 2 and path.shape[1] >= 2 and len(path) >= 2, f"path has shape {path.shape}")
    _expect(
        math.dist(path[0, :2], start[:2]) <= 2 * RES and math.dist(path[-1, :2], goal[:2]) <= 2 * RES,
        f"path runs from {path[0, :2]} to {path[-1, :2]}, not from {start[:2]} to {goal[:2]}",
    )
    _expect(planner.last_failure == "", f"last_failure is {planner.last_failure!r} after a success")
    return planner


def _layer(target: Any, name: str) -> Any:
    costmap = costmap_params(
        {
            "global_frame": "map",
            "plugins": [{"name": "checked", "type": name}],
            "robot_radius": 0.2,
            "width": 3.0,
            "height": 3.0,
            "resolution": RES,
            "origin_x": ORIGIN[0],
            "origin_y": ORIGIN[1],
        }
    )
    context = PluginContext(name="checked", footprint=make_footprint(robot_radius=0.2), costmap=costmap)
    layer = _build(target, "costmap_layer", name, {}, context)
    master = _free_grid("map")
    layer.match_size(master)
    if isinstance(layer, MapLayer):
        layer.set_map(_room())
        _expect(
            layer.on_map_obstacle((-1.49, 0.0)) and not layer.on_map_obstacle((0.0, 0.0)),
            "on_map_obstacle does not see the map's wall (or sees one in the free middle)",
        )
    if isinstance(layer, ScanLayer):
        ranges, a0, inc = _room_scan()
        a = a0 + inc * np.arange(len(ranges))
        layer.add_scan((0.0, 0.0), np.column_stack([ranges * np.cos(a), ranges * np.sin(a)]))
    layer.update_bounds((0.0, 0.0, 0.0))
    layer.update_costs(master)
    _expect(master.data.shape == (SIZE, SIZE) and master.data.dtype == np.uint8, "update_costs changed the master")
    if isinstance(layer, MapLayer | ScanLayer):
        _expect(int(master.data.max()) == COST_LETHAL, "the walls it was given are not lethal in the master")
    layer.reset()
    return layer


def _recovery(target: Any, name: str) -> Any:
    node = Node(Executor(seed=0), name="check_plugin")
    cm = Costmap2DROS(
        node,
        "local_costmap",
        {
            "global_frame": "odom",
            "rolling_window": True,
            "static_map": False,
            "width": 3.0,
            "height": 3.0,
            "resolution": RES,
            "robot_radius": 0.2,
        },
    )
    pose = (0.0, 0.0, 0.0)
    cm.layered.update_map(pose)
    behavior = _build(target, "recovery", name, {}, PluginContext(name=short_name(name), rng=node.rng))
    behavior.start(pose)
    cmd = behavior.step(pose, {"global": cm, "local": cm})
    _expect(
        cmd is None or (len(cmd) == 2 and all(math.isfinite(c) for c in cmd)),
        f"step returned {cmd!r}, expected None or a finite (v, w)",
    )
    return behavior


def _slam(target: Any, name: str) -> Any:
    _expect(isinstance(target.parameters(), dict), "parameters() is not a dict")
    slam = _build(target, "slam_backend", name, {}, PluginContext(name=name, rng=np.random.default_rng(0)))
    ranges, a0, inc = _room_scan(181)
    slam.add_scan(ranges, a0, inc, np.zeros(3), range_max=10.0, stamp_ns=0)
    _expect(np.asarray(slam.trajectory()).reshape(-1, 3).shape[1] == 3, "trajectory() is not (M, 3)")
    grid = slam.current_map()
    _expect(grid is None or isinstance(grid, GridMap), f"current_map() returned {type(grid).__name__}")
    _expect(isinstance(slam.stats(), dict), "stats() is not a dict")
    return slam


def _laser_model(target: Any, name: str) -> Any:
    field = field_from_map(_room())
    model = _build(target, "laser_model", name, AmclParams(), PluginContext(map_field=field))
    ranges, a0, inc = _room_scan()
    beams = Beams(a0 + inc * np.arange(len(ranges)), ranges, np.ones(len(ranges), bool), 0.1, 10.0)
    particles = np.array([[0.0, 0.0, 0.0], [0.5, 0.3, 1.0], [-0.6, 0.2, -2.0]])
    w = np.asarray(model.weights(particles, beams, (0.0, 0.0, 0.0)), dtype=np.float64)
    _expect(
        w.shape == (3,) and bool(np.isfinite(w).all()) and bool((w > 0).all()),
        f"weights {w} are not 3 finite positive scores",
    )
    _expect(w[0] > w[2], "the true pose does not score above a wrong one")
    return model


def _motion_model(target: Any, name: str) -> Any:
    _expect(callable(target), "is not callable")
    particles = np.zeros((50, 3))
    target(particles, (0.0, 0.0, 0.0), (0.5, 0.0, 0.1), (0.1, 0.1, 0.1, 0.1), np.random.default_rng(0))
    _expect(bool(np.isfinite(particles).all()), "moved particles are not finite")
    _expect(abs(float(particles[:, 0].mean()) - 0.5) < 0.2, "particles did not follow a 0.5 m step")
    return target


_CHECKS = {
    "controller": _controller,
    "global_planner": _planner,
    "costmap_layer": _layer,
    "recovery": _recovery,
    "slam_backend": _slam,
    "laser_model": _laser_model,
    "motion_model": _motion_model,
}
