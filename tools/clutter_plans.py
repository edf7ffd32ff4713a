"""Watch move_base's global plans through one clutter world: when the first plans commit to a way, and when the
global costmap shows it closed.

    python tools/clutter_plans.py OUT.png [--set tuning] [--world 36] [--seed 0] [--every 2]
        [--param global_costmap.track_unknown_space=true ...]

Runs world ``--world`` of ``bench clutter``'s ``--set`` with the Jackal, MPPI at 2 m/s and the benchmark's
overrides (plus each ``--param KEY=JSON``), records every global plan with the global costmap it was made on, and
draws every ``--every``-th in a grid of panels (odom frame, m): the costmap (white free, grey unknown, black
inscribed and lethal), the plan (blue), the path driven so far (green), the robot, the goal and the world's true
cylinders (red circles, seen or not) with its shortest path for a disc (cyan, dashed). Prints the trial's figures.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

import numpy as np


def clutter_world(which: str, index: int) -> Any:
    """World ``index`` (0-49) of ``bench clutter``'s set ``which`` (test or tuning), or of the suite whose seed
    ``which`` is (a number >= 2: more worlds to look at, neither tuning nor test)."""
    from navlab.experiments.clutter_protocol import SETS
    from navlab.world import clutter_suite

    return clutter_suite(50, seed=SETS[which] if which in SETS else int(which))[index]


def drive(world: Any, seed: int, params: dict[str, Any]) -> dict[str, Any]:
    """One trial of the Jackal with MPPI at 2 m/s through ``world``, as ``bench clutter`` runs it, plus ``params``."""
    from navlab.experiments.clutter_protocol import speed_overrides
    from navlab.experiments.clutter_run import run_clutter_world

    return run_clutter_world(
        world, controller="mppi", move_base_params={**speed_overrides("mppi", 2.0), **params}, seed=seed, robot="jackal"
    )


def parse_params(pairs: list[str]) -> dict[str, Any]:
    """``KEY=JSON`` strings as move_base overrides."""
    params = {}
    for kv in pairs:
        key, _, value = kv.partition("=")
        params[key] = json.loads(value)
    return params


def record(which: str, index: int, seed: int, params: dict[str, Any]) -> tuple[Any, dict[str, Any], list[Any]]:
    """Run the world; (world, trial figures, [(t s, costmap Grid copy, start (x, y, yaw), plan (N, 2+) or None)])."""
    from navlab.grid import Grid
    from navlab.navigation.move_base import MoveBase

    world = clutter_world(which, index)
    plans: list[Any] = []
    make_plan = MoveBase.make_plan

    def on_make_plan(self: Any, start: Any, goal: Any) -> Any:
        plan = make_plan(self, start, goal)
        g = self.global_costmap.costmap
        copy = Grid(g.data.copy(), g.resolution, g.origin, g.frame_id)
        plans.append((self.executor.now_ns * 1e-9, copy, tuple(start), None if plan is None else plan.copy()))
        return plan

    MoveBase.make_plan = on_make_plan  # type: ignore[method-assign]
    try:
        trial = drive(world, seed, params)
    finally:
        MoveBase.make_plan = make_plan  # type: ignore[method-assign]
    return world, trial, plans


def draw(world: Any, trial: dict[str, Any], plans: list[Any], every: int, out: str, title: str) -> None:
    """The grid of panels (see the module docstring) to ``out`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import EllipseCollection

    from navlab.geometry import between2
    from navlab.world.clutter import CYLINDER_RADIUS

    def to_odom(xy: np.ndarray) -> np.ndarray:
        return np.array([between2(world.start, (x, y, 0.0))[:2] for x, y in xy])

    cylinders, reference = to_odom(world.cylinders), to_odom(world.reference_path)
    goal = between2(world.start, world.goal)
    driven = np.array([p[2][:2] for p in plans])
    shown = list(range(0, len(plans), max(1, every)))
    cols = 4
    rows = max(1, math.ceil(len(shown) / cols))
    fig, axs = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    for ax, k in zip(axs.ravel(), shown, strict=False):
        t, grid, start, plan = plans[k]
        d = grid.data
        shade = np.where(d == 255, 150.0, np.where(d >= 253, 0.0, 255.0 - 0.6 * d))
        ox, oy = grid.origin[0], grid.origin[1]
        extent = (ox, ox + grid.width * grid.resolution, oy, oy + grid.height * grid.resolution)
        ax.imshow(shade, cmap="gray", origin="lower", vmin=0, vmax=255, extent=extent)
        size = 2 * CYLINDER_RADIUS
        ax.add_collection(
            EllipseCollection(
                size,
                size,
                0,
                units="xy",
                offsets=cylinders,
                offset_transform=ax.transData,
                facecolors="none",
                edgecolors="r",
                linewidths=0.5,
            )
        )
        ax.plot(reference[:, 0], reference[:, 1], "c--", lw=0.8)
        if plan is not None:
            ax.plot(plan[:, 0], plan[:, 1], "b-", lw=1.2)
        ax.plot(driven[: k + 1, 0], driven[: k + 1, 1], "g-", lw=1.0)
        ax.plot(start[0], start[1], "go")
        ax.plot(goal[0], goal[1], "m*")
        ax.set_xlim(-1.0, 12.5)
        ax.set_ylim(-3.5, 3.5)
        ax.set_aspect("equal")
        ax.set_title(f"plan {k} at t = {t:.1f} s" + ("" if plan is not None else " (none)"), fontsize=9)
    for ax in axs.ravel()[len(shown) :]:
        ax.axis("off")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    from navlab.io import save_figure_atomic

    try:
        save_figure_atomic(fig, out, format="png", dpi=80)
    finally:
        plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the picture (PNG)")
    ap.add_argument("--set", default="tuning", help="test, tuning or a suite seed >= 2")
    ap.add_argument("--world", type=int, default=36, help="index in the set, 0-49")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--every", type=int, default=2, help="draw every N-th plan")
    ap.add_argument("--param", action="append", default=[], metavar="KEY=JSON", help="a move_base override")
    a = ap.parse_args()
    params = parse_params(a.param)
    world, trial, plans = record(a.set, a.world, a.seed, params)
    figures = {k: trial[k] for k in ("world", "success", "failure", "barn_time_s", "score")}
    figures["cap_time_s"] = round(2 * trial["t_opt_s"], 2)
    print(json.dumps({**figures, "plans": len(plans)}))
    title = f"{world.name} (set {a.set}, world {a.world}), seed {a.seed}{' ' + str(params) if params else ''}: " + (
        f"{trial['barn_time_s']} s on BARN's clock, {figures['cap_time_s']} s scores the cap"
    )
    draw(world, trial, plans, a.every, a.out, title)
    print(a.out)


if __name__ == "__main__":
    main()
