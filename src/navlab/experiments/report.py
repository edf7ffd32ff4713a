"""``navlab report DIR``: a results folder re-rendered as ``report.md``, PNG figures and one self-contained
``report.html`` (every image inlined as a base64 data URI, no external link: it opens anywhere, offline).

The folder is one of: an experiment run (``results.jsonl``, from ``navlab experiment run``), a sweep
(``sweep.csv`` and one run folder per combination, from ``navlab experiment sweep``) or a demo report
(``report.json``, from ``navlab demo``). A report is a list of blocks — headings, paragraphs, tables and
images — written once as Markdown and once as HTML.
"""

from __future__ import annotations

import base64
import html
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.errors import NavlabError
from navlab.experiments.errors import ExperimentError

TRIAL_COLUMNS = (
    "trial",
    "seed",
    "success",
    "move_base_success",
    "failure",
    "time_s",
    "path_m",
    "spl",
    "final_error_m",
    "min_clearance_m",
    "near_miss",
    "collisions",
    "localization_error_mean_m",
    "score",
    "world",
)


@dataclass
class Report:
    """A report's title and blocks: ``("h", text)``, ``("p", text)``, ``("table", header, rows)``,
    ``("img", path, caption)`` (paths relative to the folder)."""

    title: str
    blocks: list[tuple[Any, ...]] = field(default_factory=list)

    def heading(self, text: str) -> None:
        """A section heading."""
        self.blocks.append(("h", text))

    def text(self, text: str) -> None:
        """A paragraph."""
        self.blocks.append(("p", text))

    def table(self, header: list[str], rows: list[list[Any]]) -> None:
        """A table of cells (numbers, strings, lists)."""
        self.blocks.append(("table", header, rows))

    def image(self, path: str, caption: str) -> None:
        """A PNG in the folder."""
        self.blocks.append(("img", path, caption))


def _cell(v: Any) -> str:
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_cell(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, dict):
        return ", ".join(f"{k}: {_cell(x)}" for k, x in v.items()) or "-"
    return "-" if v is None or v == "" else str(v)


def to_markdown(rep: Report) -> str:
    """The report as Markdown (images linked by their relative paths)."""
    out = [f"# {rep.title}", ""]
    for block in rep.blocks:
        kind = block[0]
        if kind == "h":
            out += [f"## {block[1]}", ""]
        elif kind == "p":
            out += [block[1], ""]
        elif kind == "table":
            header, rows = block[1], block[2]
            out += ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
            out += ["| " + " | ".join(_cell(c).replace("|", "/") for c in row) + " |" for row in rows] + [""]
        else:
            out += [f"![{block[2]}]({block[1]})", ""]
    return "\n".join(out)


def to_html(rep: Report, folder: Path) -> str:
    """The report as one HTML page with its images inlined (data URIs): nothing outside the file is needed."""
    e = html.escape
    body = [f"<h1>{e(rep.title)}</h1>"]
    for block in rep.blocks:
        kind = block[0]
        if kind == "h":
            body.append(f"<h2>{e(block[1])}</h2>")
        elif kind == "p":
            body.append(f"<p>{e(block[1]).replace('`', '')}</p>")
        elif kind == "table":
            head = "".join(f"<th>{e(h)}</th>" for h in block[1])
            rows = "".join("<tr>" + "".join(f"<td>{e(_cell(c))}</td>" for c in row) + "</tr>" for row in block[2])
            body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>")
        else:
            data = base64.b64encode((folder / block[1]).read_bytes()).decode("ascii")
            body.append(
                f'<figure><img alt="{e(block[2])}" src="data:image/png;base64,{data}">'
                f"<figcaption>{e(block[2])}</figcaption></figure>"
            )
    style = (
        "body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}"
        "table{border-collapse:collapse;margin:1em 0;font-size:90%}td,th{border:1px solid #bbb;padding:3px 8px;"
        "text-align:right}th{background:#eee}img{max-width:100%}figcaption{color:#555;font-size:90%}"
    )
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{e(rep.title)}</title><style>{style}</style></head>\n<body>\n" + "\n".join(body) + "\n</body></html>\n"
    )


