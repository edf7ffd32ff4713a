"""The paper's mapping step in simulation: the ``mapping`` launch (sim + slam_gmapping [+ explore]) with a
driver (exploration, teleop or a route), then the saved map scored against the world's truth.

``run_mapping`` is the Python API behind ``navlab map``. The map frame is SLAM's odom frame at the start:
the world frame for world-source odometry (Gazebo's default), the robot's start pose for encoder
odometry (see ``experiments.truth.world_T_map``); scores and truth overlays are taken in it.
"""

from __future__ import annotations

import contextlib
import logging
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab.errors import interrupt_note
from navlab.experiments.metrics import free_coverage, score_map, trajectory_error
from navlab.experiments.monitors import PoseMonitor
from navlab.experiments.plots import Marks, Track, plot_run
from navlab.experiments.session import Run, rounded, start_run
from navlab.geometry import inverse_transform_points2, wrap_angle
from navlab.grid import GridMap
from navlab.io import check_regular_file
from navlab.mapping import MappingError, save_map
from navlab.world import true_occupancy, world_T_map

DRIVERS = ("explore", "teleop", "route")
TRAJECTORY_HEADER = (
    "# t x y theta true_x true_y true_theta  (s, m, rad; map frame = the odom frame at the start: "
    "the world for world odometry, the start pose for encoder odometry)"
)


@dataclass
class MappingResult:
    """What a mapping run produced: files, the final grid, and its scores against the world's truth."""

    map_yaml: Path
    grid: GridMap
    sim_s: float
    finished: bool
    cpu_s: float = 0.0  # this process's CPU time in the run loop
    scores: dict[str, Any] = field(default_factory=dict)


def _add_driver(run: Run, driver: str, route: str | Path | None, stack: contextlib.ExitStack, quiet: bool) -> Any:
    """Start the driver node; returns a callable telling whether it is done. What the driver holds (the
    terminal, for teleop) is given back when ``stack`` closes; teleop shows its status line unless ``quiet``."""
    from navlab.drivers import HELP, RouteFollower, TeleopKeyboard, load_route, terminal_keys

    if driver == "explore":
        from navlab.drivers import Explore

        explorer = run.node("explore")
        assert isinstance(explorer, Explore)  # the shipped launch's explore
        return lambda: explorer.done
    if driver == "route":
        if route is None:
            raise MappingError("driver 'route' needs a route file (--route FILE)")
        segments, waypoints = load_route(route)
        follower = run.add(
            RouteFollower,
            parameters={
                "segments": [{"linear": v, "angular": w, "duration": d} for v, w, d in segments],
                "waypoints": waypoints.tolist(),
                "base_frame": run.base_frame,
                "odom_frame": run.odom_frame,
            },
        )
        return lambda: follower.done
    teleop = run.add(TeleopKeyboard)
    print("teleop_twist_keyboard:\n" + HELP, flush=True)
    stack.enter_context(terminal_keys(teleop, run.executor))
    if not quiet:  # in place of the progress bar: what is sent, where the robot is
        teleop.show_status(run.sim.base_pose2d)
        stack.callback(lambda: print(file=sys.stderr))  # the status line ends when the drive does
    return lambda: False


def run_mapping(
    *,
    world: str = "room",
    robot: str = "mybot",
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    out: str | Path = "map",
    driver: str = "explore",
    route: str | Path | None = None,
    duration: float = 600.0,
    mode: str = "gmapping",
    seed: int = 0,
    rate: float = 0.0,
    record: str | Path | None = None,
    quiet: bool = False,
    slam_params: dict[str, Any] | None = None,
    sim_params: dict[str, Any] | None = None,
    on_start: Any = None,
) -> MappingResult:
    """Map ``world`` with SLAM while ``driver`` (explore | teleop | route) drives; save ``out``/map.yaml.

    Stops when exploration finds no reachable frontier, the route ends, or ``duration`` simulated
    seconds pass (teleop: Ctrl-C or the duration). ``sim_params`` go to the ``gazebo`` node (e.g.
    ``odometry_noise``); ``slam_params`` to ``slam_gmapping``.
    """
    if driver not in DRIVERS:
        raise MappingError(f"driver must be one of {', '.join(DRIVERS)}, got {driver!r}")
    overrides = {"slam_gmapping": {"mode": mode, **(slam_params or {})}}
    if sim_params:
        overrides["gazebo"] = dict(sim_params)
    run = start_run(
        "mapping",
        world=world,
        robot=robot,
        pose=pose,
        seed=seed,
        rate=1.0 if driver == "teleop" and rate == 0 else rate,
        overrides=overrides,
        explore=str(driver == "explore").lower(),
        on_start=on_start,
    )
    with contextlib.ExitStack() as stack:  # the terminal comes back as soon as the drive ends
        is_done = _add_driver(run, driver, route, stack, quiet)
        monitor = run.add(PoseMonitor, parameters={"base_frame": run.base_frame, "odom_frame": run.odom_frame})
        no_bar = quiet or driver == "teleop"  # teleop's status line shows the time
        run.run(duration, until=is_done, record=record, quiet=no_bar, desc=f"mapping {world}")
    from navlab.mapping import SlamGMapping

    slam = run.node("slam_gmapping")
    assert isinstance(slam, SlamGMapping)  # the shipped launch's slam_gmapping
    grid = slam.current_map()
    if grid is None:
        if run.executor.stopped:  # Ctrl-C (or a stop) before the first scan was processed
            raise MappingError(f"stopped after {run.timing['sim_s']:.1f} simulated s, before SLAM made a map")
        raise MappingError("SLAM produced no map: did the robot receive scans? (check the robot's lidar)")
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    map_yaml = out_dir / "map.yaml"
    with interrupt_note(f"while saving the map: {map_yaml} is the old map or the new one, whole"):  # temp + rename
        save_map(grid, map_yaml)  # first: the map is the result; its scores and picture follow
    result = MappingResult(map_yaml, grid, run.timing["sim_s"], bool(is_done()), cpu_s=run.timing["cpu_s"])
    with interrupt_note(f"the map is saved: {map_yaml} (+ its image); trajectory.txt and map.png may be missing"):
        result.scores = _score_and_plot(run, slam, grid, pose, world, mode, monitor, out_dir, finished=result.finished)
    return result


