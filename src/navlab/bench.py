"""``navlab bench NAME --json``: measured performance figures, printed as JSON.

Each benchmark is a function ``run(args) -> dict`` registered in ``BENCHES`` by import path, so a
concern's benchmark lives beside its code. ``navlab bench all --json`` runs them all (but ``soak``) and adds
``summary``: the headline figures (``nav_rtf``, ``sim_rtf``, ``nav_sim_ratio``, ``start_s``,
``slam_peak_rss_mb``, ...). ``navlab bench compare OLD.json NEW.json`` prints every figure the two share
with its ratio new / old.
"""

from __future__ import annotations

import argparse
import importlib
import json
import statistics
import sys
from pathlib import Path
from typing import Any

from navlab.errors import NavlabError

# name -> "module:function"; the function takes the parsed args and returns a JSON-able dict.
BENCHES: dict[str, str] = {
    "mapping": "navlab.experiments.mapping_run:bench",
    "slam": "navlab.mapping.bench:run",
    "slam-office": "navlab.mapping.bench:run_office",
    "slam-gmapping": "navlab.mapping.bench:run_gmapping",
    "startup": "navlab.bench:run_startup",
    "core": "navlab.core.bench:run",
    "soak": "navlab.core.bench:run_soak",
    "amcl": "navlab.localization.bench:run",
    "description": "navlab.description.bench:run",
    "sim": "navlab.sim.bench:run",
    "decompose": "navlab.sim.decompose_bench:run",
    "sensors": "navlab.sim.sensors_bench:run",
    "controller": "navlab.navigation.bench:run_controller",
    "planner": "navlab.navigation.bench:run_planner",
    "nav": "navlab.experiments.navigate_run:bench",
    "clutter": "navlab.experiments.clutter_run:bench",
    "odom": "navlab.experiments.odom_run:bench",
    "sweep": "navlab.experiments.sweep:bench",
    "view": "navlab.viz.bench:run",
    "ros": "navlab.ros1.bench:run",
}


# summary key -> (bench, key) of ``navlab bench all``
SUMMARY = {
    "nav_rtf": ("nav", "rtf"),
    "sim_rtf": ("sim", "rtf"),
    "start_s": ("startup", "sim_start_cpu_s"),
    "help_s": ("startup", "help_cpu_s"),
    "slam_peak_rss_mb": ("slam-gmapping", "peak_rss_mb"),
    "slam_gmapping_cpu_s": ("slam-gmapping", "cpu_s"),
    "slam_gmapping_trans_m": ("slam-gmapping", "relations_trans_m"),
    "slam_graph_rtf": ("slam", "rtf"),
    "mapping_rtf": ("mapping", "rtf"),
}


def run_startup(args: argparse.Namespace) -> dict[str, Any]:
    """Start-up of the ``navlab`` command in child processes, medians of 3 after one untimed run: ``VERB
    --help`` (sim, slam, navigate) and ``sim --duration 0.01`` (the shortest run: imports, world, robot,
    MuJoCo model, one step; Numba's cache warm), each in CPU seconds (user + system) and wall seconds."""
    from navlab.core.bench import run_child

    def median(cmd: list[str]) -> dict[str, float]:
        run_child(cmd)  # warm: Numba's cache, the OS's file cache
        runs = [run_child(cmd) for _ in range(3)]
        return {k: statistics.median(r[k] for r in runs) for k in ("cpu_s", "wall_s")}

    navlab = [sys.executable, "-m", "navlab.cli"]
    helps = [median([*navlab, verb, "--help"]) for verb in ("sim", "slam", "navigate")]
    sim = median([*navlab, "sim", "--duration", "0.01", "--quiet"])
    return {
        "help_cpu_s": round(max(h["cpu_s"] for h in helps), 3),
        "help_wall_s": round(max(h["wall_s"] for h in helps), 3),
        "sim_start_cpu_s": round(sim["cpu_s"], 3),
        "sim_start_wall_s": round(sim["wall_s"], 3),
    }


def _flat(results: dict[str, Any], prefix: str = "") -> dict[str, float]:
    """Numeric figures of a bench JSON (nested for ``all``) as ``bench.key`` -> value."""
    out: dict[str, float] = {}
    for key, value in results.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[prefix + key] = float(value)
    return out


def compare(old: dict[str, Any], new: dict[str, Any]) -> list[tuple[str, float, float, float | None]]:
    """(figure, old, new, new / old) for every numeric figure both results hold, in the new one's order."""
    a, b = _flat(old), _flat(new)
    return [(k, a[k], v, v / a[k] if a[k] else None) for k, v in b.items() if k in a]


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
        if summary["nav_rtf"] and summary["sim_rtf"]:
            summary["nav_sim_ratio"] = round(summary["nav_rtf"] / summary["sim_rtf"], 3)
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
    p.add_argument("name", choices=[*BENCHES, "all", "compare"],
                   help="which benchmark to run; compare OLD.json NEW.json: the ratio of every shared figure")
    p.add_argument("files", nargs="*", metavar="FILE.json", help="compare: the old and the new results")
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
