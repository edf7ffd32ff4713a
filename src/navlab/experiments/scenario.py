"""Scenarios as YAML: what one experiment runs, trial after trial (the paper's Section V in a file).

```yaml
name: obstacles_after_mapping
world: room_obstacles        # shipped name or .world file (relative paths: beside this file), or generated:
                             #   "clutter:seed=3,fill=0.3,smooth=2" one BARN-style clutter world (world.clutter),
                             #   "clutter_suite:n=50,seed=0" trial i drives world i (mod n) of the graded suite;
                             #   clutter worlds are mapless, start and goal (10 m ahead, in odom) are the world's
map: map_first               # true (the world's true map) | map_first (SLAM in map_world first) | none | FILE
map_world: room              # the world mapped first: the obstacles come after mapping
robot: mybot
start: [0.0, 0.0, 0.0]       # x y yaw in the world (m, rad)
controller: trajectory       # trajectory | dwa | mppi | a ROS plugin name (default: the parameter files')
params: null                 # folder of move_base's ROS 1 parameter files (default: the shipped robot's)
overrides: {local_costmap.update_frequency: 5.0}   # move_base parameters
obstacles: [{t: 20.0, spec: "cylinder:x=-1.0,y=-0.45,radius=0.15,length=0.6"}]   # added while running
#   t: [lo, hi] draws the time per trial (from the trial's seed); frame: robot places x, y (and yaw) in the
#   robot's frame at that time (e.g. x=0.7: 0.7 m ahead of it), frame: world (default) in the world; never on the
#   start, a goal or the robot (see scenario_obstacles: a robot-frame one about to reach a goal appears earlier)
goals: [[4.3, 1.0, 0.0], [-3.5, -0.5, 3.14]]      # map frame (odom with map: none)
trials: 20                   # trial k runs with seed + k
seed: 0
time_limit: 90.0             # s per goal
goal_tolerance_m: 0.3        # the truth's goal region: a goal is reached when the robot truly ends this close
wheel_controller: diff_drive_controller   # gazebo_ros_diff_drive (default) | diff_drive_controller | a ros_control YAML
ekf: true                    # robot_localization's ekf_node (true: params/ekf.yaml; or a file); needs the controller
collision_monitor: false     # Nav2's collision monitor between move_base and the wheels (default: the robot's, on
                             #   for mybot; false: move_base drives the wheels directly, as in the paper)
disturbances: {wheel_radius_error: [0.03, 0.0], slip_patches: [{x: 1.0, y: 0.0, radius: 0.5, mu: 0.05}]}
```
Unknown keys get "did you mean"; bad values one line naming the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from navlab.errors import did_you_mean
from navlab.experiments.errors import ExperimentError

MAP_MODES = ("true", "map_first", "none")
CLUTTER_KEYS: dict[str, dict[str, type]] = {
    "clutter": {"seed": int, "fill": float, "smooth": int},
    "clutter_suite": {"n": int, "seed": int},
}


@dataclass
class Scenario:
    """One experiment's settings (see the module docstring); ``path`` is the file it came from."""

    name: str = "scenario"
    world: str = "room_obstacles"
    map: str = "true"
    map_world: str | None = None
    robot: str = "mybot"
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    controller: str | None = None
    params: str | None = None
    overrides: dict[str, Any] = field(default_factory=dict)
    obstacles: list[dict[str, Any]] = field(default_factory=list)
    goals: list[tuple[float, float, float]] = field(default_factory=list)
    trials: int = 1
    seed: int = 0
    time_limit: float = 90.0
    goal_tolerance_m: float = 0.3
    wheel_controller: str = "gazebo_ros_diff_drive"
    ekf: str | None = None
    collision_monitor: bool | None = None  # None: the robot's default (the launch's)
    disturbances: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None

    def resolve(self, value: str | None) -> str | None:
        """A file named in the scenario, relative to the scenario file; shipped names stay as they are."""
        if value is None or self.path is None:
            return value
        candidate = self.path.parent / value
        return str(candidate) if candidate.exists() else value

    def navigation_options(self) -> dict[str, Any]:
        """``run_navigation``'s wheel controller, EKF, disturbances and launch arguments keywords."""
        monitor = {} if self.collision_monitor is None else {"collision_monitor": str(self.collision_monitor).lower()}
        return {
            "wheel_controller": self.resolve(self.wheel_controller) or self.wheel_controller,
            "ekf": self.resolve(self.ekf),
            "disturbances": dict(self.disturbances),
            "launch_args": monitor,
        }


