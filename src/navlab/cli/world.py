"""``navlab world clutter`` (a BARN-style cluttered world: .world SDF, optional PNG and JSON) and ``navlab world
office`` (the generated office floor and a sparse laser log recorded in it)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from navlab.cli.options import add_run_options, optional_out, out_file, print_figures

if TYPE_CHECKING:
    from navlab.world import ClutterWorld


def save_png(world: ClutterWorld, path: str | Path) -> None:
    """Top view (world frame, m): walls, cylinders, start, goal and the reference path."""
    import matplotlib

    from navlab.world import CYLINDER_RADIUS, FIELD

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Rectangle

    from navlab.io import save_figure_atomic

    fig, ax = plt.subplots(figsize=(10, 5.2))
    try:
        ax.add_collection(
            PatchCollection(
                [Rectangle((w.x - w.sx / 2, w.y - w.sy / 2), w.sx, w.sy) for w in world.walls],
                facecolor="0.55",
                edgecolor="none",
            )
        )
        ax.add_collection(
            PatchCollection(
                [Circle((x, y), CYLINDER_RADIUS) for x, y in world.cylinders], facecolor="0.2", edgecolor="none"
            )
        )
        ax.add_patch(Rectangle((0.0, -FIELD / 2), FIELD, FIELD, fill=False, linestyle=":", edgecolor="0.6"))
        ref = world.reference_path
        ax.plot(
            ref[:, 0], ref[:, 1], "-", color="tab:blue", lw=1.5, label=f"reference path {world.reference_path_m:.2f} m"
        )
        (sx, sy, _), (gx, gy, _) = world.start, world.goal
        ax.add_patch(Circle((sx, sy), world.robot_radius, facecolor="none", edgecolor="tab:green", lw=1.5))
        ax.plot([sx], [sy], "o", color="tab:green", label="start")
        ax.plot([gx], [gy], "*", color="tab:red", ms=14, label="goal")
        ax.set_aspect("equal")
        ax.set_xlim(min(w.x - w.sx / 2 for w in world.walls) - 0.3, gx + 0.7)
        ax.set_ylim(-FIELD / 2 - 0.6, FIELD / 2 + 0.6)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(
            f"{world.name}: {len(world.cylinders)} cylinders ({world.attempts} draws), "
            f"difficulty {world.difficulty:.3f}"
        )
        ax.legend(loc="upper right", fontsize=8)
        fig.tight_layout()
        save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def _cmd_clutter(args: argparse.Namespace) -> int:
    from navlab.world import generate_clutter

    if args.margin is not None:
        print(
            "navlab: DeprecationWarning: --margin is ignored and goes in the next release: nothing is carved any "
            "more; each world is drawn until the robot's configuration space (--robot-cells) connects the field's "
            "ends, as BARN's",
            file=sys.stderr,
        )
    world = generate_clutter(
        args.seed, fill=args.fill, smooth=args.smooth, robot_radius=args.robot_radius, robot_cells=args.robot_cells
    )
    out = world.write_world(out_file(args.out, "clutter.world", old_suffixes=(".world", ".sdf")))
    png = optional_out(args.png, out.parent, "clutter.png")
    if png:
        save_png(world, png)
    summary = {**world.summary(), "world_file": str(out), "png": str(png) if png else None}
    if args.json:
        print(json.dumps(summary))
        return 0
    (sx, sy, syaw), (gx, gy, gyaw) = world.start, world.goal
    print(
        f"{world.name}: {len(world.cylinders)} cylinders ({world.attempts} automaton draws until a way through "
        f"for robot_cells {world.robot_cells}), difficulty {world.difficulty:.3f}"
    )
    print(f"start  x {sx:.3f} y {sy:.3f} yaw {syaw:.3f}")
    print(f"goal   x {gx:.3f} y {gy:.3f} yaw {gyaw:.3f}")
    print(
        f"reference path {world.reference_path_m:.3f} m for robot radius {world.robot_radius} m "
        f"(T_opt {world.t_opt():.2f} s at 2 m/s; narrowest passage half-width "
        f"{world.metrics['bottleneck_m']:.3f} m)"
    )
    print(f"BARN's path {world.barn_path_m:.3f} m, as its generator saves it (BARN's T_opt {world.barn_t_opt():.2f} s)")
    print(f"wrote {out}" + (f" and {png}" if png else ""))
    return 0


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}")
    return value


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``world`` verb (``navlab world clutter``)."""
    p = sub.add_parser(
        "world",
        help="generate worlds (BARN-style clutter)",
        description="Generate Gazebo .world files navlab and Gazebo classic both load.",
    )
    verbs = p.add_subparsers(dest="world_command", metavar="WHAT", required=True)
    c = verbs.add_parser(
        "clutter",
        help="a BARN-style field of cylinders between walls, with start, goal and reference path",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="A 4.5 x 4.5 m field of 0.075 m-radius cylinders on a 0.15 m grid, grown by a cellular\n"
        "automaton (random --fill, then --smooth rounds) between two rows of wall cylinders, as BARN's\n"
        "dataset generator makes it (Perille et al. 2020); drawn again until the robot's configuration\n"
        "space (no cylinder within --robot-cells cells of its centre: 2 for the Jackal) connects the\n"
        "field's ends. The robot starts at (-2.1, -0.25) facing +x, 2.1 m before the field; the goal is\n"
        "(7.9, -0.25), 10 m away. Prints start, goal and the reference (shortest collision-free) path length.",
        epilog="examples:\n"
        "  navlab world clutter --seed 3 --fill 0.3 --smooth 2 --out clutter --png   # clutter/clutter.world, .png\n"
        "  navlab sim --world clutter/clutter.world --x -2.1 --y -0.25 --duration 5",
    )
    add_run_options(c, seed=0, json=True)
    c.add_argument("--fill", type=_fraction, default=0.25, help="initial fill probability per cell (default 0.25)")
    c.add_argument("--smooth", type=_count, default=2, help="cellular-automaton rounds (default 2)")
    c.add_argument(
        "--robot-radius",
        type=float,
        default=0.2,
        help="radius of the robot disc the reference path is planned for (m, default 0.2: mybot)",
    )
    c.add_argument(
        "--robot-cells",
        type=_count,
        default=2,
        help="cells the robot reaches beyond its centre cell; the world keeps a way through for it (default 2: "
        "BARN's Jackal, 0.375 m clearance)",
    )
    c.add_argument("--margin", type=float, default=None, help=argparse.SUPPRESS)  # deprecated: nothing is carved
    c.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="folder to write clutter.world in (a FILE.world still works this release, deprecated)",
    )
    c.add_argument(
        "--png",
        nargs="?",
        const="",
        default=None,
        metavar="FILE.png",
        help="also draw the world and the reference path: in FILE.png, or DIR/clutter.png without a value",
    )
    c.set_defaults(func=_cmd_clutter)
    add_world_office(verbs)


