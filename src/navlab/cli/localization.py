"""``navlab localize``: the paper's localization launch (AMCL on a saved map) in simulation, scored against
ground truth."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from navlab.cli.options import (
    add_run_options,
    add_set_argument,
    add_world_robot,
    apply_resource_paths,
    out_file,
    parse_sets,
    positive_seconds,
    print_figures,
    start_pose,
)
from navlab.cli.runs import ros_hook, stop_signals, view_hook


def _amcl_params(path: str | None, sets: list[str]) -> dict[str, Any]:
    """AMCL parameters from a ROS 1 / Nav2 YAML file (``amcl`` node) plus ``--set name=value`` overrides."""
    params: dict[str, Any] = {}
    if path:
        from navlab.core import load_params

        params = dict(load_params(path, node="amcl"))
        if set(params) == {"amcl"} and isinstance(params["amcl"], dict):
            params = dict(params["amcl"])
    return {**params, **parse_sets(sets)}


@stop_signals()  # SIGTERM as Ctrl-C, also as a background job: a recording is closed whole
def _cmd_localize(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments import plot_result, run_localization

    with view_hook(args) as view, ros_hook(args, view) as on_start:
        result = run_localization(
            args.world,
            args.map,
            initial=tuple(args.initial) if args.initial else None,
            global_localization=args.global_localization,
            duration=args.duration,
            seed=args.seed,
            kidnap_at=args.kidnap,
            amcl_params=_amcl_params(args.params, args.set),
            robot=args.robot,
            pose=start_pose(args),
            progress=not args.quiet and sys.stderr.isatty(),
            record=args.record,
            on_start=on_start,
        )
    summary = dict(result.summary)
    if args.out:
        summary["png"] = str(plot_result(result, out_file(args.out, "localize.png", old_suffixes=(".png",))))
    print_figures(summary, args.json)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``localize``."""
    p = sub.add_parser(
        "localize",
        help="localize the simulated robot with AMCL on a saved map and score it against ground truth",
        description="The paper's localization launch (simulator, map_server and amcl with ROS 1 parameters) "
        "while the robot drives a scripted loop steered on ground truth; prints the localization error against "
        "ground truth (mean/max position and yaw error, convergence time with --global, recovery time with "
        "--kidnap) and saves a PNG of the true and estimated paths. The map frame is taken to be the world "
        "frame (true for the world's true map and for SLAM maps started at the world origin).",
    )
    add_world_robot(p, "room_obstacles")
    p.add_argument(
        "--map",
        metavar="MAP.yaml",
        default=None,
        help="map_server map (YAML + image); default: the world's true occupancy at 5 cm",
    )
    start = p.add_mutually_exclusive_group()
    start.add_argument(
        "--initial",
        nargs=3,
        type=float,
        metavar=("X", "Y", "YAW"),
        help="AMCL's initial pose in the map frame (m, m, rad); default: the start pose",
    )
    start.add_argument(
        "--global",
        dest="global_localization",
        action="store_true",
        help="start from particles spread over the whole map (global_localization service)",
    )
    p.add_argument("--duration", type=positive_seconds, default=60.0, help="simulated seconds to run (default 60)")
    p.add_argument(
        "--kidnap",
        type=float,
        metavar="T",
        default=None,
        help="at T seconds teleport the robot to the route waypoint farthest from it",
    )
    p.add_argument(
        "--params",
        metavar="AMCL.yaml",
        default=None,
        help="amcl parameter file (ROS 1 layout, or Nav2 layout with an 'amcl' node)",
    )
    add_set_argument(p, "amcl", "recovery_alpha_fast=0.1")
    p.add_argument(
        "--out",
        default=".",
        metavar="DIR",
        help="folder for the truth-vs-estimate figure DIR/localize.png (default: the current folder; "
        "'' for none; a FILE.png is deprecated but still works this release)",
    )
    add_run_options(p, seed=0, rate=None, record=True, quiet=True, json=True, view=True, ros=True)
    p.set_defaults(func=_cmd_localize)
