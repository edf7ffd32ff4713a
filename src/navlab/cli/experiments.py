"""``navlab experiment run|sweep`` (a scenario's trials headless, the paper's Section V) and ``navlab report``
(a results folder as Markdown, PNGs and one HTML page)."""

from __future__ import annotations

import argparse
import re
import sys
import textwrap
from pathlib import Path
from typing import Any

from navlab.cli.options import (
    add_resource_path_arguments,
    add_run_options,
    apply_resource_paths,
    print_figures,
)
from navlab.cli.runs import stop_signals


@stop_signals()  # SIGTERM as Ctrl-C: the workers stop, the finished trials stay
def _cmd_experiment(args: argparse.Namespace) -> int:
    apply_resource_paths(args)  # --package-path / --model-path, for this process and its workers
    from navlab.experiments import ExperimentError, load_scenario

    if args.action == "list":
        return _list_scenarios(args.json)
    if args.file is None:
        raise ExperimentError(
            f"experiment {args.action}: which scenario? a YAML file or a shipped name (`navlab experiment list`)"
        )
    sc = load_scenario(args.file)
    out = args.out or f"runs/{sc.name}"
    try:
        return _run_or_sweep(args, sc, out)
    except KeyboardInterrupt as exc:  # results.jsonl holds every finished trial whole, one line each
        from navlab.experiments import read_results

        pattern = "*/results.jsonl" if args.action == "sweep" else "results.jsonl"  # a sweep: one per combination
        n = sum(len(read_results(f)) for f in Path(out).glob(pattern))
        exc.add_note(f"{n} finished trial{'' if n == 1 else 's'} in {out}/{pattern}, whole; the same command resumes")
        raise


def _run_or_sweep(args: argparse.Namespace, sc: Any, out: str) -> int:
    from navlab.experiments import ExperimentError, run_experiment

    trials = {
        "trials": args.trials,
        "seed": args.seed,
        "workers": args.workers,
        "backend": args.backend,
        "progress": not args.quiet and sys.stderr.isatty(),
    }
    if args.action == "sweep":
        from navlab.experiments import parse_params, run_sweep

        rows = run_sweep(sc, parse_params(args.param), out, **trials)
        if not args.json:
            print(f"{len(rows)} combinations of {sc.name}: {out}/sweep.md (+ sweep.csv, a PNG per parameter)")
            print((Path(out) / "sweep.md").read_text())
        else:
            print_figures({"scenario": sc.name, "rows": rows}, True)
        return 0
    if args.param:
        raise ExperimentError("--param is for `navlab experiment sweep`")
    summary = run_experiment(sc, out, **trials)
    if not args.json:
        print(f"{summary['trials']} trials of {sc.name}: results in {out}/results.jsonl, summary in {out}/summary.json")
    print_figures(summary, args.json)
    return 0


def _cmd_report(args: argparse.Namespace) -> int:
    from navlab.experiments import render_report

    out = render_report(args.dir)
    if not args.json:
        print(
            f"{out['kind']} report: {out['html']} (one self-contained page) and {out['markdown']}, "
            f"{len(out['figures'])} figures"
        )
    else:
        print_figures(out, True)
    return 0


def _shipped_scenarios() -> list[str]:
    """The scenario names in the shipped resources folder (for --help)."""
    from navlab import resources

    return sorted(f.stem for f in (resources.root() / "scenarios").glob("*.yaml"))


