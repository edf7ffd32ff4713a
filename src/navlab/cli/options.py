"""What every ``navlab`` verb shares, declared once with one help text and kept light so ``--help`` starts fast:
:func:`add_run_options` (``--seed --json --quiet --record --rate``, ``--view`` and its server options, ``--ros``),
start-pose options, ``--set``, durations and printing figures. Imports nothing heavy at module level.

Pacing has one name, ``--rate`` (as ``rosbag play --rate``): simulated seconds per wall-clock second, 0 = as
fast as possible. ``navlab view --speed`` is its deprecated alias for one release."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any


def positive_seconds(text: str, *, zero: bool = False) -> float:
    """argparse ``type=`` for a duration in simulated seconds: a finite number > 0 (>= 0 with ``zero``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not (math.isfinite(value) and (value > 0 or (zero and value == 0))):
        raise argparse.ArgumentTypeError(f"expected a duration {'>=' if zero else '>'} 0 s, got {text}")
    return value


def seconds_or_zero(text: str) -> float:
    """argparse ``type=`` for a duration in simulated seconds that may be 0 (set everything up, step nothing)."""
    return positive_seconds(text, zero=True)


def finite_float(text: str) -> float:
    """argparse ``type=`` for a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text}")
    return value


def coordinate(text: str) -> float:
    """argparse ``type=`` for a pose coordinate: a finite number within the ``coordinate_m`` ceiling (m or rad;
    beyond it poses overflow or lose all precision)."""
    from navlab.core import ceilings

    value = finite_float(text)
    limit = ceilings()["coordinate_m"].limit
    if abs(value) > limit:
        raise argparse.ArgumentTypeError(f"expected a coordinate within ±{limit:g}, got {text}")
    return value


def add_pose_arguments(p: argparse.ArgumentParser, what: str = "robot start") -> None:
    """``--x --y --yaw``: the robot's start pose in the world (m, m, rad), the same on every verb."""
    p.add_argument("--x", type=coordinate, default=0.0, help=f"{what} x in the world (m, default 0)")
    p.add_argument("--y", type=coordinate, default=0.0, help=f"{what} y in the world (m, default 0)")
    p.add_argument("--yaw", type=coordinate, default=0.0, help=f"{what} heading (rad, default 0)")


def start_pose(args: argparse.Namespace) -> tuple[float, float, float]:
    """(x, y, yaw) from :func:`add_pose_arguments`' options."""
    return float(args.x), float(args.y), float(args.yaw)


def add_world_robot(p: argparse.ArgumentParser, world: str) -> None:
    """``--world`` (default ``world``), ``--robot``, the start pose and the resource paths of a run verb."""
    from navlab.resources import shipped

    p.add_argument(
        "--world", default=world, help=f"world file or shipped name: {', '.join(shipped('world'))} (default {world})"
    )
    p.add_argument(
        "--robot",
        default="mybot",
        help=f"robot .xacro/.urdf or shipped name: {', '.join(shipped('robot'))} (default mybot)",
    )
    add_pose_arguments(p)
    add_resource_path_arguments(p)


def add_resource_path_arguments(p: argparse.ArgumentParser) -> None:
    """``--package-path DIR`` and ``--model-path DIR`` (repeatable): where ``package://``/``$(find pkg)``
    and ``model://`` are looked up, before ``ROS_PACKAGE_PATH`` and ``GAZEBO_MODEL_PATH``."""
    p.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="a folder holding ROS packages for package:// and $(find pkg) (repeatable; searched "
        "before ROS_PACKAGE_PATH)",
    )
    p.add_argument(
        "--model-path",
        action="append",
        default=[],
        metavar="DIR",
        help="a folder holding Gazebo models for model:// (repeatable; searched before GAZEBO_MODEL_PATH)",
    )


