"""The public entry point of every fuzzed format, as a command or run would call it (in the worker process)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any


def _robot(path: Path) -> dict[str, Any]:
    from navlab.description import load_robot
    from navlab.description.summary import robot_summary

    robot_summary(load_robot(path))
    return {}


def _world(path: Path) -> dict[str, Any]:
    from navlab.world import load_world
    from navlab.world.summary import world_summary

    world_summary(load_world(path))
    return {}


def _through_launch(folder: Path, node_yaml: str, extra: str = "") -> None:
    """Start a node from a launch file in ``folder`` (as a user's launch would) and run it briefly."""
    from navlab.core.launch import start

    launch = folder / "fuzz.launch.yaml"
    launch.write_text(f"launch:\n{extra}- node: {node_yaml}\n")
    start(str(launch)).run(0.5)


def _amcl(path: Path) -> dict[str, Any]:
    _through_launch(
        path.parent,
        f"{{pkg: navlab, exec: amcl, name: amcl, param: [{{from: {path.name}}}]}}",
        "- node: {pkg: navlab, exec: map_server, name: map_server, param: [{name: yaml_filename, "
        "value: map/map.yaml}]}\n",
    )
    return {}


def _gmapping(path: Path) -> dict[str, Any]:
    _through_launch(
        path.parent, f"{{pkg: navlab, exec: slam_gmapping, name: slam_gmapping, param: [{{from: {path.name}}}]}}"
    )
    return {}


def _move_base(folder: Path) -> dict[str, Any]:
    p = folder.name
    _through_launch(
        folder.parent,
        "{pkg: navlab, exec: move_base, name: move_base, param: ["
        f"{{from: {p}/costmap_common_params.yaml, ns: global_costmap}}, "
        f"{{from: {p}/costmap_common_params.yaml, ns: local_costmap}}, "
        f"{{from: {p}/global_costmap_params.yaml}}, {{from: {p}/local_costmap_params.yaml}}, "
        f"{{from: {p}/base_local_planner_params.yaml}}, {{from: {p}/move_base_params.yaml}}]}}",
    )
    return {}


def _map(path: Path) -> dict[str, Any]:
    from navlab.mapping import load_map

    grid = load_map(path)
    return {"cells": int(grid.data.size)}


def _carmen(path: Path) -> dict[str, Any]:
    from navlab.io.carmen import read_carmen

    log = read_carmen(path)
    return {"scans": len(log.scans), "skipped": len(log.skipped)}


def _launch(path: Path) -> dict[str, Any]:
    from navlab.core.launch import start

    session = start(str(path))
    session.run(2.0)
    return {}


def _route(path: Path) -> dict[str, Any]:
    from navlab.drivers import load_route

    load_route(path)
    return {}


def _scenario(path: Path) -> dict[str, Any]:
    from navlab.experiments.scenario import load_scenario

    load_scenario(path)
    return {}


def _cli(argv: list[str]) -> dict[str, Any]:
    """Run ``navlab ARGV`` in this process as the console script would; a non-zero exit is the error it printed,
    the last line of its output (--json) the accepted run's summary."""
    import contextlib
    import io
    import json

    from navlab.cli import main
    from navlab.errors import NavlabError

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse: a malformed argument
            code = exc.code if isinstance(exc.code, int) else 2
    if code != 0:
        raise NavlabError(err.getvalue().strip() or f"navlab {' '.join(argv)}: exit code {code}")
    lines = out.getvalue().strip().splitlines()
    try:
        summary = json.loads(lines[-1]) if lines else {}
    except json.JSONDecodeError:
        summary = {}
    return summary if isinstance(summary, dict) else {}


def _goal(path: Path) -> dict[str, Any]:
    import json

    _cli(json.loads(path.read_text()))
    return {}


def _bag(folder: Path) -> dict[str, Any]:
    """Every reader of a recording, then an in-place reindex (the user's other files must survive it)."""
    from navlab.errors import NavlabError

    errors: list[NavlabError] = []
    for argv in (
        ["topic", "echo", "/chatter", "--bag", folder.name, "--count", "3"],
        ["node", "list", "--bag", folder.name],
        ["graph", "--bag", folder.name, "--out", "graph"],
        ["bag", "reindex", folder.name],
    ):
        try:
            _cli(argv)
        except NavlabError as exc:
            errors.append(exc)
    if errors:
        raise errors[0]
    return {}


def _barn(path: Path) -> dict[str, Any]:
    _cli(["sim", "--world", path.name, "--model-path", "models", "--duration", "0.05", "--quiet", "--json"])
    return {}


def _slam(path: Path) -> dict[str, Any]:
    summary = _cli(["slam", "--log", path.name, "--out", "out", "--mode", "gmapping", "--quiet", "--json"])
    return {"skipped": int(summary.get("skipped_lines", 0))}


TARGETS: dict[str, Callable[[Path], dict[str, Any]]] = {
    "robot": _robot,
    "urdf": _robot,
    "world": _world,
    "amcl": _amcl,
    "gmapping": _gmapping,
    "move_base": _move_base,
    "map": _map,
    "carmen": _carmen,
    "launch": _launch,
    "route": _route,
    "scenario": _scenario,
    "navparams": _move_base,
    "goal": _goal,
    "bag": _bag,
    "barn": _barn,
    "slam": _slam,
}
