"""Parameter sweeps: a scenario's trials over the grid of ``--param name=v1,v2,...`` values.

Each combination runs as its own experiment in ``DIR/<name>=<value>,...`` (resumable like any experiment).
``DIR/sweep.csv`` and ``DIR/sweep.md`` hold one row per combination (success with its Wilson interval,
collisions, median time; BARN's mean score in clutter worlds), and ``DIR/<param>.png`` plots them against each
parameter. All trials of all combinations share the workers: local processes, or Ray tasks
(``backend="ray"``, see ``backends``), with identical results for the same seeds.
Parameter names are move_base parameters (``local_costmap.update_frequency``, ``max_vel_x`` for the local
planner's section is written ``TrajectoryPlannerROS.max_vel_x``) or the scenario's ``controller``.
"""

from __future__ import annotations

import copy
import itertools
from pathlib import Path
from typing import Any

import yaml

from navlab.experiments.errors import ExperimentError
from navlab.experiments.scenario import Scenario
from navlab.experiments.trials import run_experiments

# "trials_with_collision" counts trials (as success and failures do); "collisions" counts contact episodes
COLUMNS = ("success_rate", "success_ci95", "move_base_success_rate", "false_success", "trials_with_collision",
           "collisions", "median_time_s", "spl_mean", "min_clearance_m", "score_mean")


def parse_params(items: list[str]) -> dict[str, list[Any]]:
    """``name=v1,v2,...`` items to {name: [values]} (values read as YAML: numbers, booleans, strings)."""
    out: dict[str, list[Any]] = {}
    for item in items:
        name, sep, values = item.partition("=")
        if not sep or not name.strip() or not values.strip():
            raise ExperimentError(f"--param {item!r}: expected name=value1,value2,... "
                                  "(e.g. local_costmap.update_frequency=0.5,1,2,5)")  # fmt: skip
        out[name.strip()] = [yaml.safe_load(v) for v in values.split(",")]
    if not out:
        raise ExperimentError("a sweep needs at least one --param name=value1,value2,...")
    return out


def combinations(params: dict[str, list[Any]]) -> list[dict[str, Any]]:
    """Every combination of the parameter values, in the order given."""
    return [dict(zip(params, values, strict=True)) for values in itertools.product(*params.values())]


def run_sweep(sc: Scenario, params: dict[str, list[Any]], out: str | Path, *, trials: int | None = None,
              seed: int | None = None, workers: int | None = 1, backend: str = "local",
              progress: bool = False) -> list[dict[str, Any]]:  # fmt: skip
    """Run the scenario for every combination (all their trials share the ``workers``, or Ray with
    ``backend="ray"``); write the table and the plots; return the rows."""
    folder = Path(out)
    combos = combinations(params)
    jobs = []
    for combo in combos:
        variant = copy.deepcopy(sc)
        for name, value in combo.items():
            if name == "controller":
                variant.controller = str(value)
            else:
                variant.overrides[name] = value
        if trials is not None:
            variant.trials = trials
        if seed is not None:
            variant.seed = seed
        jobs.append((variant, folder / ",".join(f"{k}={v}" for k, v in combo.items())))
    summaries = run_experiments(jobs, workers=workers, backend=backend, progress=progress, desc=f"{sc.name} sweep")
    columns = [c for c in COLUMNS if c != "score_mean" or any(s.get(c) is not None for s in summaries)]
    rows = [{**combo, **{c: s.get(c) for c in columns}} for combo, s in zip(combos, summaries, strict=True)]
    write_table(rows, list(params), folder)
    plot_sweep(rows, list(params), folder)
    return rows


def write_table(rows: list[dict[str, Any]], names: list[str], folder: Path) -> None:
    """``sweep.csv`` and ``sweep.md``: one row per combination."""
    from navlab.io.files import write_text_atomic

    header = [*names, *(c for c in COLUMNS if rows and c in rows[0])]

    def cell(v: Any) -> str:
        return "/".join(str(x) for x in v) if isinstance(v, list) else str(v)

    csv = [",".join(header), *(",".join(cell(r[h]) for h in header) for r in rows)]
    md = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header),
          *("| " + " | ".join(cell(r[h]) for h in header) + " |" for r in rows)]  # fmt: skip
    write_text_atomic(folder / "sweep.csv", "\n".join(csv) + "\n")
    write_text_atomic(folder / "sweep.md", "\n".join(md) + "\n")


