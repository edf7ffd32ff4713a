"""The paper's mapping step in simulation: sim + slam_gmapping + (exploration | teleop | route) → saved map.

``run_mapping`` is the Python API behind ``navlab map``; it returns the saved paths and, because a
simulated world knows its truth, the map's score against the world and the trajectory's error.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.core.runner import run_for
from navlab.geometry import inverse_transform_points2
from navlab.grid import Grid, GridMap
from navlab.mapping.errors import MappingError
from navlab.mapping.evaluation import free_coverage, score_map, trajectory_error, truth_grid
from navlab.mapping.explore_node import Explore
from navlab.mapping.mapfile import save_map
from navlab.mapping.slam_node import SlamGMapping
from navlab.mapping.teleop import HELP as TELEOP_HELP
from navlab.mapping.teleop import RouteFollower, TeleopKeyboard, load_route, terminal_keys


def mapping_slam_params() -> dict[str, Any]:
    """slam_gmapping's parameters for the paper's room: the shipped ``params/gmapping.yaml`` (ROS
    defaults, tuned for a small room driven slowly as TurtleBot3's gmapping params are)."""
    from navlab.core.launch import resources_dir
    from navlab.core.params import load_params

    return load_params(resources_dir() / "params" / "gmapping.yaml")


class TrajectoryMonitor(Node):
    """Samples the true pose (``/ground_truth/odom``), the SLAM estimate (tf map→base) and raw odometry
    (tf odom→base) at ``rate`` Hz."""

    def __init__(self, executor: Executor, *, base_frame: str, rate: float = 2.0) -> None:
        super().__init__("trajectory_monitor", executor)
        self.base_frame = base_frame
        self.truth: list[tuple[float, float, float]] = []
        self.estimate: list[tuple[float, float, float]] = []
        self.odometry: list[tuple[float, float, float]] = []
        self.times: list[float] = []
        self._latest_truth: tuple[float, float, float] | None = None
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self._on_truth, 1)
        self.create_timer(1.0 / rate, self._sample)

    def _on_truth(self, msg: Any) -> None:
        self._latest_truth = msgs.pose2d(msg.pose.pose)

    def _sample(self) -> None:
        if self._latest_truth is None:
            return
        try:
            est = self.executor.tf.lookup_pose2d("map", self.base_frame)
            odom = self.executor.tf.lookup_pose2d("odom", self.base_frame)
        except TfError:
            return
        self.times.append(self.executor.now_ns / 1e9)
        self.truth.append(self._latest_truth)
        self.estimate.append(est)
        self.odometry.append(odom)


@dataclass
class MappingResult:
    """What a mapping run produced: files, the final grid, and its scores against the world's truth."""

    map_yaml: Path
    grid: GridMap
    sim_seconds: float
    finished: bool
    scores: dict[str, Any] = field(default_factory=dict)


def true_occupancy(world: Any, grid: GridMap, margin: float = 1.0) -> Grid:
    """The world's occupancy at lidar height over the map's extent (plus ``margin`` m), in the world frame."""
    from navlab.world.occupancy import occupancy

    x0, y0, x1, y1 = grid.bounds()
    bounds = (x0 - margin, y0 - margin, x1 + margin, y1 + margin)
    occ = occupancy(world, grid.resolution, bounds, static_only=True)
    return truth_grid(occ, grid.resolution, (bounds[0], bounds[1]))