def _pose(value: Any, where: str) -> tuple[float, float, float]:
    try:
        if isinstance(value, str | bytes) or any(isinstance(v, bool | str) for v in value):
            raise TypeError
        x, y, yaw = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ExperimentError(f"{where}: expected [x, y, yaw] numbers, got {value!r}") from None
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise ExperimentError(f"{where}: expected finite numbers, got {value!r}")
    return x, y, yaw


def _time(t: Any, where: str) -> float:
    if isinstance(t, bool) or not (isinstance(t, int | float) and math.isfinite(t) and t >= 0):
        raise ExperimentError(f"{where}: expected a time >= 0 s, got {t!r}")
    return float(t)


def _obstacle(ob: Any, where: str) -> dict[str, Any]:
    """``{t, spec[, frame]}`` with ``t`` seconds or ``[lo, hi]`` and ``frame`` world (default) or robot."""
    if (
        not isinstance(ob, dict)
        or not {"t", "spec"} <= set(ob) <= {"t", "spec", "frame"}
        or not isinstance(ob["spec"], str)
    ):
        raise ExperimentError(
            f"{where}: expected {{t: seconds, spec: 'cylinder:x=..,y=..'[, frame: world|robot]}}, got {ob!r}"
        )
    t = ob["t"]
    if isinstance(t, list):
        if len(t) != 2 or _time(t[0], f"{where}.t") > _time(t[1], f"{where}.t"):
            raise ExperimentError(f"{where}.t: expected seconds or [lo, hi] with lo <= hi, got {t!r}")
    else:
        _time(t, f"{where}.t")
    if ob.get("frame", "world") not in ("world", "robot"):
        raise ExperimentError(f"{where}.frame: expected world or robot, got {ob['frame']!r}")
    return dict(ob)


def clutter_world_spec(world: str, *, where: str = "world") -> dict[str, Any] | None:
    """``{"kind": "clutter" | "clutter_suite", ...options}`` for a generated clutter world (see the module
    docstring), None for a file or shipped name."""
    kind, sep, rest = world.partition(":")
    if not sep or kind not in CLUTTER_KEYS:
        return None
    spec: dict[str, Any] = {"kind": kind}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        types = CLUTTER_KEYS[kind]
        if not eq or key not in types:
            hint = did_you_mean(key, types)
            raise ExperimentError(f"{where}: {world!r}: {item!r} is not one of {', '.join(types)}=value{hint}")
        try:
            spec[key] = types[key](value)
        except ValueError:
            raise ExperimentError(f"{where}: {world!r}: {key}={value!r} is not {types[key].__name__}") from None
    if kind == "clutter" and not {"fill", "smooth"} <= set(spec):
        raise ExperimentError(f"{where}: {world!r}: clutter needs fill=0..1 and smooth=rounds (seed=S optional)")
    if (
        not 0.0 <= spec.get("fill", 0.0) <= 1.0
        or min(spec.get("smooth", 0), spec.get("seed", 0)) < 0
        or spec.get("n", 1) < 1
    ):
        raise ExperimentError(f"{where}: {world!r}: expected fill in [0, 1], smooth and seed >= 0, n >= 1")
    return spec