def apply_resource_paths(args: argparse.Namespace) -> None:
    """Put :func:`add_resource_path_arguments`' folders in front of ``ROS_PACKAGE_PATH`` and
    ``GAZEBO_MODEL_PATH`` of this process, so every loader of the run (and its workers) finds them."""
    import os
    from pathlib import Path

    for attr, var in (("package_path", "ROS_PACKAGE_PATH"), ("model_path", "GAZEBO_MODEL_PATH")):
        dirs = [str(Path(d).expanduser().resolve()) for d in getattr(args, attr, None) or []]
        if dirs:
            os.environ[var] = os.pathsep.join([*dirs, *filter(None, [os.environ.get(var, "")])])


def add_set_argument(p: argparse.ArgumentParser, node: str, example: str) -> None:
    """``--set NAME=VALUE`` (repeatable): one parameter of ``node``, parsed as YAML."""
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help=f"override one {node} parameter, e.g. --set {example} (repeatable)",
    )


def parse_sets(items: Sequence[str]) -> dict[str, Any]:
    """``--set name=value`` items to a dict; values are read as YAML (numbers, booleans, lists)."""
    import yaml

    from navlab.errors import NavlabError

    out: dict[str, Any] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise NavlabError(f"--set {item!r}: expected name=value (e.g. laser_max_beams=60)")
        try:
            out[name.strip()] = yaml.safe_load(value)
        except yaml.YAMLError:
            raise NavlabError(f"--set {item!r}: the value is not valid YAML") from None
    return out


def print_figures(figures: dict[str, Any], as_json: bool) -> None:
    """Print a run's figures: one JSON object, or ``key: value`` lines."""
    if as_json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"  {key}: {value}")


def out_file(out: str, name: str, *, old_suffixes: tuple[str, ...]) -> Path:
    """Where a verb writes ``name`` under ``--out DIR`` (the folder is created). Deprecated until the next
    release: an ``--out`` ending in one of ``old_suffixes`` (a file, as that verb once took) is used as the file
    itself, with a one-line DeprecationWarning on stderr."""
    import sys

    path = Path(out)
    if path.suffix.lower() in old_suffixes:
        print(
            f"navlab: DeprecationWarning: --out {out}: --out names a folder now (it gets {name}); a file name is "
            "accepted until the next release",
            file=sys.stderr,
        )
        path.parent.mkdir(parents=True, exist_ok=True)
        return path
    path.mkdir(parents=True, exist_ok=True)
    return path / name


def optional_out(value: str | None, folder: Path, name: str) -> Path | None:
    """An optional extra output (``nargs="?"``, ``const=""``): None when not asked for, ``folder/name`` when
    given without a value, else the file named (its folder created)."""
    if value is None:
        return None
    path = folder / name if value == "" else Path(value)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def check_named_inputs(args: argparse.Namespace) -> None:
    """Refuse a ``--world``/``--robot`` that names neither a file nor a shipped world/robot, in one line and
    before any heavy import (MuJoCo, Numba): the loaders would say the same seconds later. ``package://`` and
    ``file://`` URIs are left to the loaders."""
    from navlab import resources
    from navlab.errors import NavlabError

    for attr, kind, suffixes in (("world", "world", (".world", ".sdf")), ("robot", "robot", (".xacro", ".urdf"))):
        text = getattr(args, attr, None)
        if not isinstance(text, str) or not text.strip() or "://" in text:
            continue
        path = Path(text).expanduser()
        if path.exists():
            continue
        if not path.suffix and "/" not in text:
            (resources.world if kind == "world" else resources.robot)(text)  # one line, with a suggestion
        else:
            hint = "" if path.suffix in suffixes else f" (a {kind} is a {' or '.join(suffixes)} file or a shipped name)"
            raise NavlabError(f"{kind} file not found: {path.absolute()}{hint}")


DEFAULT_VIEW_PORT = 8765
RATE_HELP = "pacing, simulated s per wall-clock s: 0 = as fast as possible, 1 = real time, r = r x real time"