def run_mapping(
    *,
    world: str = "room",
    robot: str = "mybot",
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
) -> MappingResult:
    """Map ``world`` with SLAM while ``driver`` (explore | teleop | route) drives; save ``out``/map.yaml.

    Stops when exploration finds no reachable frontier, the route ends, or ``duration`` simulated
    seconds pass (teleop: Ctrl-C or the duration). ``sim_params`` go to the ``gazebo`` node (e.g.
    ``odometry_noise``); ``slam_params`` to ``slam_gmapping``.
    """
    from navlab.sim.gazebo import launch_sim

    if driver not in ("explore", "teleop", "route"):
        raise MappingError(f"driver must be explore, teleop or route, got {driver!r}")
    ex = Executor(seed=seed, rate=1.0 if driver == "teleop" and rate == 0 else rate)
    gazebo = launch_sim(ex, world=world, robot=robot, **(sim_params or {}))
    model = gazebo.sim.robot
    assert model is not None
    base = model.diff_drive.robot_base_frame if model.diff_drive else model.root_link
    scan_topic = model.lidars[0].topic if model.lidars else "scan"
    slam = SlamGMapping(ex, parameters={"base_frame": base, "scan_topic": scan_topic, "mode": mode,
                                        **mapping_slam_params(), **(slam_params or {})})  # fmt: skip
    monitor = TrajectoryMonitor(ex, base_frame=base)
    is_done: Any
    if driver == "explore":
        with ex.node_context(remappings={"scan": scan_topic}):
            explorer = Explore(ex, parameters={"robot_base_frame": base})
        is_done = lambda: explorer.done  # noqa: E731
    elif driver == "route":
        if route is None:
            raise MappingError("driver 'route' needs a route file (--route FILE)")
        segments, waypoints = load_route(route)
        follower = RouteFollower(ex, parameters={
            "segments": [{"linear": v, "angular": w, "duration": d} for v, w, d in segments],
            "waypoints": waypoints.tolist(), "base_frame": base,
        })  # fmt: skip
        is_done = lambda: follower.done  # noqa: E731
    else:
        teleop = TeleopKeyboard(ex)
        print("teleop_twist_keyboard:\n" + TELEOP_HELP)
        terminal_keys(teleop, ex)
        is_done = lambda: False  # noqa: E731

    def stop_when_done(*_: Any) -> None:
        if is_done():
            ex.stop()

    ex.add_listener(stop_when_done)
    wall0 = time.perf_counter()
    run_for(ex, duration, record=record, quiet=quiet, desc=f"mapping {world}")
    wall = time.perf_counter() - wall0
    if slam.grid is None:
        raise MappingError("SLAM produced no map: did the robot receive scans? (check the robot's lidar)")
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    map_yaml = out_dir / "map.yaml"
    save_map(slam.grid, map_yaml)
    result = MappingResult(map_yaml, slam.grid, ex.now_ns / 1e9, bool(is_done()))
    spawn = (float(gazebo.get_parameter("x")), float(gazebo.get_parameter("y")), float(gazebo.get_parameter("yaw")))
    truth = true_occupancy(gazebo.sim.world, slam.grid)
    result.scores = {
        "sim_seconds": round(result.sim_seconds, 2),
        "wall_seconds": round(wall, 2),
        "rtf": round(result.sim_seconds / wall, 1),
        "finished": result.finished,
        "scans_processed": slam.scans_processed,
        **score_map(slam.grid, truth, world_T_map=spawn),
        "coverage": round(free_coverage(slam.grid, truth, world_T_map=spawn), 4),
    }
    if monitor.truth:
        est = np.array(monitor.estimate)
        tru = np.array(monitor.truth)
        # the estimate is in the map frame = the spawn pose; bring the truth into it
        tru_map = np.column_stack([inverse_transform_points2(spawn, tru[:, :2]), tru[:, 2] - spawn[2]])
        result.scores.update(trajectory_error(est, tru_map))
        write_trajectory(out_dir / "trajectory.txt", np.array(monitor.times), est, tru_map)
        # raw odometry starts at the spawn pose too, so it is compared in the same frame
        odom_err = trajectory_error(np.array(monitor.odometry), tru_map)
        result.scores["odometry_position_error_mean_m"] = odom_err["position_error_mean_m"]
        result.scores["odometry_yaw_error_mean_deg"] = odom_err["yaw_error_mean_deg"]
        _plot(slam.grid, est, tru_map, out_dir / "map.png")
    return result


TRAJECTORY_HEADER = "# t x y theta true_x true_y true_theta  (s, m, rad; map frame = the robot's start pose)"


def write_trajectory(path: Path, t: np.ndarray, est: np.ndarray, truth: np.ndarray) -> None:
    """The SLAM trajectory beside the true one, one line per sample (read by ``navlab eval map``)."""
    from navlab.io.files import write_text_atomic

    rows = np.column_stack([t, est, truth])
    lines = [TRAJECTORY_HEADER, *(" ".join(f"{v:.6f}" for v in row) for row in rows)]
    write_text_atomic(path, "\n".join(lines) + "\n")


def read_trajectory(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(estimate (N, 3), truth (N, 3)) from a file written by :func:`write_trajectory`."""
    try:
        rows = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as exc:
        raise MappingError(f"{path}: cannot read a trajectory ({exc}); expected lines of 7 numbers") from None
    if rows.shape[1] != 7:
        raise MappingError(f"{path}: expected 7 columns (t x y theta true_x true_y true_theta), got {rows.shape[1]}")
    return rows[:, 1:4], rows[:, 4:7]


def _plot(grid: GridMap, est: np.ndarray, truth: np.ndarray, path: Path) -> None:
    """The map with the SLAM trajectory (blue) and the true one (green)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io.files import save_figure_atomic

    x0, y0, x1, y1 = grid.bounds()
    img = np.where(grid.data < 0, 0.8, 1.0 - grid.data / 100.0)
    fig, ax = plt.subplots(figsize=(8, 7))
    ax.imshow(img, cmap="gray", origin="lower", extent=(x0, x1, y0, y1), vmin=0, vmax=1)
    ax.plot(truth[:, 0], truth[:, 1], "g-", lw=1.5, label="ground truth")
    ax.plot(est[:, 0], est[:, 1], "b--", lw=1.2, label="SLAM estimate")
    known = grid.known_bounds()
    if known is not None:  # crop to the part of the map SLAM has seen
        ax.set_xlim(known[0], known[2])
        ax.set_ylim(known[1], known[3])
    ax.set_xlabel("x [m] (map frame)")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right")
    save_figure_atomic(fig, path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def bench(args: Any) -> dict[str, Any]:
    """``navlab bench mapping``: the whole mapping stack (sim + lidar + slam_gmapping + exploration)
    exploring room.world until done; real-time factor of the run loop (sim s / wall s)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        seed = getattr(args, "seed", 0)
        r = run_mapping(world="room", out=tmp, driver="explore", duration=300, seed=seed, quiet=True)
    keys = ("sim_seconds", "wall_seconds", "rtf", "finished", "scans_processed", "coverage", "precision", "recall")
    return {k: r.scores[k] for k in keys}
