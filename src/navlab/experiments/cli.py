"""``navlab map``, ``navlab localize`` and ``navlab eval map``: the paper's mapping and localization steps
in simulation, each a launch with a driver and monitors, scored against the world's truth."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from navlab.cli_common import (
    add_pose_arguments,
    add_resource_path_arguments,
    add_set_argument,
    apply_resource_paths,
    coordinate,
    out_file,
    parse_sets,
    positive_seconds,
    print_figures,
    start_pose,
)
from navlab.ros1.cli import add_ros_argument, pace, ros_hook
from navlab.viz.cli import add_view_arguments, view_hook


def _cmd_map(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    if args.action == "save":
        return _cmd_map_save(args)
    from navlab.experiments.mapping_run import run_mapping

    driver = "teleop" if args.teleop else "route" if args.route else "explore"
    with view_hook(args) as view, ros_hook(args, view) as on_start:
        result = run_mapping(
            world=args.world, robot=args.robot, pose=start_pose(args), out=args.out, driver=driver, route=args.route,
            duration=args.duration, mode=args.mode, seed=args.seed, rate=args.rate or 0.0, record=args.record,
            quiet=args.quiet, slam_params=parse_sets(args.set), on_start=on_start,
        )  # fmt: skip
    if not args.json:
        print(f"saved {result.map_yaml} (+ map.pgm, map.png) after {result.sim_s:.1f} simulated s")
    print_figures(result.scores, args.json)
    return 0


def _cmd_map_save(args: argparse.Namespace) -> int:
    """map_saver: save the current ``/map`` of a running ``navlab launch``, or of one started here."""
    from navlab import msgs
    from navlab.core.launch import start
    from navlab.core.runner import parse_launch_args, run_for
    from navlab.grid import GridMap
    from navlab.mapping.errors import MappingError
    from navlab.mapping.mapfile import save_map

    path = Path(args.out) / "map.yaml"
    if not args.launch:  # the launch running in another shell: /map is latched, so its current map comes first
        from navlab.core.introspect import find_running, subscribe

        for _t, msg in subscribe(find_running(args.pid), "/map"):
            save_map(GridMap.from_msg(msg), path)
            print(f"saved {path}")
            return 0
    file, *items = args.launch
    session = start(file, seed=args.seed, launch_args=parse_launch_args(items))
    latest: list[Any] = []
    session.executor.add_listener(lambda topic, msg, _t: latest.append(msg) if topic == "/map" else None)
    run_for(session.executor, args.duration, quiet=args.quiet, desc="map save")
    maps = [m for m in latest if isinstance(m, msgs.OccupancyGrid)]
    if not maps:
        raise MappingError(f"the launch {file!r} published no /map in {args.duration} s (is a SLAM node running?)")
    save_map(GridMap.from_msg(maps[-1]), path)
    print(f"saved {path}")
    return 0


def _amcl_params(path: str | None, sets: list[str]) -> dict[str, Any]:
    """AMCL parameters from a ROS 1 / Nav2 YAML file (``amcl`` node) plus ``--set name=value`` overrides."""
    params: dict[str, Any] = {}
    if path:
        from navlab.core import load_params

        params = dict(load_params(path, node="amcl"))
        if set(params) == {"amcl"} and isinstance(params["amcl"], dict):
            params = dict(params["amcl"])
    return {**params, **parse_sets(sets)}


def _cmd_localize(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments.localize_run import plot_result, run_localization

    with view_hook(args) as view, ros_hook(args, view) as on_start:
        result = run_localization(
            args.world, args.map, initial=tuple(args.initial) if args.initial else None,
            global_localization=args.global_localization, duration=args.duration, seed=args.seed,
            kidnap_at=args.kidnap, amcl_params=_amcl_params(args.params, args.set), robot=args.robot,
            pose=start_pose(args), progress=not args.quiet and sys.stderr.isatty(), record=args.record,
            on_start=on_start,
        )  # fmt: skip
    summary = dict(result.summary)
    if args.out:
        summary["png"] = str(plot_result(result, out_file(args.out, "localize.png", old_suffixes=(".png",))))
    print_figures(summary, args.json)
    return 0


def _cmd_navigate(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments.navigate_run import run_navigation, save_goal_pictures
    from navlab.sim.spawn import parse_spawn_spec

    spawns = []
    for i, spec in enumerate(args.spawn):
        model, t = parse_spawn_spec(spec, default_name=f"spawned_{i}")
        spawns.append((t, model))
    with view_hook(args) as view, ros_hook(args, view) as on_start:
        result = run_navigation(
            [tuple(g) for g in args.goal], world=args.world, map_yaml=args.map, robot=args.robot,
            pose=start_pose(args), controller=args.controller, params_dir=args.params,
            move_base_params=parse_sets(args.set), spawn=spawns, goal_timeout=args.timeout, seed=args.seed,
            record=args.record, snapshots=bool(args.out), mapless=args.mapless, on_start=on_start,
            progress=None if args.quiet else lambda text: print(text, file=sys.stderr, flush=True),
        )  # fmt: skip
    figures: dict[str, Any] = {"goals": result.goals, **result.summary}
    if args.out:
        figures["pictures"] = save_goal_pictures(result, args.out)
    if args.json:
        print_figures(figures, True)
    else:  # one readable line per goal, then the run's figures
        for k, g in enumerate(result.goals, 1):
            mb = g.get("move_base_outcome", g["outcome"])
            said = f" (move_base: {mb})" if mb != g["outcome"] else ""
            print(f"goal {k} ({', '.join(f'{v:g}' for v in g['goal'])}): {g['outcome']}{said} in {g['time_s']} s, "
                  f"path "
                  f"{g['path_m']} m, closest {g['min_clearance_m']} m, {g['collisions']} collisions"
                  + (f" ({g['reason']})" if g["reason"] else ""))  # fmt: skip
        print_figures({k: v for k, v in figures.items() if k != "goals"}, False)
    failed = [g for g in result.goals if g["outcome"] != "succeeded"]
    if failed:  # as a script would want it: 0 only when every goal succeeded
        print(f"navlab: {len(failed)} of {len(result.goals)} goals not reached "
              f"({', '.join(sorted({g['outcome'] for g in failed}))})", file=sys.stderr)
        return 1
    return 0


def _cmd_experiment(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments.errors import ExperimentError
    from navlab.experiments.scenario import load_scenario
    from navlab.experiments.trials import run_experiment

    sc = load_scenario(args.file)
    out = args.out or f"runs/{sc.name}"
    if args.action == "sweep":
        from navlab.experiments.sweep import parse_params, run_sweep

        rows = run_sweep(sc, parse_params(args.param), out, trials=args.trials, seed=args.seed, workers=args.workers,
                         backend=args.backend, progress=not args.quiet and sys.stderr.isatty())  # fmt: skip
        if not args.json:
            print(f"{len(rows)} combinations of {sc.name}: {out}/sweep.md (+ sweep.csv, a PNG per parameter)")
            print((Path(out) / "sweep.md").read_text())
        else:
            print_figures({"scenario": sc.name, "rows": rows}, True)
        return 0
    if args.param:
        raise ExperimentError("--param is for `navlab experiment sweep`")
    summary = run_experiment(sc, out, trials=args.trials, seed=args.seed, workers=args.workers, backend=args.backend,
                             progress=not args.quiet and sys.stderr.isatty())  # fmt: skip
    if not args.json:
        print(f"{summary['trials']} trials of {sc.name}: results in {out}/results.jsonl, summary in {out}/summary.json")
    print_figures(summary, args.json)
    return 0


def _cmd_report(args: argparse.Namespace) -> int:
    from navlab.experiments.report import render_report

    out = render_report(args.dir)
    if not args.json:
        print(f"{out['kind']} report: {out['html']} (one self-contained page) and {out['markdown']}, "
              f"{len(out['figures'])} figures")
    else:
        print_figures(out, True)
    return 0


def cmd_eval_map(args: argparse.Namespace) -> int:
    """Score a saved map against a world's true occupancy (start pose known, no alignment)."""
    from navlab.experiments.mapping_run import read_trajectory
    from navlab.experiments.metrics import free_coverage, score_map, trajectory_error
    from navlab.experiments.session import rounded
    from navlab.experiments.truth import true_occupancy, world_T_map
    from navlab.mapping.mapfile import load_map
    from navlab.sim.gazebo import load_robot_named, load_world_named

    apply_resource_paths(args)
    grid = load_map(args.map)
    truth = true_occupancy(load_world_named(args.world), grid)
    start = start_pose(args)
    map_in_world = world_T_map(load_robot_named(args.robot), start)  # the odometry source decides
    scores: dict[str, Any] = {"map_frame_in_world": list(map_in_world)}
    scores.update(score_map(grid, truth, world_T_map=map_in_world, start_xy=start[:2]))
    scores["coverage"] = free_coverage(grid, truth, world_T_map=map_in_world, start_xy=start[:2])
    traj = Path(args.trajectory) if args.trajectory else Path(args.map).with_name("trajectory.txt")
    if args.trajectory or traj.is_file():
        est, true = read_trajectory(traj)
        scores.update(trajectory_error(est, true))
    print_figures(rounded(scores), args.json)
    return 0


