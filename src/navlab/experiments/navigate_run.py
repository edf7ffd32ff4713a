"""The paper's navigation step: the ``navigation`` launch (sim + map_server + amcl + move_base), goals sent
one after another, each scored from ground truth and the simulator's contacts.

``run_navigation`` is the Python API behind ``navlab navigate``. Each goal is judged by the simulator's truth:
``outcome`` is ``succeeded`` when the robot truly ended within ``goal_tolerance`` m of the goal, else move_base's
failure (``aborted`` | ``preempted`` | ``timeout``) or ``not_reached`` when move_base reported success from its
own (odometry/AMCL) estimate, ``stuck`` when move_base gave up for lack of progress or the robot truly stayed
within ``STUCK_RADIUS_M`` for the last ``STUCK_WINDOW_S`` s before the time ran out; ``move_base_outcome`` is
move_base's verdict beside it and ``false_success`` marks the disagreement. Also move_base's reason, time, path
length, ``near_goal_m`` (the closest the robot truly came to the goal), minimum clearance (m between the robot's
collision geometry and the world's, from MuJoCo), ``time_under_safety_s`` (time with the clearance under
``safety_distance``), ``near_miss`` (clearance under ``NEAR_MISS_M`` without a contact) and collisions
(contact episodes).
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from navlab.core import Node, Recorder, TfError
from navlab.experiments.navigate_monitor import SAFETY_DISTANCE_M, SAMPLE_S, NavMonitor
from navlab.experiments.plots import NavSnapshot
from navlab.experiments.session import Run, rounded, start_run
from navlab.geometry import compose2
from navlab.grid import Grid, GridMap
from navlab.navigation import STUCK_PREFIX, GoalOutcome, NavigationError, stuck_window
from navlab.world import true_map, unmapped_obstacles

if TYPE_CHECKING:
    from navlab.navigation import MoveBase

Pose = tuple[float, float, float]


GOAL_TOLERANCE_M = 0.3  # the truth's goal region: twice the shipped robots' xy_goal_tolerance (AMCL's error room)
NEAR_MISS_M = 0.05  # clearance (m) under which a drive without contact is flagged a near miss
STUCK_WINDOW_S, STUCK_RADIUS_M = 20.0, 0.5  # a timed-out robot that stayed this close this long was stuck


@dataclass
class NavigateResult:
    """Per-goal figures, the whole run's timing, and what the pictures need."""

    goals: list[dict[str, Any]]
    summary: dict[str, Any]
    grid: GridMap
    snapshots: list[NavSnapshot] = field(default_factory=list)  # per goal, the middle of the drive
    arrivals: list[NavSnapshot] = field(default_factory=list)  # per goal, when it ended (arrival or give-up)
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # the true path: (t s, x m, y m) at 10 Hz


def _move_base(run: Run) -> MoveBase:
    """The run's move_base node (navlab's, as the shipped launch starts it)."""
    from navlab.navigation import MoveBase

    mb = run.node("move_base")
    assert isinstance(mb, MoveBase)
    return mb


def _episodes(times: Sequence[float], t0: float, t1: float, gap: float = 0.25) -> int:
    """Contact episodes in [t0, t1]: runs of /collisions messages no more than ``gap`` s apart."""
    ts = [t for t in times if t0 <= t <= t1]
    return sum(1 for k, t in enumerate(ts) if k == 0 or t - ts[k - 1] > gap)


def _benchmark_times(
    path: Sequence[tuple[float, float, float]], goal: Any, tolerance: float, start_m: float = 0.1
) -> tuple[float | None, float | None]:
    """When (s, the monitor's clock) the true path ``(t, x, y)`` first left ``start_m`` m of its first point, and
    when it first came within ``tolerance`` m of ``goal`` after that (None: never) — the clock BARN's run.py keeps."""
    if not path:
        return None, None
    pts = np.asarray(path, dtype=np.float64)
    left = np.flatnonzero(np.hypot(*(pts[:, 1:3] - pts[0, 1:3]).T) >= start_m)
    if not left.size:
        return None, None
    near = np.flatnonzero(np.hypot(*(pts[left[0] :, 1:3] - np.asarray(goal[:2])).T) <= tolerance)
    return float(pts[left[0], 0]), (float(pts[left[0] + near[0], 0]) if near.size else None)


