"""CLI verb of the localization package: ``navlab localize``."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from navlab.core.runner import positive_seconds


def _amcl_params(path: str | None, sets: list[str]) -> dict[str, Any]:
    """AMCL parameters from a ROS 1 / Nav2 YAML file (``amcl`` node) plus ``--set name=value`` overrides."""
    import yaml

    from navlab.localization.errors import LocalizationError

    params: dict[str, Any] = {}
    if path:
        from navlab.core import load_params

        params = dict(load_params(path, node="amcl"))
        if set(params) == {"amcl"} and isinstance(params["amcl"], dict):
            params = dict(params["amcl"])
    for item in sets:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise LocalizationError(f"--set {item!r}: expected name=value (e.g. laser_max_beams=60)")
        params[name.strip()] = yaml.safe_load(value)
    return params


def _cmd_localize(args: argparse.Namespace) -> int:
    from navlab.localization.run import plot_result, run_localization

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
        progress=not args.quiet and sys.stderr.isatty(),
        record=args.record,
    )
    summary = dict(result.summary)
    if args.png:
        summary["png"] = str(plot_result(result, args.png))
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            print(f"{key}: {value}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``localize`` verb."""
    p = sub.add_parser(
        "localize",
        help="localize the simulated robot with AMCL on a saved map and score it against ground truth",
        description="Run the simulator, map_server and amcl (ROS 1 parameters) while the robot drives a "
        "scripted loop steered on ground truth; print the localization error against ground truth "
        "(mean/max position and yaw error, convergence time with --global, recovery time with "
        "--kidnap) and save a PNG of the true and estimated paths. The map frame is taken to be the "
        "world frame (true for the world's true map and for SLAM maps started at the world origin).",
    )
    p.add_argument("--world", default="room_obstacles",
                   help="shipped world name or .world file (default room_obstacles)")
    p.add_argument("--map", metavar="MAP.yaml", default=None,
                   help="map_server map (YAML + image); default: the world's true occupancy at 5 cm")
    p.add_argument("--robot", default="mybot", help="shipped robot name or .xacro/.urdf (default mybot)")
    start = p.add_mutually_exclusive_group()
    start.add_argument("--initial", nargs=3, type=float, metavar=("X", "Y", "YAW"),
                       help="AMCL's initial pose in the map frame (m, m, rad); default 0 0 0 (the spawn pose)")
    start.add_argument("--global", dest="global_localization", action="store_true",
                       help="start from particles spread over the whole map (global_localization service)")
    p.add_argument("--duration", type=positive_seconds, default=60.0, help="simulated seconds to run (default 60)")
    p.add_argument("--kidnap", type=float, metavar="T", default=None,
                   help="at T seconds teleport the robot to the route waypoint farthest from it")
    p.add_argument("--params", metavar="AMCL.yaml", default=None,
                   help="amcl parameter file (ROS 1 layout, or Nav2 layout with an 'amcl' node)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override one amcl parameter, e.g. --set recovery_alpha_fast=0.1 (repeatable)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the run (default 0)")
    p.add_argument("--png", default="localize.png", metavar="PATH",
                   help="where to save the truth-vs-estimate figure (default localize.png; '' for none)")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    p.add_argument("--record", metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_localize)
