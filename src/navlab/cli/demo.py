"""``navlab demo``: the paper's pipeline in one command (:func:`navlab.demo.run_demo`), with a report."""

from __future__ import annotations

import argparse
import json

from navlab import demo
from navlab.cli.options import add_run_options
from navlab.cli.runs import stop_signals, view_hook
from navlab.errors import interrupt_note


@stop_signals()  # SIGTERM as Ctrl-C, also as a background job: a recording is closed whole
def _cmd(args: argparse.Namespace) -> int:
    note = f"{args.out}/ holds the steps finished so far, each file whole; no report (run it again for one)"
    with interrupt_note(note), view_hook(args) as on_start:
        summary = demo.run_demo(
            args.out,
            seed=args.seed,
            quiet=args.quiet,
            render=not args.no_render,
            record=not args.no_record,
            on_start=on_start,
        )
    if args.json:
        print(json.dumps(summary))
        return 0
    m, loc = summary["mapping"], summary["localization"]
    print(f"\nnavlab demo — report in {summary['out']}/report.md and report.html (+ report.json, pictures, recording)")
    if "render" in summary:
        print(f"  robot in its world:  {summary['render']}")
    print(f"  map:                 {m['map']} (+ map.pgm), picture {m['picture']}")
    print(f"    {m['sim_s']:.0f} simulated s mapped in {m['wall_s']:.1f} s wall ({m['rtf']}x real time)")
    print(
        f"    walls: precision {m['precision']:.3f}, recall {m['recall']:.3f}, mean error {m['mean_wall_error_m']} m;"
        f" free space covered {m['coverage']:.1%}"
    )
    print(
        f"    SLAM trajectory error {m['position_error_mean_m']} m mean (raw odometry "
        f"{m['odometry_position_error_mean_m']} m)"
    )
    print(
        f"  AMCL on that map with new obstacles: mean error {loc['position_error_mean_m']} m, "
        f"{loc['yaw_error_mean_deg']}° over {loc['sim_s']:.0f} s; picture {loc['picture']}"
    )
    n = summary["navigation"]
    print(
        f"  move_base on that map: {n['goals_succeeded']} of {len(n['goals'])} goals reached (the simulator's "
        f"truth; move_base reported {n['goals_succeeded_move_base']}), {n['collisions']} collisions; pictures in "
        f"{summary['out']}/navigate/"
    )
    for k, g in enumerate(n["goals"], 1):
        said = f", move_base: {g['move_base_outcome']}" if g["move_base_outcome"] != g["outcome"] else ""
        print(
            f"    goal {k} {tuple(g['goal'])}: {g['outcome']}{said} in {g['time_s']} s, path {g['path_m']} m, "
            f"{g['final_error_m']} m from the goal, closest {g['min_clearance_m']} m"
            + (" — NEAR MISS (< 5 cm)" if g.get("near_miss") else "")
            + (f" ({g['reason']})" if g["reason"] else "")
        )
    print(f"  total {summary['wall_s']} s wall")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``demo``."""
    p = sub.add_parser(
        "demo",
        help="run the paper's pipeline: render, SLAM mapping by exploration, AMCL and move_base on the saved map",
        description=demo.__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--out",
        default="navlab-demo",
        metavar="DIR",
        help="the report folder: report.md, report.json, map.png, pictures and the recording (default ./navlab-demo)",
    )
    p.add_argument("--no-record", action="store_true", help="no rosbag2 recording of the navigation step")
    p.add_argument("--no-render", action="store_true", help="skip the rendered picture (no OpenGL needed)")
    add_run_options(p, seed=0, quiet=True, json=True, view=True)
    p.set_defaults(func=_cmd)