def folder_kind(folder: Path) -> str:
    """``sweep``, ``run`` or ``demo``, from the files the folder holds."""
    if (folder / "sweep.csv").is_file():
        return "sweep"
    if (folder / "results.jsonl").is_file():
        return "run"
    if (folder / "report.json").is_file():
        return "demo"
    raise ExperimentError(
        f"{folder}: not a results folder (expected results.jsonl from `navlab experiment run`, "
        "sweep.csv from `navlab experiment sweep` or report.json from `navlab demo`)"
    )


def render_report(folder: str | Path) -> dict[str, Any]:
    """Re-render ``folder``'s report: ``report.md``, its PNG figures and ``report.html``; returns what it wrote."""
    from navlab.io import write_text_atomic

    folder = Path(folder)
    if not folder.is_dir():
        raise ExperimentError(f"{folder}: no such results folder")
    kind = folder_kind(folder)
    rep = {"sweep": _sweep_report, "run": _run_report, "demo": _demo_report}[kind](folder)
    write_text_atomic(folder / "report.md", to_markdown(rep))
    write_text_atomic(folder / "report.html", to_html(rep, folder))
    figures = [b[1] for b in rep.blocks if b[0] == "img"]
    return {
        "kind": kind,
        "markdown": str(folder / "report.md"),
        "html": str(folder / "report.html"),
        "figures": [str(folder / f) for f in figures],
    }


# ----------------------------------------------------------------------------------------------- runs
def _summary_rows(summary: dict[str, Any]) -> list[list[Any]]:
    return [[k, v] for k, v in summary.items() if k != "scenario"]


def _run_report(folder: Path) -> Report:
    from navlab.experiments.trials import read_results, summarize_trials

    results = sorted(read_results(folder / "results.jsonl"), key=lambda r: int(r["trial"]))
    if not results:
        raise ExperimentError(f"{folder}/results.jsonl: no finished trial to report")
    name = _scenario_name(folder)
    summary = summarize_trials(results)
    rep = Report(f"Experiment {name}: {len(results)} trials")
    ok = sum(bool(r["success"]) for r in results)
    lo, hi = summary["success_ci95"]
    said = (
        ""
        if summary.get("move_base_success_rate") is None
        else (
            f" move_base reported {summary['move_base_success_rate']:.0%}, with {summary['false_success']} false "
            "successes (goals it called reached that the robot truly missed)."
        )
    )
    rep.text(
        f"{ok} of {len(results)} trials succeeded by the simulator's truth ({ok / len(results):.0%}, 95 % Wilson "
        f"interval {lo:.0%}–{hi:.0%}); {summary['trials_with_collision']} trials with a collision "
        f"({summary['collisions']} contact episodes in all).{said}"
    )
    rep.heading("Summary")
    rep.table(["figure", "value"], _summary_rows(summary))
    rep.heading("Trials")
    plot_trials(results, folder / "trials.png", title=name)
    rep.image("trials.png", "time to goal per trial (green: success, red: failure) and minimum clearance")
    if any(r.get("path_xy") for r in results):
        plot_trial_paths(results, folder / "paths.png", title=name)
        rep.image("paths.png", PATHS_CAPTION)
    cols = [c for c in TRIAL_COLUMNS if any(c in r for r in results)]
    rep.table(cols, [[r.get(c) for c in cols] for r in results])
    return rep


PATHS_CAPTION = "every trial's true path on the world's true map (green: success, red: failure), start and goals"