def add_eval_map(esub: argparse._SubParsersAction) -> None:
    """``navlab eval map MAP.yaml --world W``; called by the mapping CLI's ``eval`` verb."""
    m = esub.add_parser(
        "map",
        help="score a map against a simulated world's true occupancy",
        description="Occupied-cell precision and recall (a match within one cell), mean wall error and "
        "free-space coverage of a map_server map against the world's true occupancy at lidar height, and the "
        "SLAM trajectory's error against ground truth when a trajectory file is there. "
        "The map frame is SLAM's odom frame at the start, decided by the robot's odometry source as navlab map "
        "does: the world frame for <odometrySource>world (Gazebo's default), the start pose (--x --y --yaw) for "
        "encoder odometry; so no alignment is searched.",
    )
    m.add_argument("map", help="map_server YAML file")
    m.add_argument("--world", required=True, help="world file or shipped name (room, room_obstacles)")
    m.add_argument("--robot", default="mybot",
                   help="the robot that mapped: .xacro/.urdf or shipped name (default mybot); its diff-drive "
                   "odometry source decides the map frame")  # fmt: skip
    add_pose_arguments(m, "robot start")
    add_resource_path_arguments(m)
    m.add_argument("--trajectory", metavar="FILE",
                   help="SLAM vs true trajectory to score too (default: trajectory.txt beside the map, "
                   "as navlab map writes it)")  # fmt: skip
    m.add_argument("--json", action="store_true", help="print JSON")
    m.set_defaults(func=cmd_eval_map)


