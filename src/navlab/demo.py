"""``navlab demo``: the paper's pipeline end to end, in simulation, faster than real time.

1. The robot in its world (Figs. 4–5): a rendered picture of room_obstacles.world.
2. Mapping (Fig. 7): slam_gmapping while the robot explores the empty room by itself; the map is saved
   as map.yaml + map.pgm and scored against the world.
3. Localization: cubes and cylinders are added that the map does not have (room_obstacles), and AMCL
   tracks the robot on the saved map along a route; its error against ground truth is printed.
4. Navigation (Figs. 9-12): move_base on the saved map drives to a sequence of goals in that room, plus one
   more cylinder dropped in while it drives; each goal's outcome, time and collisions are printed and
   drawn (navigate/goal_N.png).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any


def _say(text: str, quiet: bool) -> None:
    if not quiet:
        print(text, file=sys.stderr, flush=True)


def _progress(text: str) -> None:
    print(f"      {text}", file=sys.stderr, flush=True)


def run_demo(
    out: str | Path = "navlab-demo",
    *,
    seed: int = 0,
    quiet: bool = False,
    render: bool = True,
    record: bool = True,
    on_start: Any = None,
) -> dict[str, Any]:
    """Run the four steps, writing the report folder ``out``; returns the figures (also in report.json)."""
    from navlab.experiments import plot_result, run_localization, run_mapping, run_navigation, save_goal_pictures
    from navlab.sim import primitive_model

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, Any] = {"out": str(out)}
    t0 = time.perf_counter()
    if render:
        _say("[1/4] rendering the robot in room_obstacles.world ...", quiet)
        summary["render"] = _render(out / "world.png")
    _say("[2/4] mapping room.world with slam_gmapping while the robot explores ...", quiet)
    mapping = run_mapping(
        world="room", out=out / "map", driver="explore", duration=300, seed=seed, quiet=quiet, on_start=on_start
    )
    summary["mapping"] = {"map": str(mapping.map_yaml), "picture": str(out / "map" / "map.png"), **mapping.scores}
    _say("[3/4] AMCL on the saved map, in the room with new obstacles (room_obstacles.world) ...", quiet)
    loc = run_localization(
        "room_obstacles", mapping.map_yaml, duration=60.0, seed=seed, progress=not quiet, on_start=on_start
    )
    summary["localization"] = {**loc.summary, "picture": str(plot_result(loc, out / "localize.png"))}
    _say("[4/4] move_base on the saved map, to goals among the new obstacles and one more cylinder ...", quiet)
    late = primitive_model("cylinder", "late_cylinder", (0.15, 0.6), x=-1.0, y=-0.45)
    nav = run_navigation(
        DEMO_GOALS,
        world="room_obstacles",
        map_yaml=mapping.map_yaml,
        spawn=[(20.0, late)],
        seed=seed,
        goal_timeout=90,
        snapshots=True,
        progress=None if quiet else _progress,
        record=out / "recording" if record else None,
        on_start=on_start,
    )
    pictures = save_goal_pictures(nav, out / "navigate")
    for k, goal in enumerate(nav.goals):
        goal["picture"], goal["picture_mid"] = pictures[2 * k], pictures[2 * k + 1]
    summary["navigation"] = {"goals": nav.goals, **nav.summary}
    summary["wall_s"] = round(time.perf_counter() - t0, 1)
    write_report(summary, out)
    return summary


def write_report(summary: dict[str, Any], out: Path) -> None:
    """``report.json`` (every figure), ``map.png`` (Fig. 7) on top, and ``report.md`` + ``report.html`` rendered
    from them by ``navlab report``'s renderer."""
    import shutil

    from navlab.experiments import render_report
    from navlab.io import write_text_atomic

    if Path(summary["mapping"]["picture"]).is_file():
        shutil.copyfile(summary["mapping"]["picture"], out / "map.png")
    write_text_atomic(out / "report.json", json.dumps(summary, indent=1) + "\n")
    render_report(out)


# Goals across room_obstacles (map frame = the world frame: the robot mapped from the origin).
DEMO_GOALS = [(4.3, 1.0, 0.0), (-3.5, -0.5, 3.14), (1.5, -2.5, 0.0)]


def _render(path: Path) -> str:
    """Picture of the paper's robot among the obstacles; skipped (with the reason) without OpenGL."""
    from navlab.description import load_robot_named
    from navlab.sim import Simulation, render_image, save_png
    from navlab.world import load_world

    try:
        sim = Simulation(load_robot_named("mybot"), load_world("room_obstacles"), visuals=True)
        sim.advance_to(200_000_000)
        return str(save_png(render_image(sim, width=960, height=720), path))
    except Exception as exc:  # no EGL/OSMesa on this machine: the rest of the demo still runs
        return f"skipped: {exc}"