def pace(text: str) -> float:
    """argparse type of ``--rate``: a finite number >= 0 (simulated s per wall-clock s; 0 = as fast as possible)."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a number >= 0 (0 = as fast as possible), got {text!r}")
    return value


class DeprecatedAlias(argparse.Action):
    """An old option name kept for one release: stores into the new option's ``dest`` and says so on stderr."""

    def __init__(self, option_strings: list[str], dest: str, *, new: str, **kwargs: Any) -> None:
        self.new = new
        super().__init__(option_strings, dest, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        import sys

        print(
            f"navlab: DeprecationWarning: {option_string} is deprecated, use {self.new} (accepted until the next "
            "release)",
            file=sys.stderr,
        )
        setattr(namespace, self.dest, values)


def add_server_arguments(p: argparse.ArgumentParser, *, prefix: str = "") -> None:
    """``--host``, ``--port`` (with ``prefix``: ``--view-host``, ``--view-port``), ``--no-browser``, ``--foxglove``."""
    p.add_argument(
        f"--{prefix}host",
        default="127.0.0.1",
        help="address to listen on (default 127.0.0.1: this machine only; anything else warns)",
    )
    p.add_argument(
        f"--{prefix}port",
        type=int,
        default=DEFAULT_VIEW_PORT,
        help=f"port of the page and its WebSocket (default {DEFAULT_VIEW_PORT}; 0 = any free port)",
    )
    p.add_argument("--no-browser", action="store_true", help="print the URL only, do not open a browser")
    p.add_argument(
        "--foxglove",
        nargs="?",
        type=int,
        const=8766,
        default=None,
        metavar="PORT",
        help="also serve the topics to Foxglove (its WebSocket protocol, ROS 2 schemas) on PORT "
        "(default 8766); Foxglove's 3D panel can publish goals and initial poses",
    )


def add_view_arguments(p: argparse.ArgumentParser) -> None:
    """``--view`` and its server options, for verbs that run a simulation."""
    p.add_argument(
        "--view",
        action="store_true",
        help="watch and command the run in a browser page (navlab view's viewer, paced at real time; "
        "the page can pause and change the speed)",
    )
    add_server_arguments(p, prefix="view-")


def add_ros_argument(p: argparse.ArgumentParser) -> None:
    """``--ros``: offer the run on a ROS 1 master (``$ROS_MASTER_URI``, or navlab's own)."""
    p.add_argument(
        "--ros",
        action="store_true",
        help="join the ROS 1 graph at $ROS_MASTER_URI (or start navlab's own master): real rostopic, "
        "rviz, rosbag and rospy nodes see and drive the run; runs in real time unless --rate",
    )


_UNSET: Any = object()


def add_run_options(
    p: argparse.ArgumentParser,
    *,
    seed: int | None = _UNSET,
    json: bool = False,
    quiet: bool = False,
    record: bool = False,
    rate: float | None = _UNSET,
    rate_default: str = "0; real time with --ros",
    view: bool = False,
    ros: bool = False,
) -> None:
    """The options a run verb shares, each declared here once with one help text: ``--seed`` (given a default),
    ``--json``, ``--quiet``, ``--record DIR``, ``--rate`` (given a default; None = decided by the verb, which
    ``rate_default`` describes), ``--view`` with its server options and ``--ros``."""
    if seed is not _UNSET:
        p.add_argument("--seed", type=int, default=seed, help=f"random seed (default {seed})")
    if rate is not _UNSET:
        shown = rate_default if rate is None else f"{rate:g}"
        p.add_argument("--rate", type=pace, default=rate, help=f"{RATE_HELP} (default {shown})")
    if record:
        p.add_argument(
            "--record", default=None, metavar="DIR", help="also write every topic to a rosbag2 (MCAP) in DIR"
        )
    if quiet:
        p.add_argument("--quiet", action="store_true", help="no progress output on stderr")
    if json:
        p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    if view:
        add_view_arguments(p)
    if ros:
        add_ros_argument(p)