def plot_trial_paths(results: list[dict[str, Any]], path: Path, *, title: str = "") -> Path:
    """The trials' true paths over the world's true map (when the trials share a shipped or file world), coloured
    by outcome, with the start (circle) and the goals (stars with heading)."""
    import numpy as np

    from navlab.experiments.plots import Marks, Track, plot_run
    from navlab.grid import GridMap

    world = results[0].get("world_file")
    start = results[0].get("start") or [0.0, 0.0, 0.0]
    grid: GridMap | None = None
    if world and all(r.get("world_file") == world for r in results):
        from navlab.world import load_world, true_map

        try:
            grid = true_map(load_world(str(world)), (float(start[0]), float(start[1])))
        except NavlabError:  # the world file moved since the run: paths without the map
            grid = None
    tracks = []
    for k, r in enumerate(results):
        xy = np.asarray(r.get("path_xy") or [], dtype=np.float64).reshape(-1, 2)
        ok = bool(r["success"])
        label = None
        if k == next(i for i, q in enumerate(results) if bool(q["success"]) == ok):
            label = "trial path (succeeded)" if ok else "trial path (failed)"
        tracks.append(Track(xy, label or "", "-", "tab:green" if ok else "tab:red", 0.9))
    goals = np.array([g["goal"] for g in results[0].get("per_goal", [])], dtype=np.float64).reshape(-1, 3)
    if grid is None:  # no map: an empty unknown grid around the paths
        pts = np.vstack([t.xy for t in tracks if len(t.xy)] + [goals[:, :2], np.array([start[:2]])])
        lo, hi = pts.min(0) - 1.0, pts.max(0) + 1.0
        shape = (int((hi[1] - lo[1]) / 0.05) + 1, int((hi[0] - lo[0]) / 0.05) + 1)
        grid = GridMap(np.full(shape, -1, dtype=np.int8), 0.05, (float(lo[0]), float(lo[1]), 0.0))
    marks = [
        Marks(np.array([start[:2]]), "start", "black", "o", 60.0),
        Marks(goals[:, :2], "goals", "tab:purple", "*", 180.0),
    ]
    return plot_run(
        grid, tracks, path, title=f"{title}: {len(results)} trials' true paths", marks=marks, crop=False, dpi=100
    )


def _scenario_name(folder: Path) -> str:
    try:
        return str(json.loads((folder / "summary.json").read_text())["scenario"])
    except (OSError, ValueError, KeyError):
        return folder.name


