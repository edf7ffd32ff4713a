"""A localization run: the ``localization`` launch (sim + map_server + amcl) with a route follower steering on
ground truth, scored against ground truth; optionally kidnapped through the simulator's API.

Without a map file the world's true occupancy is saved to a temporary map_server map and served.
``run_localization`` is what ``navlab localize`` does. The map frame is taken to coincide with the
world frame (true for the world's true map, and for a SLAM map made by a robot spawned at the origin).
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab.core import Node
from navlab.experiments.metrics import settled_after, trajectory_error
from navlab.experiments.monitors import PoseMonitor
from navlab.experiments.plots import ErrorPanel, Marks, Track, plot_run
from navlab.experiments.session import rounded, start_run
from navlab.geometry import wrap_angle
from navlab.grid import GridMap
from navlab.localization import LocalizationError
from navlab.world import true_map, unmapped_obstacles

# A 17.5 m loop through room.world / room_obstacles.world, at least 0.5 m from every obstacle.
DEFAULT_ROUTE: tuple[tuple[float, float], ...] = (
    (3.0, 0.0),
    (3.0, -0.6),
    (-0.6, -0.6),
    (-0.6, -0.1),
    (-2.6, -0.1),
    (-2.6, 0.5),
    (-0.6, 0.5),
    (0.3, 1.4),
    (0.3, 0.2),
)
CONVERGED_M = 0.10  # position error (m) that counts as localized


@dataclass
class LocalizeResult:
    """Samples every 0.1 s: time (s), true pose and AMCL pose (world/map frame; NaN until AMCL has one)."""

    t: np.ndarray
    truth: np.ndarray
    estimate: np.ndarray
    grid: GridMap
    summary: dict[str, Any] = field(default_factory=dict)
    unmapped: np.ndarray | None = None  # (N, 2) world points of obstacles the map does not have (m)

    @property
    def error(self) -> np.ndarray:
        """Position error (m) per sample (NaN before the first estimate)."""
        return np.hypot(*(self.estimate[:, :2] - self.truth[:, :2]).T)

    @property
    def yaw_error(self) -> np.ndarray:
        """|yaw error| (rad) per sample."""
        return np.abs(wrap_angle(self.estimate[:, 2] - self.truth[:, 2]))


class Kidnapper(Node):
    """At ``at`` s, teleports the robot to the route waypoint farthest from it (through the simulator's
    API) and sends the route follower on from there."""

    def __init__(
        self,
        executor: Any,
        *,
        name: str = "kidnapper",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Any = None,
        follower: Any = None,
        route: Sequence[tuple[float, float]] = DEFAULT_ROUTE,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.at = float(self.declare_parameter("at", 20.0))
        self.sim, self.follower, self.route = sim, follower, list(route)
        self.event: dict[str, float] = {}
        self._timer = self.create_timer(0.1, self._tick)

    def _tick(self) -> None:
        if self.event or self.executor.now_ns / 1e9 < self.at - 1e-9:
            return
        x, y, _ = self.sim.base_pose2d()
        route = self.route
        far = max(range(len(route)), key=lambda k: math.dist(route[k], (x, y)))
        nxt = route[(far + 1) % len(route)]
        yaw = math.atan2(nxt[1] - route[far][1], nxt[0] - route[far][0])
        self.sim.teleport(route[far][0], route[far][1], yaw)
        self.follower.index = (far + 1) % len(route)
        self.event = {"t": self.executor.now_ns / 1e9, "distance": math.dist(route[far], (x, y))}
        self._timer.cancel()


def run_localization(
    world: str = "room_obstacles",
    map_yaml: str | Path | None = None,
    *,
    initial: tuple[float, float, float] | None = None,
    global_localization: bool = False,
    duration: float = 60.0,
    seed: int = 0,
    kidnap_at: float | None = None,
    amcl_params: dict[str, Any] | None = None,
    robot: str = "mybot",
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    route: Sequence[tuple[float, float]] = DEFAULT_ROUTE,
    progress: bool = False,
    record: str | Path | None = None,
    on_start: Any = None,
) -> LocalizeResult:
    """Run the robot along ``route`` for ``duration`` simulated seconds with AMCL; see ``LocalizeResult``.

    ``pose``: the robot's spawn pose; ``initial``: AMCL's initial pose (default: the spawn pose);
    ``global_localization``: start from particles spread over the whole map instead. ``kidnap_at``: at
    that time (s) the robot is teleported to the route waypoint farthest from it and continues the route
    from there. ``record``: also write every topic to a rosbag2 (MCAP) in that folder.
    """
    from navlab.drivers import RouteFollower
    from navlab.localization import field_from_map
    from navlab.mapping import load_map, save_map
    from navlab.world import load_world

    if duration <= 0:
        raise LocalizationError(f"duration must be > 0 s, got {duration}")
    if initial is not None and not all(math.isfinite(v) for v in initial):
        raise LocalizationError(f"initial pose {initial} is not finite")
    with tempfile.TemporaryDirectory(prefix="navlab-localize-") as tmp:
        if map_yaml is not None:
            served = Path(map_yaml)
            grid = load_map(served)
        else:  # serve the world's true map through a map file, as map_server would
            from navlab.world import shape_footprints

            served = Path(tmp) / "true_map.yaml"
            world_model = load_world(world)
            if not shape_footprints(world_model):
                raise LocalizationError(
                    f"world {world}: nothing stands at the lidar's height (an empty world); AMCL "
                    "needs walls or obstacles to localize against"
                )
            grid = true_map(world_model, (pose[0], pose[1]))
            save_map(grid, served)
        name = str(map_yaml or f"true map of {world}")
        if not np.any(grid.data >= 65):
            raise LocalizationError(
                f"map {name} has no occupied cell; AMCL needs walls or obstacles to localize against"
            )
        fld = field_from_map(grid, name=name)  # refuse a bad map before running
        init = initial if initial is not None else pose
        if not fld.contains(init[0], init[1]):
            x0, y0, x1, y1 = grid.bounds()
            raise LocalizationError(
                f"initial pose ({init[0]}, {init[1]}) lies outside the map {name} "
                f"(x {x0:.2f}..{x1:.2f}, y {y0:.2f}..{y1:.2f})"
            )
        amcl = {"initial_pose_x": init[0], "initial_pose_y": init[1], "initial_pose_a": init[2], **(amcl_params or {})}
        run = start_run(
            "localization",
            world=world,
            robot=robot,
            pose=pose,
            seed=seed,
            map=str(served),
            overrides={"amcl": amcl},
            on_start=on_start,
        )
        if global_localization:
            run.executor.call_service("/global_localization")
        follower = run.add(
            RouteFollower,
            parameters={"waypoints": [list(w) for w in route], "loop": True, "pose_topic": "/ground_truth/odom"},
        )
        monitor = run.add(
            PoseMonitor, parameters={"base_frame": run.base_frame, "odom_frame": run.odom_frame, "rate": 10.0}
        )
        kidnapper = None
        if kidnap_at is not None:
            kidnapper = run.add(Kidnapper, parameters={"at": kidnap_at}, sim=run.sim, follower=follower, route=route)
        run.run(duration, record=record, quiet=not progress, chunk=1.0, desc="localize")
    s = monitor.samples()
    res = LocalizeResult(
        t=s["t"],
        truth=s["truth"],
        estimate=s["estimate"],
        grid=grid,
        unmapped=None if map_yaml is None else unmapped_obstacles(run.sim.world, grid, pose[:2]),
    )
    from navlab.localization import AmclNode

    node = run.node("amcl")
    assert isinstance(node, AmclNode)  # the shipped launch's amcl
    res.summary = rounded(
        {
            "world": world,
            "map": str(map_yaml) if map_yaml else "true",
            "mode": "global" if global_localization else "tracking",
            **_errors(res, kidnapper.event if kidnapper else {}, global_localization),
            "updates": node.filter.n_updates if node.filter else 0,
            "scans": node.scans_received,
            "scans_invalid": node.scans_invalid,
            "particles_final": node.filter.n_particles if node.filter else 0,
            **run.figures(),
        }
    )
    return res


def _errors(res: LocalizeResult, kidnap: dict[str, float], global_mode: bool) -> dict[str, Any]:
    """Errors over the samples before any kidnap (after convergence in global mode), and the timings."""
    err, t = res.error, res.t
    before = t < kidnap["t"] if kidnap else np.ones(t.shape, bool)
    use = before & np.isfinite(err)
    out: dict[str, Any] = {"samples": int(t.size)}
    if global_mode:
        converged = settled_after(t[before], err[before], 0.0, CONVERGED_M)
        use &= t >= (converged if converged is not None else math.inf)
        out["converged_s"] = converged
    figures = trajectory_error(res.estimate[use], res.truth[use])
    out.update({k: figures[k] for k in ("position_error_mean_m", "position_error_max_m", "yaw_error_mean_deg")})
    out["position_error_final_m"] = float(err[-1]) if t.size else None
    whole = np.isfinite(err)  # the whole run, kidnap and recovery included (NaN: no estimate yet)
    out["position_error_mean_whole_run_m"] = float(err[whole].mean()) if whole.any() else None
    out["position_error_max_whole_run_m"] = float(err[whole].max()) if whole.any() else None
    out["estimate_missing_share"] = float(1.0 - whole.mean()) if t.size else None
    if kidnap:
        out["kidnap_s"] = kidnap["t"]
        out["kidnap_distance_m"] = kidnap["distance"]
        rec = settled_after(t, err, kidnap["t"] + 0.05, CONVERGED_M)
        out["recovered_after_s"] = None if rec is None else rec - kidnap["t"]
        out["recovered"] = rec is not None  # False: the estimate never came back within CONVERGED_M
    return out


def plot_result(res: LocalizeResult, path: str | Path) -> Path:
    """Save a PNG: map with true and estimated paths, and position error over time."""
    truth, est = res.truth.copy(), res.estimate.copy()
    events = {}
    if res.summary.get("kidnap_s") is not None:  # do not draw the teleport as a path
        k = int(np.searchsorted(res.t, res.summary["kidnap_s"]))
        truth, est = np.insert(truth, k, np.nan, axis=0), np.insert(est, k, np.nan, axis=0)
        events["kidnapped"] = res.summary["kidnap_s"]
    mean = res.summary.get("position_error_mean_m")
    marks = (
        []
        if res.unmapped is None or not len(res.unmapped)
        else [Marks(res.unmapped, "obstacle not in the map", "tab:purple")]
    )
    return plot_run(
        res.grid,
        [Track(truth, "ground truth", "-", "tab:green", 2.0), Track(est, "AMCL estimate", "--", "tab:red")],
        path,
        title=f"AMCL ({res.summary.get('mode', '')}) in {res.summary.get('world', '')} on map "
        f"{Path(str(res.summary.get('map', ''))).name}",
        error=ErrorPanel(
            res.t,
            res.error,
            title="position error: AMCL vs truth" + (f" (mean {100 * mean:.1f} cm)" if mean is not None else ""),
            threshold=CONVERGED_M,
            events=events,
        ),
        marks=marks,
        dpi=110,
    )