def _list_scenarios(as_json: bool) -> int:
    """`navlab experiment list`: each shipped scenario, what it runs, and its file's opening sentence."""
    from navlab.experiments import load_scenario

    rows: list[dict[str, Any]] = []
    for name in _shipped_scenarios():
        sc = load_scenario(name)
        assert sc.path is not None  # a shipped file
        text = " ".join(line.lstrip("# ") for line in _opening_comment(sc.path))
        about = re.split(r"(?<=\.)\s+(?=[A-Z])", text)[0]  # its first sentence ("et al. 2020" does not end one)
        extra = (
            [f"controller {sc.controller}"] * bool(sc.controller)
            + [sc.wheel_controller] * (sc.wheel_controller != "gazebo_ros_diff_drive")
            + [f"ekf {sc.ekf}"] * bool(sc.ekf)
        )
        goals = f"{len(sc.goals)} goal{'s' * (len(sc.goals) != 1)}" if sc.goals else "the world's goal"
        facts = ", ".join([f"world {sc.world}", f"robot {sc.robot}", f"map {sc.map}", goals, *extra])
        rows.append({"name": name, "runs": f"{facts}; {sc.trials} trials", "about": about, "file": str(sc.path)})
    if as_json:
        print_figures({"scenarios": rows}, True)
        return 0
    for r in rows:
        print(f"{r['name']}: {r['runs']}\n    {textwrap.shorten(r['about'], 110)}")
    print("\nnavlab experiment run NAME --trials N; a scenario YAML of your own: keys in docs/experiments.md")
    return 0


def _opening_comment(path: Path) -> list[str]:
    """A scenario file's opening comment lines, up to its example commands (``#   navlab ...``)."""
    lines = []
    for line in path.read_text().splitlines():
        if not line.startswith("#") or line.startswith("#   "):
            break
        lines.append(line)
    return lines


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``experiment`` and ``report``."""
    p = sub.add_parser(
        "experiment",
        help="run a scenario's trials headless and summarize them, or sweep parameters (the paper's Section V)",
        description="navlab experiment list: the shipped scenarios, one line each. "
        "navlab experiment run FILE: run the trials of a scenario YAML (or a shipped one: "
        f"{', '.join(_shipped_scenarios())}) headless, each with its own seed, in parallel processes with "
        "--workers. Each "
        "finished trial is appended whole to DIR/results.jsonl; running again resumes and skips finished trials. "
        "Prints (and writes DIR/summary.json) the success rate with a 95 % Wilson interval, collisions, failures "
        "by kind, time quartiles, SPL, clearance, localization error and command jerk. navlab experiment sweep FILE "
        "--param name=v1,v2 [--param ...]: the same for every combination, with DIR/sweep.md, sweep.csv and a plot "
        "per parameter. --backend ray runs the trials as Ray tasks (a cluster at $RAY_ADDRESS or a local instance).",
    )
    p.add_argument(
        "action",
        choices=["run", "sweep", "list"],
        help="run: the scenario's trials; sweep: the trials for every combination of --param values; list: the "
        "shipped scenarios and what each shows",
    )
    p.add_argument("file", nargs="?", help="scenario YAML, or a shipped scenario's name")
    p.add_argument("--trials", type=int, default=None, help="how many trials (default: the scenario's)")
    p.add_argument(
        "--seed", type=int, default=None, help="seed of trial 0; trial k uses seed + k (default: the scenario's)"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="parallel processes (local: default 1), or the CPUs of a local Ray instance (default all)",
    )
    p.add_argument(
        "--backend",
        choices=["local", "ray"],
        default="local",
        help="local: worker processes on this machine (default); ray: Ray tasks on the cluster at "
        "$RAY_ADDRESS, or on a local Ray instance when it is not set (same results for the same seeds)",
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=V1,V2,...",
        help="sweep: a move_base parameter (or controller, or collision_monitor=false,true) and its values, e.g. "
        "local_costmap.update_frequency=0.5,1,2,5 (repeatable: the grid of all combinations)",
    )
    p.add_argument("--out", metavar="DIR", default=None, help="results folder (default runs/<scenario name>)")
    add_run_options(p, quiet=True, json=True)
    add_resource_path_arguments(p)
    p.set_defaults(func=_cmd_experiment)

    p = sub.add_parser(
        "report",
        help="re-render a results folder (experiment run, sweep or demo) as Markdown, PNGs and one HTML page",
        description="Reads DIR — an `navlab experiment run` folder (results.jsonl), an `navlab experiment sweep` "
        "folder (sweep.csv) or a `navlab demo` folder (report.json) — and writes DIR/report.md with its PNG "
        "figures and DIR/report.html, a single self-contained page (images inlined) to open in any browser.",
    )
    p.add_argument("dir", help="the results folder")
    add_run_options(p, json=True)
    p.set_defaults(func=_cmd_report)
