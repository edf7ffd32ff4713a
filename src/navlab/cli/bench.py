"""``navlab bench NAME [--json]``: run a benchmark of :mod:`navlab.bench` (or ``all``) and print its figures;
``navlab bench compare OLD.json NEW.json``: the ratio of every figure two results share."""

from __future__ import annotations

import argparse
import importlib
import json
from pathlib import Path
from typing import Any

from navlab.bench import BENCHES, SUMMARY, compare
from navlab.cli.options import add_run_options
from navlab.errors import NavlabError


def _read_json(path: str) -> dict[str, Any]:
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise NavlabError(f"bench compare: {path}: cannot read a bench JSON ({exc})") from None
    if not isinstance(data, dict):
        raise NavlabError(f"bench compare: {path}: expected a JSON object of figures (navlab bench ... --json)")
    return data


def _cmd_compare(files: list[str]) -> int:
    if len(files) != 2:
        raise NavlabError(f"bench compare: expected two files, OLD.json NEW.json, got {len(files)}")
    rows = compare(_read_json(files[0]), _read_json(files[1]))
    if not rows:
        raise NavlabError(f"bench compare: {files[0]} and {files[1]} share no figure")
    width = max(len(r[0]) for r in rows)
    print(f"{'figure':<{width}}  {'old':>12}  {'new':>12}  {'new/old':>8}")
    for key, a, b, ratio in rows:
        print(f"{key:<{width}}  {a:>12.6g}  {b:>12.6g}  {'-' if ratio is None else f'{ratio:.3f}':>8}")
    return 0


def _run_one(name: str, args: argparse.Namespace) -> dict[str, Any]:
    import sys
    import time

    module, func = BENCHES[name].split(":")
    if not args.quiet:  # benchmarks take seconds to minutes: say what runs, and when it is done
        print(f"bench {name}: running ...", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    out = getattr(importlib.import_module(module), func)(args)
    if not args.quiet:
        print(f"bench {name}: done in {time.perf_counter() - t0:.1f} s wall", file=sys.stderr, flush=True)
    return out


def _cmd(args: argparse.Namespace) -> int:
    if args.name == "compare":
        return _cmd_compare(args.files)
    if args.files:
        raise NavlabError(f"bench {args.name}: unexpected arguments {' '.join(args.files)} (only compare takes files)")
    # soak (minutes) and ros (real time, needs the ROS tools) run alone
    names = [n for n in BENCHES if n not in ("soak", "ros")] if args.name == "all" else [args.name]
    results: dict[str, Any] = {name: _run_one(name, args) for name in names}
    out = results[names[0]] if len(names) == 1 else results
    if args.name == "all":
        summary = {key: results[bench].get(figure) for key, (bench, figure) in SUMMARY.items()}
        if summary["nav_rtf_cpu"] and summary["sim_rtf"]:  # both per CPU second: the stack's cost against the sim's
            summary["nav_sim_ratio"] = round(summary["nav_rtf_cpu"] / summary["sim_rtf"], 3)
        results["summary"] = summary
    if args.json:
        print(json.dumps(out))
    else:
        for name, res in results.items():
            print(name + ":")
            for key, value in res.items():
                print(f"  {key}: {value}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``bench`` verb."""
    p = sub.add_parser(
        "bench",
        help="measure performance and print the figures (JSON with --json)",
        description="Run a benchmark and print its figures (sim_s, wall_s, rtf and each benchmark's own, units "
        "as key suffixes). Run on an idle machine for stable numbers; the figures measured so far are in the "
        "docs (docs/mapping.md, docs/navigation.md, docs/viewer.md).",
    )
    p.add_argument(
        "name",
        choices=[*BENCHES, "all", "compare"],
        help="which benchmark to run; compare OLD.json NEW.json: the ratio of every shared figure",
    )
    p.add_argument("files", nargs="*", metavar="FILE.json", help="compare: the old and the new results")
    add_run_options(p, seed=0, quiet=True, json=True)
    p.add_argument(
        "--controller",
        default=None,
        help="clutter: local planner to drive with (trajectory, dwa, mppi, rpp or a ROS plugin name; "
        "default mppi for jackal and mybot, else the robot's own files)",
    )
    p.add_argument("--worlds", type=int, default=50, help="clutter: how many generated worlds (default 50)")
    p.add_argument(
        "--robot",
        default=None,
        help="clutter: shipped robot (default jackal; e.g. jackal_skid with its own move_base files)",
    )
    p.add_argument(
        "--set",
        default="test",
        choices=["test", "tuning"],
        help="clutter: the 50 test worlds (report on these) or the separate tuning set (tune on these)",
    )
    p.add_argument(
        "--max-speed",
        type=float,
        default=None,
        metavar="M_S",
        help="clutter: the controller's top speed (default 2.0, the Jackal's; 0 keeps the files')",
    )
    p.add_argument("--out", default=None, metavar="DIR", help="clutter: a picture of each failure in DIR")
    p.add_argument(
        "--trials", type=int, default=None, help="sweep: trials per combination (default 10; 2 combinations)"
    )
    p.add_argument(
        "--minutes",
        type=float,
        default=60.0,
        help="soak: simulated minutes of the mapping launch (default 60); RSS after 1 and at the end",
    )
    p.set_defaults(func=_cmd)