def _cmd_world_office(args: argparse.Namespace) -> int:
    from navlab.experiments import rounded
    from navlab.io import write_carmen, write_poses
    from navlab.mapping import OdometryNoise, record_log
    from navlab.world import generate_office

    office = generate_office()
    world = office.write_world(out_file(args.out, "office.world", old_suffixes=(".world", ".sdf")))
    log = optional_out(args.log, world.parent, "office.clf")
    truth = optional_out(args.truth, world.parent, "truth.txt")
    summary: dict = {
        "world": str(world),
        "width_m": office.width,
        "depth_m": office.depth,
        "rooms": office.rooms,
        "start": list(office.start),
    }
    if log:
        rec = record_log(
            world,
            office.route(),
            seed=args.seed,
            noise=OdometryNoise(scale=args.odom_scale, heading_drift=args.heading_drift),
        )
        write_carmen(
            log,
            rec.log,
            comment=f"navlab office log, seed {args.seed}: odometry frame = the true "
            f"start pose {rec.start} in {world.name}",
        )
        summary.update(log=str(log), scans=len(rec.log.scans), log_s=rec.log.duration)
        if truth:
            from navlab.experiments import apply_se2
            from navlab.geometry import inverse2

            # the truth in the log's odometry frame (the start pose), as the SLAM output is
            write_poses(truth, rec.timestamps, apply_se2(tuple(inverse2(rec.start)), rec.truth))
            summary["truth"] = str(truth)
    print_figures(rounded(summary), args.json)
    return 0


def add_world_office(verbs: argparse._SubParsersAction) -> None:
    """``navlab world office``: the generated office floor, and a sparse log recorded in it."""
    o = verbs.add_parser(
        "office",
        help="an office floor (30 x 20.5 m, 28 alike rooms, corridors closing two loops) and a sparse log in it",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Writes the generated office floor as a .world file. With --log, drives the robot around "
        "both loops\n(and into two rooms) in the simulator and records a sparse laser log: a scan every 1 m "
        "or 0.5 rad,\n181 beams over 180 degrees, wheel odometry with --odom-scale scale errors and heading "
        "drift.\nThe log's odometry frame is the robot's true start pose; --truth writes the true poses in it.",
        epilog="examples:\n"
        "  navlab world office --out office --log --truth --seed 1   # office/office.world, office.clf, truth.txt\n"
        "  navlab slam --log office/office.clf --out office_map --mode gmapping\n"
        "  navlab eval trajectory office_map/poses.txt office/truth.txt",
    )
    o.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="folder to write office.world in (a FILE.world still works this release, deprecated)",
    )
    o.add_argument(
        "--log",
        nargs="?",
        const="",
        metavar="FILE.clf",
        help="also record a sparse CARMEN log: in FILE.clf, or DIR/office.clf without a value",
    )
    o.add_argument(
        "--truth",
        nargs="?",
        const="",
        metavar="FILE.txt",
        help="with --log: the true poses ('t x y theta', log frame) in FILE.txt, or DIR/truth.txt",
    )
    add_run_options(o, seed=0, json=True)
    o.add_argument(
        "--odom-scale",
        type=float,
        default=0.05,
        help="std. dev. of the odometry's scale errors and per-step noise (default 0.05: 5 %%)",
    )
    o.add_argument(
        "--heading-drift",
        type=float,
        default=0.02,
        help="std. dev. of the odometry's heading drift rate, rad/m (default 0.02)",
    )
    o.set_defaults(func=_cmd_world_office)
