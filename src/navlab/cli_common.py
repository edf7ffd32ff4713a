"""What every ``navlab`` verb shares, kept light so ``--help`` starts fast: start-pose options, ``--set``,
durations and printing figures. Imports nothing heavy at module level."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any


def positive_seconds(text: str) -> float:
    """argparse ``type=`` for a duration in simulated seconds: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a duration > 0 s, got {text}")
    return value


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
    from navlab.core.limits import ceilings

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


def add_resource_path_arguments(p: argparse.ArgumentParser) -> None:
    """``--package-path DIR`` and ``--model-path DIR`` (repeatable): where ``package://``/``$(find pkg)``
    and ``model://`` are looked up, before ``ROS_PACKAGE_PATH`` and ``GAZEBO_MODEL_PATH``."""
    p.add_argument("--package-path", action="append", default=[], metavar="DIR",
                   help="a folder holding ROS packages for package:// and $(find pkg) (repeatable; searched "
                   "before ROS_PACKAGE_PATH)")
    p.add_argument("--model-path", action="append", default=[], metavar="DIR",
                   help="a folder holding Gazebo models for model:// (repeatable; searched before "
                   "GAZEBO_MODEL_PATH)")


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
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help=f"override one {node} parameter, e.g. --set {example} (repeatable)")  # fmt: skip


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
        print(f"navlab: DeprecationWarning: --out {out}: --out names a folder now (it gets {name}); a file name is "
              "accepted until the next release", file=sys.stderr)  # fmt: skip
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
