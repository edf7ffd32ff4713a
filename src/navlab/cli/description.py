"""``navlab check robot FILE`` / ``navlab check world FILE``: validate a description and summarise it."""

from __future__ import annotations

import argparse
import json

from navlab.cli.options import add_run_options
from navlab.errors import NavlabError


def _xacro_args(pairs: list[str]) -> dict[str, str]:
    out = {}
    for pair in pairs:
        key, sep, value = pair.partition(":=")
        if not sep:
            raise NavlabError(f"xacro argument {pair!r}: expected name:=value")
        out[key] = value
    return out


def _cmd(args: argparse.Namespace) -> int:
    path = args.file  # a path, package:// URI or shipped name: the loaders resolve it (one resolver)
    if args.kind == "robot":
        from navlab.description import format_robot, load_robot, robot_summary

        summary = robot_summary(load_robot(path, search_paths=args.package_path, args=_xacro_args(args.arg)))
        text = format_robot(summary)
    else:
        from navlab.world import format_world, load_world, world_summary

        summary = world_summary(load_world(path, model_path=args.model_path))
        text = format_world(summary)
    print(json.dumps(summary, indent=2) if args.json else text)
    return 1 if args.strict and summary["warnings"] else 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``check`` verb."""
    p = sub.add_parser(
        "check",
        help="validate a robot description or a world file and print a summary",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Load a robot description (.xacro/.urdf with <gazebo> plugin tags) or a Gazebo\n"
        "world (.world SDF) exactly as the simulator would, and print what it contains:\n"
        "links, joints, masses, plugins, sensors (robot); models, shapes, extents (world);\n"
        "and every warning. A malformed file exits with status 2 and a one-line error\n"
        "naming the file and the element.",
        epilog="examples:\n"
        "  navlab check robot mybot\n"
        "  navlab check world room_obstacles --json\n"
        "  navlab check robot turtlebot3_burger.urdf.xacro --package-path ~/catkin_ws/src\n"
        "  navlab check robot package://my_description/urdf/robot.xacro --arg use_lidar:=true\n"
        "  navlab check world my.world --model-path ~/.gazebo/models",
    )
    p.add_argument("kind", choices=("robot", "world"), help="what FILE is")
    p.add_argument(
        "file",
        help="path of the .xacro/.urdf or .world file, or a shipped name (robot: mybot; world: room, room_obstacles)",
    )
    add_run_options(p, json=True)
    p.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="robot: a directory holding ROS packages for $(find pkg) and package:// "
        "(repeatable; ROS_PACKAGE_PATH is also searched)",
    )
    p.add_argument(
        "--arg", action="append", default=[], metavar="NAME:=VALUE", help="robot: a xacro argument (repeatable)"
    )
    p.add_argument(
        "--model-path",
        action="append",
        default=[],
        metavar="DIR",
        help="world: a directory holding Gazebo models for model:// includes (repeatable; "
        "GAZEBO_MODEL_PATH is also searched)",
    )
    p.add_argument("--strict", action="store_true", help="exit with status 1 if there are warnings")
    p.set_defaults(func=_cmd)