def _add_world_robot(p: argparse.ArgumentParser, world: str) -> None:
    p.add_argument("--world", default=world, help=f"world file or shipped name (default {world})")
    p.add_argument("--robot", default="mybot", help="robot .xacro/.urdf or shipped name (default mybot)")
    add_pose_arguments(p)
    add_resource_path_arguments(p)


def _shipped_scenarios() -> list[str]:
    """The scenario names in the shipped resources folder (for --help)."""
    from navlab import resources

    return sorted(f.stem for f in (resources.root() / "scenarios").glob("*.yaml"))


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``map``, ``localize``, ``navigate``, ``experiment`` and ``report``."""
    p = sub.add_parser(
        "map",
        help="build a map with SLAM in simulation (exploration, teleop or a route) and save it",
        description="The paper's mapping launch: simulator + slam_gmapping + a driver. Saves DIR/map.yaml, "
        "DIR/map.pgm, DIR/map.png (map with SLAM and true trajectories) and DIR/trajectory.txt, and prints the "
        "map's score against the world. `navlab map save --out DIR` saves the current /map of a running "
        "`navlab launch` (map_saver); with --launch FILE it starts the launch itself.",
    )
    p.add_argument("action", nargs="?", choices=["save"], help="save: run a launch and save its /map")
    _add_world_robot(p, "room")
    drive = p.add_mutually_exclusive_group()
    drive.add_argument("--explore", action="store_true", help="frontier exploration (the default)")
    drive.add_argument("--teleop", action="store_true", help="drive with the keyboard, in real time")
    drive.add_argument("--route", metavar="FILE",
                       help="a route YAML (segments and/or waypoints) or a shipped route's name (room)")
    p.add_argument("--out", default="map", metavar="DIR", help="output folder (default ./map)")
    p.add_argument("--mode", default="gmapping",
                   help="SLAM mode: gmapping, the paper's RBPF (default), or graph (pose graph)")  # fmt: skip
    add_set_argument(p, "slam_gmapping", "particles=50")
    p.add_argument("--duration", type=positive_seconds, default=600.0, help="at most this many simulated s (600)")
    p.add_argument("--rate", type=pace, default=None,
                   help="pacing: 0 = as fast as possible (default; real time with --ros), 1 = real time")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--record", metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR")
    p.add_argument("--launch", nargs="+", metavar=("FILE", "name:=value"),
                   help="save: start this launch here and save its /map after --duration (default: save the "
                   "/map of the `navlab launch` running in another shell)")  # fmt: skip
    p.add_argument("--pid", type=int, help="save: which running navlab launch, when several run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the scores as JSON")
    add_view_arguments(p)
    add_ros_argument(p)
    p.set_defaults(func=_cmd_map)

    p = sub.add_parser(
        "localize",
        help="localize the simulated robot with AMCL on a saved map and score it against ground truth",
        description="The paper's localization launch (simulator, map_server and amcl with ROS 1 parameters) "
        "while the robot drives a scripted loop steered on ground truth; prints the localization error against "
        "ground truth (mean/max position and yaw error, convergence time with --global, recovery time with "
        "--kidnap) and saves a PNG of the true and estimated paths. The map frame is taken to be the world "
        "frame (true for the world's true map and for SLAM maps started at the world origin).",
    )
    _add_world_robot(p, "room_obstacles")
    p.add_argument("--map", metavar="MAP.yaml", default=None,
                   help="map_server map (YAML + image); default: the world's true occupancy at 5 cm")
    start = p.add_mutually_exclusive_group()
    start.add_argument("--initial", nargs=3, type=float, metavar=("X", "Y", "YAW"),
                       help="AMCL's initial pose in the map frame (m, m, rad); default: the start pose")
    start.add_argument("--global", dest="global_localization", action="store_true",
                       help="start from particles spread over the whole map (global_localization service)")
    p.add_argument("--duration", type=positive_seconds, default=60.0, help="simulated seconds to run (default 60)")
    p.add_argument("--kidnap", type=float, metavar="T", default=None,
                   help="at T seconds teleport the robot to the route waypoint farthest from it")
    p.add_argument("--params", metavar="AMCL.yaml", default=None,
                   help="amcl parameter file (ROS 1 layout, or Nav2 layout with an 'amcl' node)")
    add_set_argument(p, "amcl", "recovery_alpha_fast=0.1")
    p.add_argument("--seed", type=int, default=0, help="random seed of the run (default 0)")
    p.add_argument("--out", default=".", metavar="DIR",
                   help="folder for the truth-vs-estimate figure DIR/localize.png (default: the current folder; "
                   "'' for none; a FILE.png is deprecated but still works this release)")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    p.add_argument("--record", metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_view_arguments(p)
    add_ros_argument(p, rate=True)
    p.set_defaults(func=_cmd_localize)

    p = sub.add_parser(
        "navigate",
        help="navigate to goals with move_base on a map, as in the paper's experiments (Figs. 9-12)",
        description="The paper's navigation launch (simulator, map_server, amcl and move_base with the ROS 1 "
        "parameter files of --params) drives the robot to each --goal in turn. Prints each goal's outcome, judged "
        "by the simulator's truth (succeeded: the robot truly ended within 0.3 m of the goal; else aborted with "
        "move_base's reason, preempted, timeout, or not_reached when move_base reported success from its own "
        "estimate), move_base's own verdict beside it, time, path length, final error, minimum clearance (the "
        "robot's collision geometry to the world's) and collisions (contact episodes from the simulator), and with "
        "--out DIR saves two labelled pictures per goal (at its end and mid-drive) with a legend. Exits 0 only "
        "when every goal succeeded (1 otherwise).",
    )
    _add_world_robot(p, "room_obstacles")
    p.add_argument("--map", metavar="MAP.yaml", default=None,
                   help="map_server map to navigate on; default: the world's true occupancy at 5 cm")
    p.add_argument("--mapless", action="store_true",
                   help="no map and no amcl: move_base's global costmap rolls in odom, built from the laser; "
                   "goals are then in odom (the start pose)")  # fmt: skip
    p.add_argument("--goal", nargs=3, type=coordinate, action="append", required=True, metavar=("X", "Y", "YAW"),
                   help="a goal in the map frame (odom with --mapless) (m, m, rad); repeat for a sequence")  # fmt: skip
    p.add_argument("--controller", default=None,
                   help="local planner: trajectory (TrajectoryPlannerROS), dwa (DWAPlannerROS), mppi, or a ROS "
                   "plugin name (default: move_base_params.yaml's base_local_planner)")  # fmt: skip
    p.add_argument("--params", metavar="DIR", default=None,
                   help="folder of move_base's ROS 1 parameter files (default: the shipped params/mybot)")
    add_set_argument(p, "move_base", "local_costmap.update_frequency=1.0")
    p.add_argument("--spawn", action="append", default=[], metavar="SPEC",
                   help="add an obstacle while running, e.g. 'cylinder:x=1,y=0.5,radius=0.15,length=0.5,t=5' "
                   "(see navlab sim --help; repeatable)")  # fmt: skip
    p.add_argument("--timeout", type=positive_seconds, default=90.0, help="simulated s allowed per goal (90)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="save two pictures per goal into DIR: goal_N.png when it ended, goal_N_mid.png mid-drive")
    p.add_argument("--record", metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    add_view_arguments(p)
    add_ros_argument(p, rate=True)
    p.set_defaults(func=_cmd_navigate)

    p = sub.add_parser(
        "experiment",
        help="run a scenario's trials headless and summarize them, or sweep parameters (the paper's Section V)",
        description="navlab experiment run FILE: run the trials of a scenario YAML (or a shipped one: "
        f"{', '.join(_shipped_scenarios())}) headless, each with its own seed, in parallel processes with "
        "--workers. Each "
        "finished trial is appended whole to DIR/results.jsonl; running again resumes and skips finished trials. "
        "Prints (and writes DIR/summary.json) the success rate with a 95 % Wilson interval, collisions, failures "
        "by kind, time quartiles, SPL, clearance, localization error and command jerk. navlab experiment sweep FILE "
        "--param name=v1,v2 [--param ...]: the same for every combination, with DIR/sweep.md, sweep.csv and a plot "
        "per parameter. --backend ray runs the trials as Ray tasks (a cluster at $RAY_ADDRESS or a local instance).",
    )
    p.add_argument("action", choices=["run", "sweep"],
                   help="run: the scenario's trials; sweep: the trials for every combination of --param values")
    p.add_argument("file", help="scenario YAML, or a shipped scenario's name")
    p.add_argument("--trials", type=int, default=None, help="how many trials (default: the scenario's)")
    p.add_argument("--seed", type=int, default=None,
                   help="seed of trial 0; trial k uses seed + k (default: the scenario's)")
    p.add_argument("--workers", type=int, default=None,
                   help="parallel processes (local: default 1), or the CPUs of a local Ray instance (default all)")
    p.add_argument("--backend", choices=["local", "ray"], default="local",
                   help="local: worker processes on this machine (default); ray: Ray tasks on the cluster at "
                   "$RAY_ADDRESS, or on a local Ray instance when it is not set (same results for the same seeds)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="sweep: a move_base parameter (or controller) and its values, e.g. "
                   "local_costmap.update_frequency=0.5,1,2,5 (repeatable: the grid of all combinations)")
    p.add_argument("--out", metavar="DIR", default=None, help="results folder (default runs/<scenario name>)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    add_resource_path_arguments(p)
    p.set_defaults(func=_cmd_experiment)

    p = sub.add_parser(
        "report",
        help="re-render a results folder (experiment run, sweep or demo) as Markdown, PNGs and one HTML page",
        description="Reads DIR — an `navlab experiment run` folder (results.jsonl), an `navlab experiment sweep` "
        "folder (sweep.csv) or a `navlab demo` folder (report.json) — and writes DIR/report.md with its PNG "
        "figures and DIR/report.html, a single self-contained page (images inlined) to open in any browser.",
    )
    p.add_argument("dir", help="the results folder")
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(func=_cmd_report)