def _score_and_plot(
    run: Run,
    slam: Any,
    grid: GridMap,
    pose: tuple[float, float, float],
    world: str,
    mode: str,
    monitor: PoseMonitor,
    out_dir: Path,
    *,
    finished: bool,
) -> dict[str, Any]:
    """The saved map's scores against the world's truth; writes trajectory.txt and map.png into ``out_dir``."""
    truth = true_occupancy(run.sim.world, grid)
    map_in_world = world_T_map(run.sim.robot, pose)
    scores: dict[str, Any] = {
        **run.figures(),
        "finished": finished,
        "scans_processed": slam.scans_processed,
        "scans_invalid": slam.scans_invalid,
        "map_empty": not bool(np.any(grid.data >= 65)),
        "map_frame_in_world": list(map_in_world),
        **score_map(grid, truth, world_T_map=map_in_world, start_xy=pose[:2]),
        "coverage": free_coverage(grid, truth, world_T_map=map_in_world, start_xy=pose[:2]),
    }
    s = monitor.samples()
    if len(s["t"]):
        # the estimate is in the map frame; bring the truth into it
        tru = s["truth"]
        tru_map = np.column_stack(
            [inverse_transform_points2(map_in_world, tru[:, :2]), wrap_angle(tru[:, 2] - map_in_world[2])]
        )
        est = s["estimate"]
        scores.update(trajectory_error(est, tru_map))
        odom_err = trajectory_error(s["odometry"], tru_map)  # raw odometry is in the odom frame = the map frame
        scores["odometry_position_error_mean_m"] = odom_err["position_error_mean_m"]
        scores["odometry_yaw_error_mean_deg"] = odom_err["yaw_error_mean_deg"]
        write_trajectory(out_dir / "trajectory.txt", s["t"], est, tru_map)
        title = (
            f"{mode} map of {Path(str(world)).stem} after {float(s['t'][-1]):.0f} simulated s "
            f"(SLAM error {scores['position_error_mean_m']:.3f} m mean)"
        )
        marks = [
            Marks(tru_map[:1, :2], "start", "black", "o", 40.0),
            Marks(tru_map[-1:, :2], "end", "black", "s", 40.0),
        ]
        plot_run(
            grid,
            [Track(tru_map, "ground truth", "g-", width=1.5), Track(est, "SLAM estimate", "b--")],
            out_dir / "map.png",
            title=title,
            marks=marks,
        )
    if scores["map_empty"]:
        scores["finished"] = False  # nothing was mapped, whatever the driver says
        scores["warning"] = (
            f"the map is empty: no obstacle was seen ({slam.scans_invalid} of {slam.scans_received} "
            "scans had no reading within the lidar's range)"
        )
        logging.getLogger("navlab.mapping").warning(scores["warning"])
    return rounded(scores)


def write_trajectory(path: Path, t: np.ndarray, est: np.ndarray, truth: np.ndarray) -> None:
    """The SLAM trajectory beside the true one, one line per sample (read by ``navlab eval map``)."""
    from navlab.io import write_text_atomic

    ok = np.isfinite(est).all(axis=1)
    rows = np.column_stack([t, est, truth])[ok]
    lines = [TRAJECTORY_HEADER, *(" ".join(f"{v:.6f}" for v in row) for row in rows)]
    write_text_atomic(path, "\n".join(lines) + "\n")


def read_trajectory(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(estimate (N, 3), truth (N, 3)) from a file written by :func:`write_trajectory`."""
    try:
        check_regular_file(path, what="trajectory")
        rows = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as exc:
        raise MappingError(f"{path}: cannot read a trajectory ({exc}); expected lines of 7 numbers") from None
    if rows.shape[1] != 7:
        raise MappingError(f"{path}: expected 7 columns (t x y theta true_x true_y true_theta), got {rows.shape[1]}")
    return rows[:, 1:4], rows[:, 4:7]