def _drive_goal(
    run: Run,
    mon: NavMonitor,
    goal: Pose,
    frame: str,
    timeout: float,
    shots: list[NavSnapshot] | None = None,
    world_T_frame: Pose = (0.0, 0.0, 0.0),
    tolerance: float = GOAL_TOLERANCE_M,
    *,
    shot: Any = None,
    say: Any = None,
) -> dict[str, Any]:
    """Send one goal (in ``frame``, which sits at ``world_T_frame``) and run until it ends or ``timeout`` s
    pass; ``shots`` collects ``shot()`` a second; ``say(text)`` gets a progress line every 10 simulated s.
    Judged by the truth (within ``tolerance`` m at the end) beside move_base's verdict (see the module
    docstring)."""
    mb = _move_base(run)
    t0 = mon.now_s()
    k0 = len(mon.path)
    next_say = t0 + 10.0
    handle = mb.send_goal(*goal, frame_id=frame)
    while not handle.done() and mon.now_s() - t0 < timeout - 1e-9:
        run.run(min(1.0, timeout - (mon.now_s() - t0)), until=handle.done, quiet=True, chunk=1.0)
        if shots is not None and shot is not None:
            shots.append(shot())
        if say is not None and mon.now_s() >= next_say - 1e-6 and not handle.done():
            next_say += 10.0
            x, y, _ = run.sim.base_pose2d()
            say(f"  t={mon.now_s():.1f} s: {mon.now_s() - t0:.0f} s into this goal, robot at ({x:.2f}, {y:.2f})")
    verdict = GoalOutcome.of(handle.state)
    if not handle.done():
        mb.cancel_goal()
    t1 = handle.end_s if verdict != GoalOutcome.TIMEOUT and handle.end_s is not None else mon.now_s()
    pts = np.array([p[1:] for p in mon.path[k0:]]).reshape(-1, 2)
    goal_world = compose2(world_T_frame, goal)[:2]
    final_error = math.dist(run.sim.base_pose2d()[:2], goal_world)
    reached = final_error <= tolerance
    false_success = verdict == GoalOutcome.SUCCEEDED and not reached
    outcome = "succeeded" if reached else ("not_reached" if false_success else str(verdict))
    reason = {"succeeded": "", "timeout": f"not reached in {timeout:g} s"}.get(verdict, handle.reason)
    if false_success:
        reason = f"move_base reported success but the robot is {final_error:.2f} m from the goal (> {tolerance:g} m)"
    if not reached and (verdict == GoalOutcome.ABORTED and handle.reason.startswith(STUCK_PREFIX)):
        outcome = "stuck"
    elif not reached and verdict == GoalOutcome.TIMEOUT and stuck_window(mon.path[k0:], STUCK_WINDOW_S, STUCK_RADIUS_M):
        outcome = "stuck"
        reason = (
            f"stuck: the robot stayed within {STUCK_RADIUS_M:g} m for the last {STUCK_WINDOW_S:g} s "
            f"(not reached in {timeout:g} s)"
        )
    clearance = np.asarray(mon.clearance[k0:], dtype=np.float64)
    collisions = _episodes(mon.contacts, t0, t1)
    moved_s, within_s = _benchmark_times(mon.path[k0:], goal_world, tolerance)
    min_clearance = float(clearance.min()) if clearance.size else math.inf
    return {
        "goal": list(goal),
        "outcome": outcome,
        "move_base_outcome": str(verdict),
        "false_success": false_success,
        "reason": reason,
        "time_s": t1 - t0,
        "path_m": float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()) if len(pts) > 1 else 0.0,
        "min_clearance_m": min_clearance,
        "time_under_safety_s": float(np.count_nonzero(clearance < mon.safety_distance)) * SAMPLE_S,
        "safety_distance_m": mon.safety_distance,
        "near_miss": collisions == 0 and min_clearance < NEAR_MISS_M,
        "collisions": collisions,
        "final_error_m": final_error,
        "near_goal_m": min(
            final_error, float(np.min(np.linalg.norm(pts - goal_world, axis=1))) if len(pts) else final_error
        ),
        "goal_tolerance_m": tolerance,
        "tracking_error_m": _nanmean(mon.tracking[k0:]),
        "moved_s": None if moved_s is None else moved_s - t0,
        "within_tolerance_s": None if within_s is None else within_s - t0,
    }


