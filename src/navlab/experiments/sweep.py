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
from navlab.experiments.trials import run_experiments, with_run_options

# "trials_with_collision" counts trials (as success and failures do); "collisions" counts contact episodes
COLUMNS = (
    "success_rate",
    "success_ci95",
    "move_base_success_rate",
    "false_success",
    "trials_with_collision",
    "collisions",
    "median_time_s",
    "spl_mean",
    "min_clearance_m",
    "score_mean",
)


def parse_params(items: list[str]) -> dict[str, list[Any]]:
    """``name=v1,v2,...`` items to {name: [values]} (values read as YAML: numbers, booleans, strings)."""
    out: dict[str, list[Any]] = {}
    for item in items:
        name, sep, values = item.partition("=")
        if not sep or not name.strip() or not values.strip():
            raise ExperimentError(
                f"--param {item!r}: expected name=value1,value2,... (e.g. local_costmap.update_frequency=0.5,1,2,5)"
            )
        out[name.strip()] = [yaml.safe_load(v) for v in values.split(",")]
    if not out:
        raise ExperimentError("a sweep needs at least one --param name=value1,value2,...")
    return out


def combinations(params: dict[str, list[Any]]) -> list[dict[str, Any]]:
    """Every combination of the parameter values, in the order given."""
    return [dict(zip(params, values, strict=True)) for values in itertools.product(*params.values())]


def run_sweep(
    sc: Scenario,
    params: dict[str, list[Any]],
    out: str | Path,
    *,
    trials: int | None = None,
    seed: int | None = None,
    workers: int | None = 1,
    backend: str = "local",
    progress: bool = False,
) -> list[dict[str, Any]]:
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
            elif name == "collision_monitor":  # a launch argument, not a move_base parameter
                if not isinstance(value, bool):
                    raise ExperimentError(f"--param collision_monitor: expected true or false, got {value!r}")
                variant.collision_monitor = value
            else:
                variant.overrides[name] = value
        jobs.append((with_run_options(variant, trials, seed), folder / ",".join(f"{k}={v}" for k, v in combo.items())))
    summaries = run_experiments(jobs, workers=workers, backend=backend, progress=progress, desc=f"{sc.name} sweep")
    columns = [c for c in COLUMNS if c != "score_mean" or any(s.get(c) is not None for s in summaries)]
    rows = [{**combo, **{c: s.get(c) for c in columns}} for combo, s in zip(combos, summaries, strict=True)]
    write_table(rows, list(params), folder)
    plot_sweep(rows, list(params), folder)
    return rows


def write_table(rows: list[dict[str, Any]], names: list[str], folder: Path) -> None:
    """``sweep.csv`` and ``sweep.md``: one row per combination."""
    from navlab.io import write_text_atomic

    header = [*names, *(c for c in COLUMNS if rows and c in rows[0])]

    def cell(v: Any) -> str:
        return "/".join(str(x) for x in v) if isinstance(v, list) else str(v)

    csv = [",".join(header), *(",".join(cell(r[h]) for h in header) for r in rows)]
    md = [
        "| " + " | ".join(header) + " |",
        "|" + " --- |" * len(header),
        *("| " + " | ".join(cell(r[h]) for h in header) + " |" for r in rows),
    ]
    write_text_atomic(folder / "sweep.csv", "\n".join(csv) + "\n")
    write_text_atomic(folder / "sweep.md", "\n".join(md) + "\n")


def plot_sweep(rows: list[dict[str, Any]], names: list[str], folder: Path) -> list[Path]:
    """One PNG per parameter: success rate (with its interval), trials with a collision and median time against
    it. Numeric values are joined by lines; categorical ones (controller names) are separate points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io import save_figure_atomic

    out = []
    for name in names:
        values = sorted({r[name] for r in rows}, key=_order)
        numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
        style = {"marker": "o", "linestyle": "-" if numeric else "none"}
        score = any(r.get("score_mean") is not None for r in rows)  # BARN's score in clutter worlds
        fig, axes = plt.subplots(1, 4 if score else 3, figsize=(17 if score else 13, 3.6))
        for others, group in itertools.groupby(
            sorted(rows, key=lambda r: str([r[n] for n in names if n != name])),
            key=lambda r: [r[n] for n in names if n != name],
        ):
            g = sorted(group, key=lambda r: values.index(r[name]))
            xs = [values.index(r[name]) for r in g]
            label = ", ".join(f"{n}={v}" for n, v in zip([n for n in names if n != name], others, strict=True)) or None
            ci = [r["success_ci95"] or [0, 1] for r in g]
            axes[0].errorbar(
                xs,
                [r["success_rate"] for r in g],
                yerr=[
                    [r["success_rate"] - c[0] for r, c in zip(g, ci, strict=True)],
                    [c[1] - r["success_rate"] for r, c in zip(g, ci, strict=True)],
                ],
                capsize=3,
                label=label,
                **style,
            )
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