def plot_trials(results: list[dict[str, Any]], path: Path, *, title: str = "") -> Path:
    """Two panels against the trial number: time (s) coloured by outcome, and minimum clearance (m)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from navlab.io import save_figure_atomic

    trials = [int(r["trial"]) for r in results]
    colours = ["tab:green" if r["success"] else "tab:red" for r in results]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 3.6))
    a.bar(trials, [r.get("time_s") or 0.0 for r in results], color=colours)
    for ax in (a, b):
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    a.set_xlabel("trial")
    a.set_ylabel("time (s)")
    a.set_title(f"{title}: time to goal" if title else "time to goal")
    b.plot(trials, [r.get("min_clearance_m") for r in results], "o-", color="tab:blue")
    b.axhline(0.0, color="k", lw=0.8)
    b.axhline(0.05, color="tab:red", lw=0.8, ls="--", label="near miss (< 5 cm)")
    b.legend(loc="upper right", fontsize=8)
    b.set_xlabel("trial")
    b.set_ylabel("minimum clearance (m)")
    b.set_title("closest approach to an obstacle")
    fig.tight_layout()
    try:
        save_figure_atomic(fig, path, dpi=100)
    finally:
        plt.close(fig)
    return path


# --------------------------------------------------------------------------------------------- sweeps
def _sweep_report(folder: Path) -> Report:
    import yaml

    from navlab.experiments.sweep import COLUMNS, plot_sweep
    from navlab.experiments.trials import read_results

    lines = (folder / "sweep.csv").read_text().splitlines()
    header = lines[0].split(",")
    names = header[: next((k for k, h in enumerate(header) if h in COLUMNS), len(header))]
    rows = []
    for line in lines[1:]:
        cells = line.split(",")
        row: dict[str, Any] = {}
        for h, c in zip(header, cells, strict=False):
            value = None if c in ("", "None") else yaml.safe_load(c)
            row[h] = [float(x) for x in c.split("/")] if h == "success_ci95" and c not in ("", "None") else value
        rows.append(row)
    rep = Report(f"Sweep of {', '.join(names)} ({len(rows)} combinations)")
    rep.text(f"Folder `{folder}`: one experiment per combination, in the subfolders named after it.")
    rep.heading("Table")
    rep.table(header, [[r.get(h) for h in header] for r in rows])
    rep.heading("Figures")
    for path in plot_sweep(rows, names, folder):
        rep.image(path.name, f"success (95 % CI), collisions and median time against {path.stem}")
    failures, pictures = [], []
    for sub in sorted(p for p in folder.iterdir() if (p / "summary.json").is_file()):
        s = json.loads((sub / "summary.json").read_text())
        failures.append([sub.name, s.get("trials"), s.get("failures") or {}])
        results = read_results(sub / "results.jsonl") if (sub / "results.jsonl").is_file() else []
        if any(r.get("path_xy") for r in results):  # as the combination's own run report draws them
            plot_trial_paths(sorted(results, key=lambda r: int(r["trial"])), sub / "paths.png", title=sub.name)
            pictures.append(f"{sub.name}/paths.png")
    if failures:
        rep.heading("Failures by kind")
        rep.table(["combination", "trials", "failures"], failures)
    if pictures:
        rep.heading("Paths per combination")
        for picture in pictures:
            rep.image(picture, f"{Path(picture).parent.name}: {PATHS_CAPTION}")
    return rep


# ----------------------------------------------------------------------------------------------- demo
def _demo_report(folder: Path) -> Report:
    """The demo's report: the paper's three steps with their figures and pictures (``navlab demo`` writes it
    with this too, so a re-render gives the same page)."""
    data = json.loads((folder / "report.json").read_text())
    m, loc, nav = (
        data.get(k) if isinstance(data.get(k), dict) else {} for k in ("mapping", "localization", "navigation")
    )
    rep = Report("navlab demo: the paper's pipeline in simulation")
    if "wall_s" in data:
        world = ", `world.png` (Figs. 4–5)" if (folder / "world.png").is_file() else ""
        rep.text(
            f"Total {data['wall_s']} s wall. Pictures: `map.png` (Fig. 7), `localize.png`, "
            f"`navigate/goal_N_mid.png` and `goal_N.png` (Figs. 9–12){world}."
        )
    rep.heading("1. Mapping: slam_gmapping while the robot explores room.world")
    rep.table(["figure", "value"], [[k, v] for k, v in m.items() if k not in ("map", "picture")])
    if (folder / "map.png").is_file():
        rep.image("map.png", "the saved map (the paper's Fig. 7)")
    rep.heading("2. Localization: AMCL on the saved map, in room_obstacles.world")
    rep.table(["figure", "value"], [[k, v] for k, v in loc.items() if k != "picture"])
    if (folder / "localize.png").is_file():
        rep.image("localize.png", "AMCL's estimate against the ground truth")
    rep.heading("3. Navigation: move_base on the saved map, obstacles added after mapping")
    goals = nav.get("goals") if isinstance(nav.get("goals"), list) else []
    cols = [
        "goal",
        "outcome",
        "move_base_outcome",
        "time_s",
        "path_m",
        "final_error_m",
        "min_clearance_m",
        "near_miss",
        "time_under_safety_s",
        "collisions",
        "reason",
    ]
    rep.table(cols, [[g.get(c) for c in cols] for g in goals])
    if "goals_succeeded" in nav:
        bag = f"; recording `{Path(nav['record']).name}/`" if nav.get("record") else ""
        rep.text(
            f"{nav['goals_succeeded']} of {len(goals)} goals reached (the simulator's truth; move_base reported "
            f"{nav.get('goals_succeeded_move_base', '-')}), {nav.get('collisions')} collisions "
            "(contact episodes); "
            f"{nav.get('sim_s')} simulated s at {nav.get('rtf')}x real time{bag}."
        )
    for k, g in enumerate(goals, 1):
        for png, when in ((f"navigate/goal_{k}_mid.png", "mid-drive"), (f"navigate/goal_{k}.png", "end of the drive")):
            if (folder / png).is_file():
                rep.image(png, f"goal {k} {g.get('goal')}: {g.get('outcome')} — {when}")
    if (folder / "world.png").is_file():
        rep.image("world.png", "the robot in its world")
    return rep