def scenario_from_dict(data: Any, *, where: str = "scenario", path: Path | None = None) -> Scenario:
    """A validated ``Scenario`` from parsed YAML."""
    if not isinstance(data, dict):
        raise ExperimentError(f"{where}: expected a mapping of scenario keys, got {type(data).__name__}")
    names = [f.name for f in fields(Scenario) if f.name != "path"]
    for key in data:
        if key not in names:
            hint = did_you_mean(key, names)
            raise ExperimentError(f"{where}: unknown key '{key}'{hint} (keys: {', '.join(names)})")
    sc = Scenario(path=path)
    if isinstance(data.get("map"), bool):  # YAML reads `map: true` as a boolean
        data = {**data, "map": "true" if data["map"] else "none"}
    for key in ("name", "world", "map", "robot"):
        if key in data:
            if not isinstance(data[key], str) or not data[key]:
                raise ExperimentError(f"{where}: {key}: expected a non-empty string, got {data[key]!r}")
            setattr(sc, key, data[key])
    for key in ("map_world", "controller", "params"):
        if data.get(key) is not None:
            setattr(sc, key, str(data[key]))
    if sc.map not in MAP_MODES and not sc.map.endswith(".yaml"):
        raise ExperimentError(f"{where}: map: expected {', '.join(MAP_MODES)} or a map .yaml file, got {sc.map!r}")
    if "start" in data:
        sc.start = _pose(data["start"], f"{where}: start")
    goals = data.get("goals")
    clutter = clutter_world_spec(sc.world, where=f"{where}: world")
    if clutter is not None:
        if "start" in data or data.get("map", "none") != "none":
            raise ExperimentError(
                f"{where}: a clutter world sets its own start and is mapless: leave out 'start' "
                "and 'map' (or write map: none)"
            )
        sc.map = "none"
        goals = goals if goals is not None else [[10.0, 0.0, 0.0]]  # the world's goal, in odom (= the start)
    if not isinstance(goals, list) or not goals:
        raise ExperimentError(f"{where}: goals: expected a list of [x, y, yaw], got {goals!r}")
    sc.goals = [_pose(g, f"{where}: goals[{k}]") for k, g in enumerate(goals)]
    overrides = data.get("overrides") or {}
    if not isinstance(overrides, dict):
        raise ExperimentError(f"{where}: overrides: expected a mapping of move_base parameters, got {overrides!r}")
    sc.overrides = dict(overrides)
    obstacles = data.get("obstacles") or []
    if not isinstance(obstacles, list):
        raise ExperimentError(f"{where}: obstacles: expected a list of {{t: seconds, spec: ...}}, got {obstacles!r}")
    sc.obstacles = [_obstacle(ob, f"{where}: obstacles[{k}]") for k, ob in enumerate(obstacles)]
    for key, low in (("trials", 1), ("seed", 0)):
        if key in data:
            v = data[key]
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise ExperimentError(f"{where}: {key}: expected an integer >= {low}, got {v!r}")
            setattr(sc, key, v)
    monitor = data.get("collision_monitor")
    if monitor is not None:
        if not isinstance(monitor, bool):
            raise ExperimentError(f"{where}: collision_monitor: expected true or false, got {monitor!r}")
        sc.collision_monitor = monitor
    for key, unit in (("time_limit", "seconds"), ("goal_tolerance_m", "metres")):
        if key in data:
            v = data[key]
            if isinstance(v, bool) or not isinstance(v, int | float) or not (math.isfinite(v) and v > 0):
                raise ExperimentError(f"{where}: {key}: expected {unit} > 0, got {v!r}")
            setattr(sc, key, float(v))
    _future_work_keys(sc, data, where)
    return sc


def _future_work_keys(sc: Scenario, data: dict[str, Any], where: str) -> None:
    """wheel_controller, ekf and disturbances, checked here so a bad value fails before any trial."""
    from navlab.errors import NavlabError
    from navlab.sim import parse_disturbances

    if "wheel_controller" in data:
        if not isinstance(data["wheel_controller"], str) or not data["wheel_controller"]:
            raise ExperimentError(
                f"{where}: wheel_controller: expected gazebo_ros_diff_drive, diff_drive_controller "
                f"or a ros_control YAML file, got {data['wheel_controller']!r}"
            )
        sc.wheel_controller = data["wheel_controller"]
    ekf = data.get("ekf")
    sc.ekf = ("default" if ekf else None) if isinstance(ekf, bool) or ekf is None else str(ekf)
    if sc.ekf and sc.wheel_controller == "gazebo_ros_diff_drive":
        raise ExperimentError(f"{where}: ekf needs wheel_controller: diff_drive_controller (the EKF owns odom -> base)")
    dist = data.get("disturbances") or {}
    try:
        parse_disturbances(dist if isinstance(dist, dict) else {"": dist}, where=f"{where}: disturbances")
    except NavlabError as exc:
        raise ExperimentError(str(exc)) from None
    sc.disturbances = dict(dist)


def load_scenario(name_or_path: str | Path) -> Scenario:
    """A scenario file, or a shipped one by name (``empty_room``, ``obstacles_after_mapping``, ``refresh_rate``,
    ``clutter_suite``)."""
    from navlab import resources
    from navlab.core import read_yaml

    p = Path(name_or_path)
    if not p.is_file():
        shipped = resources.root() / "scenarios" / f"{p.name.removesuffix('.yaml')}.yaml"
        if not shipped.is_file():
            names = sorted(f.stem for f in (resources.root() / "scenarios").glob("*.yaml"))
            raise ExperimentError(f"no scenario file {str(name_or_path)!r} (shipped: {', '.join(names)})")
        p = shipped
    return scenario_from_dict(read_yaml(p), where=str(p), path=p.resolve())
