"""``navlab bench NAME --json``: measured performance figures, printed as JSON.

Each benchmark is a function ``run(args) -> dict`` registered in ``BENCHES`` by import path, so a
concern's benchmark lives beside its code.
"""

from __future__ import annotations

import argparse
import importlib
import json
from typing import Any

# name -> "module:function"; the function takes the parsed args and returns a JSON-able dict.
BENCHES: dict[str, str] = {
    "mapping": "navlab.experiments.mapping_run:bench",
    "slam": "navlab.mapping.bench:run",
    "slam-office": "navlab.mapping.bench:run_office",
    "core": "navlab.core.bench:run",
    "soak": "navlab.core.bench:run_soak",
    "amcl": "navlab.localization.bench:run",
    "description": "navlab.description.bench:run",
    "sim": "navlab.sim.bench:run",
    "decompose": "navlab.sim.decompose_bench:run",
    "controller": "navlab.navigation.bench:run_controller",
    "planner": "navlab.navigation.bench:run_planner",
    "nav": "navlab.experiments.navigate_run:bench",
    "clutter": "navlab.experiments.clutter_run:bench",
    "odom": "navlab.experiments.odom_run:bench",
    "sweep": "navlab.experiments.sweep:bench",
    "view": "navlab.viz.bench:run",
    "ros": "navlab.ros1.bench:run",
}


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
    # soak (minutes) and ros (real time, needs the ROS tools) run alone
    names = [n for n in BENCHES if n not in ("soak", "ros")] if args.name == "all" else [args.name]
    results = {name: _run_one(name, args) for name in names}
    out = results[names[0]] if len(names) == 1 else results
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
    p.add_argument("name", choices=[*BENCHES, "all"], help="which benchmark to run")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--quiet", action="store_true", help="no 'running ...' lines on stderr")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--controller", default=None,
                   help="clutter: local planner to drive with (trajectory, dwa, mppi; default mppi)")
    p.add_argument("--worlds", type=int, default=50, help="clutter: how many generated worlds (default 50)")
    p.add_argument("--robot", default=None,
                   help="clutter: shipped robot (default mybot; e.g. jackal_skid with its own move_base files)")
    p.add_argument("--trials", type=int, default=None,
                   help="sweep: trials per combination (default 10; 2 combinations)")
    p.add_argument("--minutes", type=float, default=60.0,
                   help="soak: simulated minutes of the mapping launch (default 60); RSS after 1 and at the end")
    p.set_defaults(func=_cmd)