def _nanmean(values: Sequence[float]) -> float | None:
    """Mean of the finite values (None if there are none)."""
    a = np.asarray(values, dtype=np.float64)
    a = a[np.isfinite(a)]
    return float(a.mean()) if a.size else None


def run_navigation(
    goals: Sequence[Pose],
    *,
    world: str = "room_obstacles",
    map_yaml: str | Path | None = None,
    robot: str = "mybot",
    pose: Pose = (0.0, 0.0, 0.0),
    controller: str | None = None,
    params_dir: str | Path | None = None,
    move_base_params: dict[str, Any] | None = None,
    spawn: Sequence[tuple[float, Any]] = (),
    goal_timeout: float = 90.0,
    seed: int = 0,
    record: str | Path | None = None,
    snapshots: bool = False,
    mapless: bool = False,
    wheel_controller: str = "gazebo_ros_diff_drive",
    ekf: str | Path | None = None,
    disturbances: dict[str, Any] | None = None,
    on_start: Any = None,
    goal_tolerance: float = GOAL_TOLERANCE_M,
    progress: Any = None,
    safety_distance: float = SAFETY_DISTANCE_M,
    launch_args: dict[str, str] | None = None,
) -> NavigateResult:
    """Navigate to ``goals`` (x, y, yaw in the map frame) in turn; see ``NavigateResult``.

    ``map_yaml``: the map to navigate on (default: the world's true map). ``controller``: ``trajectory``,
    ``dwa``, ``mppi`` or a ROS plugin name (default: the parameter files'). ``move_base_params``: overrides
    (``{"local_costmap.update_frequency": 0.5}``). ``spawn``: (time s, ModelSpec) obstacles added while
    running (or a function of the simulation that returns one, to place it relative to the robot then; or a later
    time in s to be asked again then; or None to place nothing).
    ``snapshots``: keep what the per-goal pictures need. ``mapless``: no map, no amcl — the global costmap
    is a rolling window in ``odom`` built from scans, and ``goals`` are in ``odom`` (the start pose).
    ``wheel_controller``: ``gazebo_ros_diff_drive`` (the robot's plugin) or ``diff_drive_controller`` (or a
    ros_control YAML file: see ``sim.wheel_control``); ``ekf``: a robot_localization parameter file (``default``:
    the shipped params/ekf.yaml) — the EKF then owns tf odom → base; both go to the launch as its
    ``wheel_controller``/``ekf`` arguments (``sim_launch_args``); ``disturbances``: see ``sim.disturbances``.
    ``goal_tolerance``: the truth's goal region (m): a goal whose robot truly ends farther away is not reached,
    whatever move_base says.
    ``progress``: a function given one line of text per goal sent/ended and every 10 simulated s (None: silent).
    ``safety_distance``: the clearance (m) under which a goal's ``time_under_safety_s`` counts.
    ``launch_args``: more arguments for the launch (``{"collision_monitor": "true"}`` on the mapless one).
    """
    from navlab.mapping import load_map, save_map
    from navlab.world import load_world

    def say(text: str) -> None:
        if progress is not None:
            progress(text)

    if not goals:
        raise NavigationError("no goals given (e.g. --goal 2.0 1.0 0.0)")
    if not (math.isfinite(goal_tolerance) and goal_tolerance > 0):
        raise NavigationError(f"goal_tolerance: expected a distance > 0 m, got {goal_tolerance!r}")
    for g in goals:
        if len(g) != 3 or not all(math.isfinite(float(v)) for v in g):
            raise NavigationError(f"goal {g!r}: expected three finite numbers x y yaw")
    overrides: dict[str, Any] = dict(move_base_params or {})
    if controller:
        overrides["base_local_planner"] = controller  # a ROS name or a registry alias (dwa, mppi, ...)
    gazebo = {"gazebo": {"disturbances": dict(disturbances)}} if disturbances else {}
    args: dict[str, Any] = {**sim_launch_args(wheel_controller, ekf), **(launch_args or {})}
    if params_dir is not None:
        args["params"] = str(params_dir)
    with tempfile.TemporaryDirectory(prefix="navlab-navigate-") as tmp:
        if map_yaml is None:
            served = Path(tmp) / "true_map.yaml"
            save_map(true_map(load_world(world), pose[:2]), served)
        else:
            served = Path(map_yaml)
        grid = load_map(served)
        if mapless:
            run = start_run(
                "navigation_mapless",
                world=world,
                robot=robot,
                pose=pose,
                seed=seed,
                overrides={"move_base": overrides, **gazebo},
                on_start=on_start,
                **args,
            )
        else:
            run = start_run(
                "navigation",
                world=world,
                robot=robot,
                pose=pose,
                seed=seed,
                map=str(served),
                overrides={"move_base": overrides, **gazebo},
                on_start=on_start,
                **args,
            )
    mb = _move_base(run)
    mon = run.add(
        NavMonitor,
        parameters={
            "base_frame": run.base_frame,
            "safety_distance": float(safety_distance),
            "estimate_frame": "" if mapless else "map",
            "keep_scan": bool(snapshots),  # only the pictures read the last scan
        },
        remappings={"scan": run.scan_topic},
        sim=run.sim,
        move_base=mb,
    )
    dropped: list[tuple[float, float, float, str]] = []  # (x m, y m, t s, name) of what was spawned, world frame

    def drop(model: Any) -> float | None:
        spec = model(run.sim) if callable(model) else model
        if spec is None or isinstance(spec, float):  # left out, or: ask again at that time
            return spec
        run.gazebo.spawn(spec)
        dropped.append((float(spec.pose[0]), float(spec.pose[1]), mon.now_s(), spec.name))
        return None

    for t, model in spawn:
        _at(run, float(t), lambda m=model: drop(m))
    results: list[dict[str, Any]] = []
    shots: list[NavSnapshot] = []
    arrivals: list[NavSnapshot] = []
    new_obstacles = unmapped_obstacles(load_world(world), grid, pose[:2]) if snapshots and not mapless else None
    recorder = Recorder(run.executor, record) if record else None  # the whole run, every goal, in one bag
    run.run(1.0, quiet=True)  # amcl's first update, the costmaps' first maps
    frame = run.odom_frame if mapless else "map"
    # where the goals' frame sits in the world: the map is the world's; odom starts at the spawn pose
    dd = run.sim.robot.diff_drive if run.sim.robot is not None else None
    odom_is_world = dd is not None and dd.odometry_source == "world"
    world_T_frame = pose if mapless and not odom_is_world else (0.0, 0.0, 0.0)
    for k, goal in enumerate(goals, 1):
        during: list[NavSnapshot] | None = [] if snapshots else None
        gx, gy, gyaw = (float(v) for v in goal)
        say(f"goal {k}/{len(goals)} ({gx:g}, {gy:g}, {gyaw:g}) sent at t={mon.now_s():.1f} s")
        shot = (lambda: _snapshot(run, mon, world_T_frame, mapless)) if snapshots else None
        results.append(
            rounded(
                _drive_goal(
                    run,
                    mon,
                    (gx, gy, gyaw),
                    frame,
                    goal_timeout,
                    during,
                    world_T_frame,
                    goal_tolerance,
                    shot=shot,
                    say=say,
                )
            )
        )
        r = results[-1]
        say(
            f"goal {k}/{len(goals)}: {r['outcome']} after {r['time_s']} s (t={mon.now_s():.1f} s)"
            + (f": {r['reason']}" if r["reason"] else "")
        )
        if shot is not None:  # the paper's pictures show the robot on its way (the middle of the drive); + arrival
            end: NavSnapshot = shot()
            end["new_obstacles"], end["dropped"] = new_obstacles, list(dropped)
            end["near_misses"], end["collision_xy"] = _near_misses(mon), _collision_points(mon)
            mid = NavSnapshot(**(during[len(during) // 2] if during else end))
            mid["new_obstacles"], mid["dropped"] = new_obstacles, [d for d in dropped if d[2] <= mid.get("t", 0.0)]
            shots.append(mid)
            arrivals.append(end)
    bag = recorder.close() if recorder else None
    loc = np.array(mon.localization_error)
    summary = rounded(
        {
            "goals_succeeded": sum(r["outcome"] == "succeeded" for r in results),  # the truth's
            "goals_succeeded_move_base": sum(r["move_base_outcome"] == "succeeded" for r in results),
            "false_success": sum(r["false_success"] for r in results),
            "collisions": sum(r["collisions"] for r in results),
            "near_misses": sum(r["near_miss"] for r in results),
            "min_clearance_m": min(
                (r["min_clearance_m"] for r in results if r["min_clearance_m"] is not None), default=None
            ),  # None: a goal that ended before the first sample
            "localization_error_mean_m": float(loc.mean()) if loc.size else None,
            "localization_error_max_m": float(loc.max()) if loc.size else None,
            "cmd_jerk_mean": mean_abs_jerk(mon.cmd),
            **run.figures(),
            **({"record": str(bag)} if bag else {}),
        }
    )
    return NavigateResult(results, summary, grid, shots, arrivals, np.array(mon.path, dtype=np.float64).reshape(-1, 3))


def save_goal_pictures(result: NavigateResult, folder: str | Path) -> list[str]:
    """Two labelled pictures per goal in ``folder``: ``goal_N.png`` when the goal ended (arrival or give-up) and
    ``goal_N_mid.png`` in the middle of the drive (the paper's Figs. 9–12); returns their paths, in that order."""
    from navlab.experiments.plots import plot_navigation

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for k, (goal, mid, end) in enumerate(zip(result.goals, result.snapshots, result.arrivals, strict=True), 1):
        head = f"goal {k} ({', '.join(f'{v:g}' for v in goal['goal'])}): {goal['outcome']} in {goal['time_s']} s"
        if goal.get("near_miss"):
            head += f" — NEAR MISS: {100 * goal['min_clearance_m']:.1f} cm from an obstacle"
        for shot, name, when in ((end, f"goal_{k}.png", "end of the drive"), (mid, f"goal_{k}_mid.png", "mid-drive")):
            title = f"{head}\n{when}, t = {shot.get('t', 0.0):.1f} s"
            paths.append(str(plot_navigation(result.grid, shot, out / name, title=title, goal=goal["goal"])))
    return paths


def _near_misses(mon: NavMonitor) -> np.ndarray:
    """Where (world x, y; m) the true clearance was under ``NEAR_MISS_M`` but not a contact: one point per run of
    consecutive samples, at its closest moment."""
    c = np.asarray(mon.clearance[: len(mon.path)], dtype=np.float64)
    close = (c < NEAR_MISS_M) & (c > 0.0)
    out = []
    k = 0
    while k < len(c):
        if not close[k]:
            k += 1
            continue
        end = k
        while end + 1 < len(c) and close[end + 1]:
            end += 1
        best = k + int(np.argmin(c[k : end + 1]))
        out.append(mon.path[best][1:])
        k = end + 1
    return np.array(out, dtype=np.float64).reshape(-1, 2)


def _collision_points(mon: NavMonitor) -> np.ndarray:
    """Where (world x, y; m) the robot was at each contact episode's first message."""
    if not mon.path:
        return np.zeros((0, 2))
    t = np.array([p[0] for p in mon.path])
    starts = [c for k, c in enumerate(mon.contacts) if k == 0 or c - mon.contacts[k - 1] > 0.25]
    return np.array([mon.path[int(np.argmin(np.abs(t - c)))][1:] for c in starts], dtype=np.float64).reshape(-1, 2)


WHEEL_CONTROLLERS = ("gazebo_ros_diff_drive", "diff_drive_controller")


def sim_launch_args(wheel_controller: str, ekf: str | Path | None) -> dict[str, str]:
    """The shipped launches' arguments for a wheel controller and an EKF: ``wheel_controller:=true``
    (+ ``controller_params:=FILE`` for a ros_control YAML), ``ekf:=true`` (+ ``ekf_params:=FILE`` unless
    ``default``/``true``: the shipped params/ekf.yaml)."""
    args: dict[str, str] = {}
    if wheel_controller != "gazebo_ros_diff_drive":
        args["wheel_controller"] = "true"
        if wheel_controller != "diff_drive_controller":
            if not Path(wheel_controller).is_file():
                known = " or ".join(WHEEL_CONTROLLERS)
                raise NavigationError(
                    f"wheel_controller {wheel_controller!r}: expected {known} or a ros_control YAML file"
                )
            args["controller_params"] = str(Path(wheel_controller).resolve())
    if ekf:
        args["ekf"] = "true"
        if str(ekf) not in ("default", "true", "True"):
            args["ekf_params"] = str(Path(ekf).resolve())
    return args


def _at(run: Run, t: float, fn: Any) -> None:
    """Call ``fn`` at simulated time ``t`` (s) of the run, and again at the time (s) it returns, if any."""
    node = run.add(Node, name=f"at_{t:g}_{len(run.session.nodes)}")
    holder: dict[str, Any] = {}

    def arm(when: float) -> None:
        holder["timer"] = node.create_timer(max(when - run.executor.now_ns / 1e9, 1e-3), fire)

    def fire() -> None:
        holder["timer"].cancel()
        again = fn()
        if again is not None:
            arm(again)

    arm(t)


def _snapshot(run: Run, mon: NavMonitor, world_T_frame: Pose = (0.0, 0.0, 0.0), mapless: bool = False) -> NavSnapshot:
    """What a picture of this moment needs, in the world (= map) frame; with ``mapless`` the costmap and plans are
    in odom, which sits at ``world_T_frame``."""
    mb = _move_base(run)
    gc = mb.global_costmap.costmap
    gc = Grid(gc.data.copy(), gc.resolution, gc.origin, gc.frame_id)  # the master changes in place
    plan = mb.global_plan
    local = getattr(mb.controller, "local_plan", None)
    odom_to_map: Pose | None = world_T_frame if mapless else None
    if not mapless:
        try:
            odom_to_map = run.executor.tf.lookup_pose2d("map", mb.local_costmap.global_frame)
        except TfError:  # no tf: no local plan drawn
            local = None
    return {
        "costmap": gc,
        "plan": None if plan is None else plan.copy(),
        "local_plan": None if local is None else np.asarray(local).copy(),
        "odom_to_map": odom_to_map,
        "path": np.array([p[1:] for p in mon.path]),
        "scan_xy": mon.scan_points(),
        "robot": run.sim.base_pose2d(),
        "footprint": mb.local_costmap.layered.footprint,
        "t": mon.now_s(),
        "costmap_in_map": world_T_frame if mapless else None,
    }


def mean_abs_jerk(cmd: Sequence[tuple[float, float]]) -> float | None:
    """Mean |d²v/dt²| (m/s³) of the commanded linear speed, from (t s, v m/s) samples; None if too few."""
    if len(cmd) < 3:
        return None
    a = np.array(cmd, dtype=np.float64)
    t, v = a[:, 0], a[:, 1]
    dt = np.diff(t)
    keep = np.concatenate([[True], dt > 1e-9])  # one command per instant
    t, v = t[keep], v[keep]
    if len(t) < 3:
        return None
    acc = np.diff(v) / np.diff(t)
    jerk = np.diff(acc) / np.diff(t)[1:]
    return float(np.abs(jerk).mean())