def plot_sweep(rows: list[dict[str, Any]], names: list[str], folder: Path) -> list[Path]:
    """One PNG per parameter: success rate (with its interval), trials with a collision and median time against
    it. Numeric values are joined by lines; categorical ones (controller names) are separate points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io.files import save_figure_atomic

    out = []
    for name in names:
        values = sorted({r[name] for r in rows}, key=_order)
        numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
        style = {"marker": "o", "linestyle": "-" if numeric else "none"}
        score = any(r.get("score_mean") is not None for r in rows)  # BARN's score in clutter worlds
        fig, axes = plt.subplots(1, 4 if score else 3, figsize=(17 if score else 13, 3.6))
        for others, group in itertools.groupby(sorted(rows, key=lambda r: str([r[n] for n in names if n != name])),
                                               key=lambda r: [r[n] for n in names if n != name]):  # fmt: skip
            g = sorted(group, key=lambda r: values.index(r[name]))
            xs = [values.index(r[name]) for r in g]
            label = ", ".join(f"{n}={v}" for n, v in zip([n for n in names if n != name], others, strict=True)) or None
            ci = [r["success_ci95"] or [0, 1] for r in g]
            axes[0].errorbar(xs, [r["success_rate"] for r in g], yerr=[[r["success_rate"] - c[0] for r, c in zip(g, ci,
                             strict=True)], [c[1] - r["success_rate"] for r, c in zip(g, ci, strict=True)]],
                             capsize=3, label=label, **style)  # fmt: skip
            axes[1].plot(xs, [r.get("trials_with_collision", r["collisions"]) for r in g], label=label, **style)
            axes[2].plot(xs, [r["median_time_s"] for r in g], label=label, **style)
            if score:
                axes[3].plot(xs, [r.get("score_mean") for r in g], label=label, **style)
        titles = ("success rate (95 % CI)", "trials with a collision", "median time (s)", "mean BARN score")
        for ax, title in zip(axes, titles, strict=False):
            ax.set_xticks(range(len(values)), [str(v) for v in values])
            ax.set_xlim(-0.5, len(values) - 0.5)
            ax.set_xlabel(name)
            ax.set_title(title)
        axes[0].set_ylim(-0.05, 1.05)
        axes[1].yaxis.get_major_locator().set_params(integer=True)
        for ax in axes[1:]:  # counts and times start at 0; all-zero data gets a 0..1 axis, not -0.04..0.04
            top = max(ax.get_ylim()[1], 1.0)
            ax.set_ylim(-0.04 * top, top)  # a little below 0 so points at 0 are not cut by the frame
        if len(names) > 1:
            axes[0].legend(fontsize=7)
        fig.tight_layout()
        path = folder / f"{name}.png"
        try:
            save_figure_atomic(fig, path, dpi=100)
        finally:
            plt.close(fig)
        out.append(path)
    return out


def _order(v: Any) -> tuple[int, float, str]:
    """Numbers by value, then anything else by its text."""
    if isinstance(v, int | float) and not isinstance(v, bool):
        return (0, float(v), "")
    return (1, 0.0, str(v))


BENCH_TRIALS = 10  # per combination: 2 x 10 trials, a small real sweep (the shipped sweeps run 20 per value)
RAY_COSTS = """import json, time
t0 = time.perf_counter()
import ray
t1 = time.perf_counter()
from navlab.experiments.backends import init_ray
t2 = time.perf_counter()
init_ray(ray, 2)
t3 = time.perf_counter()
ray.shutdown()
t4 = time.perf_counter()
print(json.dumps({"ray_import_s": t1 - t0, "ray_init_s": t3 - t2, "ray_shutdown_s": t4 - t3}))
"""


def bench(args: Any) -> dict[str, Any]:
    """``navlab bench sweep``: wall time of one sweep (2 combinations x ``--trials`` trials, default 10, of two
    goals in the empty room), each run as a user runs it — a fresh ``navlab experiment sweep`` process (imports,
    Numba's caches, worker or Ray start-up included) — with 1 local worker, 2 local workers and a local Ray
    instance of 2 CPUs, each twice (in the order A B C C B A; ``*_runs_s``), the faster of the two kept, and the
    speed-ups against 1 worker. ``*_cpu_s``: the CPU seconds the whole machine spent during the kept run (Ray's own
    processes included). Ray's fixed costs, timed apart in an idle process:
    ``ray_startup_s`` (``import ray`` + ``ray.init``) and ``ray_shutdown_s`` (which a sweep overlaps with
    writing its tables and plots); ``ray_overhead_s``: the Ray sweep's wall time over 2 local workers'."""
    import json
    import os
    import subprocess
    import sys
    import tempfile
    import time

    per = int(getattr(args, "trials", None) or BENCH_TRIALS)
    scenario = {"name": "bench_sweep", "world": "room", "goals": [[3.5, 3.0, 1.57], [-3.5, 0.0, -1.57]],
                "trials": per, "seed": int(getattr(args, "seed", 0) or 0), "time_limit": 60}  # fmt: skip
    out: dict[str, Any] = {"trials": 2 * per, "trials_per_combination": per, "cpus": os.cpu_count(),
                           "load_1min": round(os.getloadavg()[0], 2)}  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}  # a local instance: this machine's figure
    with tempfile.TemporaryDirectory(prefix="navlab-bench-sweep-") as tmp:
        path = Path(tmp) / "bench_sweep.yaml"
        path.write_text(yaml.safe_dump(scenario))
        configs = [("workers_1", ["--workers", "1"]), ("workers_2", ["--workers", "2"]),
                   ("ray_2", ["--workers", "2", "--backend", "ray"])]  # fmt: skip
        for k, (key, extra) in enumerate(configs + configs[::-1]):  # A B C C B A: drifting load hits all alike
            cmd = [sys.executable, "-m", "navlab.cli", "experiment", "sweep", str(path), "--param",
                   "controller=trajectory,dwa", "--out", str(Path(tmp) / f"{key}{k}"), "--quiet", "--json",
                   *extra]  # fmt: skip
            cpu0, t0 = _machine_cpu_s(), time.perf_counter()
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
            wall, cpu1 = time.perf_counter() - t0, _machine_cpu_s()
            if done.returncode != 0:
                raise ExperimentError(f"bench sweep: {' '.join(cmd[3:])} failed: {done.stderr.strip()[-500:]}")
            runs = out[f"{key}_runs_s"] = [*out.get(f"{key}_runs_s", []), round(wall, 2)]
            if runs[-1] == min(runs):  # the less disturbed run is the figure
                out[f"{key}_s"] = runs[-1]
                out[f"{key}_cpu_s"] = round(cpu1 - cpu0, 1) if cpu0 is not None and cpu1 is not None else None
        costs = subprocess.run([sys.executable, "-c", RAY_COSTS], env=env, capture_output=True, text=True,
                               check=False, cwd=tmp)  # fmt: skip
        if costs.returncode != 0:
            raise ExperimentError(f"bench sweep: timing Ray's start-up failed: {costs.stderr.strip()[-500:]}")
    ray = json.loads(costs.stdout.strip().splitlines()[-1])
    out["ray_startup_s"] = round(ray["ray_import_s"] + ray["ray_init_s"], 2)
    out.update({k: round(v, 2) for k, v in ray.items()})
    out["ray_overhead_s"] = round(out["ray_2_s"] - out["workers_2_s"], 2)
    out["speedup_2"] = round(out["workers_1_s"] / out["workers_2_s"], 2)
    out["speedup_ray"] = round(out["workers_1_s"] / out["ray_2_s"], 2)
    out["load_1min_after"] = round(os.getloadavg()[0], 2)
    return out


def _machine_cpu_s() -> float | None:
    """CPU seconds the whole machine has been busy since boot (Linux's /proc/stat; None elsewhere)."""
    import os

    try:
        fields = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:8]]
    except (OSError, ValueError):
        return None
    user, nice, system, _idle, _iowait, irq, softirq = fields
    return (user + nice + system + irq + softirq) / os.sysconf("SC_CLK_TCK")
