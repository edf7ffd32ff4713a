"""``navlab navigate``: the paper's navigation launch (move_base on a map) driving to goals in simulation."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from navlab.cli.options import (
    add_run_options,
    add_set_argument,
    add_world_robot,
    apply_resource_paths,
    coordinate,
    parse_sets,
    positive_seconds,
    print_figures,
    start_pose,
)
from navlab.cli.runs import ros_hook, stop_signals, view_hook


@stop_signals()  # SIGTERM as Ctrl-C, also as a background job: a recording is closed whole
def _cmd_navigate(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments import run_navigation, save_goal_pictures
    from navlab.sim import parse_spawn_spec

    spawns = []
    for i, spec in enumerate(args.spawn):
        model, t = parse_spawn_spec(spec, default_name=f"spawned_{i}")
        spawns.append((t, model))
    with view_hook(args) as view, ros_hook(args, view) as on_start:
        result = run_navigation(
            [tuple(g) for g in args.goal],
            world=args.world,
            map_yaml=args.map,
            robot=args.robot,
            pose=start_pose(args),
            controller=args.controller,
            params_dir=args.params,
            move_base_params=parse_sets(args.set),
            spawn=spawns,
            goal_timeout=args.timeout,
            seed=args.seed,
            record=args.record,
            snapshots=bool(args.out),
            mapless=args.mapless,
            on_start=on_start,
            progress=None if args.quiet else lambda text: print(text, file=sys.stderr, flush=True),
        )
    figures: dict[str, Any] = {"goals": result.goals, **result.summary}
    if args.out:
        figures["pictures"] = save_goal_pictures(result, args.out)
    if args.json:
        print_figures(figures, True)
    else:  # one readable line per goal, then the run's figures
        for k, g in enumerate(result.goals, 1):
            mb = g.get("move_base_outcome", g["outcome"])
            said = f" (move_base: {mb})" if mb != g["outcome"] else ""
            print(
                f"goal {k} ({', '.join(f'{v:g}' for v in g['goal'])}): {g['outcome']}{said} in {g['time_s']} s, "
                f"path "
                f"{g['path_m']} m, closest {g['min_clearance_m']} m, {g['collisions']} collisions"
                + (f" ({g['reason']})" if g["reason"] else "")
            )
        print_figures({k: v for k, v in figures.items() if k != "goals"}, False)
    failed = [g for g in result.goals if g["outcome"] != "succeeded"]
    if failed:  # as a script would want it: 0 only when every goal succeeded
        print(
            f"navlab: {len(failed)} of {len(result.goals)} goals not reached "
            f"({', '.join(sorted({g['outcome'] for g in failed}))})",
            file=sys.stderr,
        )
        return 1
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``navigate``."""
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
    add_world_robot(p, "room_obstacles")
    p.add_argument(
        "--map",
        metavar="MAP.yaml",
        default=None,
        help="map_server map to navigate on; default: the world's true occupancy at 5 cm",
    )
    p.add_argument(
        "--mapless",
        action="store_true",
        help="no map and no amcl: move_base's global costmap rolls in odom, built from the laser; "
        "goals are then in odom (the start pose)",
    )
    p.add_argument(
        "--goal",
        nargs=3,
        type=coordinate,
        action="append",
        required=True,
        metavar=("X", "Y", "YAW"),
        help="a goal in the map frame (odom with --mapless) (m, m, rad); repeat for a sequence",
    )
    p.add_argument(
        "--controller",
        default=None,
        help="local planner: trajectory (TrajectoryPlannerROS), dwa (DWAPlannerROS), mppi, or a ROS "
        "plugin name (default: move_base_params.yaml's base_local_planner)",
    )
    p.add_argument(
        "--params",
        metavar="DIR",
        default=None,
        help="folder of move_base's ROS 1 parameter files (default: the shipped params/mybot)",
    )
    add_set_argument(p, "move_base", "local_costmap.update_frequency=1.0")
    p.add_argument(
        "--spawn",
        action="append",
        default=[],
        metavar="SPEC",
        help="add an obstacle while running, e.g. 'cylinder:x=1,y=0.5,radius=0.15,length=0.5,t=5' "
        "(see navlab sim --help; repeatable)",
    )
    p.add_argument("--timeout", type=positive_seconds, default=90.0, help="simulated s allowed per goal (90)")
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="save two pictures per goal into DIR: goal_N.png when it ended, goal_N_mid.png mid-drive",
    )
    add_run_options(p, seed=0, rate=None, record=True, quiet=True, json=True, view=True, ros=True)
    p.set_defaults(func=_cmd_navigate)
