"""Watch MPPI cycle by cycle through one clutter world: why the robot stands or creeps at a gap.

    python tools/clutter_cycles.py [--set tuning] [--world 43] [--seed 3] [--every 5] [--at 6.4,7.1]
        [--box X0,X1,Y0,Y1] [--out OUT.png] [--param global_costmap.footprint_padding=0.05 ...]

Runs world ``--world`` of ``bench clutter``'s ``--set`` with the Jackal, MPPI at 2 m/s and the benchmark's
overrides (plus each ``--param KEY=JSON``) and prints every ``--every``-th MPPI cycle: time (s), pose (odom: m, rad),
measured and commanded (v m/s, w rad/s), ``valid`` (False: every sample collided, the robot is stopped), what the
rotation shim did (its command, or None: MPPI drove) and its heading error to the plan (rad), the share of samples
CostCritic charged a collision (footprint) in each optimisation round, and the local costmap cost under the robot
with the cost-regulated speed limit it gives (m/s); then move_base's recoveries. ``--out`` draws, at each time of
``--at``, the global costmap with the plan of that moment (top) and the local costmap with MPPI's optimal trajectory
(magenta; bottom), the true cylinders (red), the Jackal's footprint and the path driven (green), zoomed to ``--box``
(odom, m).
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

import numpy as np
from clutter_plans import clutter_world, drive, parse_params  # tools/, beside this script

FOOTPRINT = np.array([[-0.254, -0.215], [-0.254, 0.215], [0.254, 0.215], [0.254, -0.215]])  # m, the Jackal's


def record(which: str, index: int, seed: int, params: dict[str, Any]) -> tuple[Any, dict[str, Any], dict[str, list]]:
    """Run the world; (world, trial figures, {"cycles": [...], "plans": [(t, grid, plan)], "recoveries": [...]})."""
    from navlab.navigation.controllers import mppi, mppi_critics, mppi_rotation
    from navlab.navigation.move_base import MoveBase

    world = clutter_world(which, index)
    log: dict[str, list] = {"cycles": [], "plans": [], "recoveries": []}
    cycle: dict[str, Any] = {}
    clock: list[Any] = []
    cost_critic, shim_command = mppi_critics.SCORERS["CostCritic"], mppi_rotation.RotationShim.command
    command, make_plan, clearing = mppi.MPPIController._command, MoveBase.make_plan, MoveBase._enter_clearing

    def on_cost(c: Any, b: Any) -> Any:
        out = cost_critic(c, b)
        points = b.cost[:, :: max(1, c.trajectory_point_step)].shape[1]
        cycle.setdefault("collided", []).append(
            float((out >= 0.999 * c.cost_weight * c.collision_cost / (254.0 * points)).mean())
        )
        return out

    def on_shim(self: Any, pose: Any, velocity: Any, path: Any, *args: Any, **kw: Any) -> Any:
        cmd = shim_command(self, pose, velocity, path, *args, **kw)
        cycle["shim"], cycle["heading_error"] = cmd, self.heading_error(pose, path)
        return cmd

    def on_command(self: Any, pose: Any, velocity: Any, costmap: Any) -> tuple[float, float]:
        cycle.clear()
        v, w = command(self, pose, velocity, costmap)
        i, j = (math.floor((pose[k] - costmap.origin[k]) / costmap.resolution) for k in (0, 1))
        inside = 0 <= i < costmap.width and 0 <= j < costmap.height
        cost = int(costmap.data[j, i]) if inside else 255
        cap = None if self._speed_limits is None else float(self._speed_limits[cost])
        grid = (costmap.data.copy(), costmap.resolution, tuple(costmap.origin))
        entry = {"t": clock[0].executor.now_ns * 1e-9 if clock else math.nan, "pose": tuple(map(float, pose))}
        entry.update(velocity=tuple(map(float, velocity)), cmd=(v, w), valid=self.valid, cost=cost, cap=cap)
        log["cycles"].append({**entry, **cycle, "local_plan": self.local_plan.copy(), "grid": grid})
        return v, w

    def on_make_plan(self: Any, start: Any, goal: Any) -> Any:
        clock[:] = [self]
        plan = make_plan(self, start, goal)
        g = self.global_costmap.costmap
        grid = (g.data.copy(), g.resolution, tuple(g.origin))
        log["plans"].append((self.executor.now_ns * 1e-9, grid, None if plan is None else plan.copy()))
        return plan

    def on_clearing(self: Any, trigger: Any) -> None:
        log["recoveries"].append((round(self.executor.now_ns * 1e-9, 2), str(trigger)))
        clearing(self, trigger)

    mppi_critics.SCORERS["CostCritic"] = on_cost
    patches = [
        (mppi_rotation.RotationShim, "command", on_shim, shim_command),
        (mppi.MPPIController, "_command", on_command, command),
        (MoveBase, "make_plan", on_make_plan, make_plan),
        (MoveBase, "_enter_clearing", on_clearing, clearing),
    ]
    for cls, name, new, _ in patches:
        setattr(cls, name, new)
    try:
        trial = drive(world, seed, params)
    finally:
        mppi_critics.SCORERS["CostCritic"] = cost_critic
        for cls, name, _, old in patches:
            setattr(cls, name, old)
    return world, trial, log


def describe(c: dict[str, Any]) -> str:
    """One cycle as a line of text."""
    shim = None if c.get("shim") is None else tuple(round(x, 2) for x in c["shim"])
    err = c.get("heading_error")
    collided = [round(x, 2) for x in c.get("collided", [])]
    cap = None if c["cap"] is None else round(c["cap"], 2)
    return (
        f"{c['t']:6.2f} x={c['pose'][0]:5.2f} y={c['pose'][1]:5.2f} th={c['pose'][2]:5.2f} "
        f"v0={c['velocity'][0]:5.2f} w0={c['velocity'][1]:5.2f} cmd=({c['cmd'][0]:5.2f},{c['cmd'][1]:5.2f}) "
        f"valid={int(c['valid'])} shim={shim} err={None if err is None else round(err, 2)} collided={collided} "
        f"cost={c['cost']} cap={cap}"
    )


def draw(world: Any, log: dict[str, list], times: list[float], box: list[float], out: str) -> None:
    """The zoomed panels (see the module docstring) to ``out`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon

    from navlab.geometry import between2
    from navlab.io import save_figure_atomic
    from navlab.world.clutter import CYLINDER_RADIUS

    cylinders = [between2(world.start, (x, y, 0.0))[:2] for x, y in world.cylinders]
    cycles = log["cycles"]
    stamps = np.array([c["t"] for c in cycles])
    driven = np.array([c["pose"][:2] for c in cycles])
    fig, axs = plt.subplots(2, len(times), figsize=(4 * len(times), 8), squeeze=False)

    def panel(ax: Any, grid: tuple[np.ndarray, float, tuple], title: str) -> None:
        data, res, origin = grid
        shade = np.where(data == 255, 150.0, np.where(data >= 253, 0.0, 255.0 - 0.6 * data))
        h, w = data.shape
        extent = (origin[0], origin[0] + w * res, origin[1], origin[1] + h * res)
        ax.imshow(shade, cmap="gray", origin="lower", vmin=0, vmax=255, extent=extent)
        for c in cylinders:
            ax.add_patch(Circle(c, CYLINDER_RADIUS, fill=False, ec="r", lw=0.8))
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=8)

    for k, t in enumerate(times):
        made, grid, plan = [p for p in log["plans"] if p[0] <= t + 1e-6][-1]
        i = int(np.argmin(np.abs(stamps - t)))
        c = cycles[i]
        panel(axs[0, k], grid, f"global costmap and plan at t = {made:.1f} s")
        title = (
            f"local costmap, t = {c['t']:.2f} s: v {c['velocity'][0]:.2f}, cmd ({c['cmd'][0]:.2f}, {c['cmd'][1]:.2f})"
        )
        panel(axs[1, k], c["grid"], title)
        x, y, th = c["pose"]
        rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        for ax in axs[:, k]:
            ax.plot(driven[: i + 1, 0], driven[: i + 1, 1], "g-", lw=0.8)
            ax.add_patch(Polygon(FOOTPRINT @ rot.T + [x, y], fill=False, ec="g", lw=1))
            if plan is not None:
                ax.plot(plan[:, 0], plan[:, 1], "b-", lw=0.8)
        if len(c["local_plan"]):
            axs[1, k].plot(c["local_plan"][:, 0], c["local_plan"][:, 1], "m-", lw=1)
    fig.tight_layout()
    try:
        save_figure_atomic(fig, out, format="png", dpi=70)
    finally:
        plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", default="tuning", help="test, tuning or a suite seed >= 2")
    ap.add_argument("--world", type=int, default=43, help="index in the set, 0-49")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--every", type=int, default=5, help="print every N-th cycle")
    ap.add_argument("--at", default="", help="times (s) to draw, comma-separated")
    ap.add_argument("--box", default="3.5,6.5,-2.0,1.5", help="the drawn window X0,X1,Y0,Y1 (odom, m)")
    ap.add_argument("--out", default="", help="the picture (PNG), with --at")
    ap.add_argument("--param", action="append", default=[], metavar="KEY=JSON", help="a move_base override")
    a = ap.parse_args()
    params = parse_params(a.param)
    world, trial, log = record(a.set, a.world, a.seed, params)
    for c in log["cycles"][:: max(1, a.every)]:
        print(describe(c))
    print("recoveries:", log["recoveries"])
    print(json.dumps({k: trial[k] for k in ("world", "success", "barn_time_s", "score", "min_clearance_m")}))
    if a.out and a.at:
        draw(world, log, [float(t) for t in a.at.split(",")], [float(v) for v in a.box.split(",")], a.out)
        print(a.out)


if __name__ == "__main__":
    main()
