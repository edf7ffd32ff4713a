"""A localization run: simulator + map_server + amcl + a scripted route, scored against ground truth.

Without a map file the world's true occupancy is saved to a temporary map_server map and served.

``run_localization`` is what ``navlab localize`` does; tests and the example call it directly. The
map frame is taken to coincide with the world frame (true for the world's true map, and for a SLAM
map made by a robot spawned at the world origin), so the estimate is compared with the true pose.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from scipy import ndimage

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.core.runner import run_for
from navlab.grid import GridMap
from navlab.localization.amcl_node import Amcl
from navlab.localization.errors import LocalizationError
from navlab.localization.field import field_from_map

# A 17.5 m loop through room.world / room_obstacles.world, at least 0.5 m from every obstacle.
DEFAULT_ROUTE: tuple[tuple[float, float], ...] = (
    (3.0, 0.0), (3.0, -0.6), (-0.6, -0.6), (-0.6, -0.1), (-2.6, -0.1), (-2.6, 0.5), (-0.6, 0.5),
    (0.3, 1.4), (0.3, 0.2),
)
CONVERGED_M = 0.10  # position error (m) that counts as localized


def true_map(world: Any, start_xy: tuple[float, float], resolution: float = 0.05) -> GridMap:
    """The world's true occupancy as a map: obstacles 100, free space reachable from ``start_xy`` 0,
    everything else (outside the walls) unknown (-1). World frame = map frame."""
    from navlab.world import occupancy, shape_footprints

    pts = np.vstack([fp.points for fp in shape_footprints(world)])
    lo, hi = pts.min(0) - 0.5, pts.max(0) + 0.5
    occ = occupancy(world, resolution, (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])))
    labels, _ = ndimage.label(~occ)
    i = int((start_xy[0] - lo[0]) / resolution)
    j = int((start_xy[1] - lo[1]) / resolution)
    data = np.full(occ.shape, -1, dtype=np.int8)
    data[occ] = 100
    if 0 <= j < occ.shape[0] and 0 <= i < occ.shape[1] and labels[j, i] > 0:
        data[labels == labels[j, i]] = 0
    else:
        data[~occ] = 0
    return GridMap(data, resolution, (float(lo[0]), float(lo[1]), 0.0))


class GroundTruthRoute(Node):
    """Drives waypoints (world frame) in a loop, steering on ``/ground_truth/odom`` (m, rad; 10 Hz)."""

    def __init__(self, executor: Executor, waypoints: Sequence[tuple[float, float]], *, max_v: float = 0.3,
                 name: str = "route") -> None:
        super().__init__(name, executor)
        self.waypoints = [tuple(map(float, w)) for w in waypoints]
        self.index = 0
        self.max_v = max_v
        self.pose: tuple[float, float, float] | None = None
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self._on_truth, 10)
        self.create_timer(0.1, self._tick)

    def _on_truth(self, msg: Any) -> None:
        self.pose = msgs.pose2d(msg.pose.pose)

    def _tick(self) -> None:
        if self.pose is None:
            return
        x, y, yaw = self.pose
        tx, ty = self.waypoints[self.index]
        if math.hypot(tx - x, ty - y) < 0.1:
            self.index = (self.index + 1) % len(self.waypoints)
            tx, ty = self.waypoints[self.index]
        err = math.remainder(math.atan2(ty - y, tx - x) - yaw, 2 * math.pi)
        w = max(-1.0, min(1.0, 2.0 * err))
        v = self.max_v * max(0.0, 1.0 - abs(err) / 0.5)
        self.pub.publish(msgs.twist(v, w))


def teleport(sim: Any, x: float, y: float, yaw: float) -> None:
    """Move the robot's root body to (x, y, yaw) in the world and stop it (the 'kidnapping')."""
    m, d = sim.model, sim.data
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{sim.robot.name}::root")
    if jid < 0:
        raise LocalizationError(f"robot {sim.robot.name!r} has no free root joint to teleport")
    q, v = int(m.jnt_qposadr[jid]), int(m.jnt_dofadr[jid])
    d.qpos[q:q + 2] = (x, y)
    d.qpos[q + 3:q + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    d.qvel[v:v + 6] = 0.0
    mujoco.mj_forward(m, d)


@dataclass
class LocalizeResult:
    """Samples every 0.1 s: time (s), true pose and AMCL pose (world/map frame; NaN until AMCL has one)."""

    t: np.ndarray
    truth: np.ndarray
    estimate: np.ndarray
    grid: GridMap
    summary: dict[str, Any] = field(default_factory=dict)

    @property
    def error(self) -> np.ndarray:
        """Position error (m) per sample (NaN before the first estimate)."""
        return np.hypot(*(self.estimate[:, :2] - self.truth[:, :2]).T)

    @property
    def yaw_error(self) -> np.ndarray:
        """|yaw error| (rad) per sample."""
        return np.abs(np.remainder(self.estimate[:, 2] - self.truth[:, 2] + math.pi, 2 * math.pi) - math.pi)


def _settled_after(t: np.ndarray, err: np.ndarray, t0: float) -> float | None:
    """First time >= t0 from which the error stays <= CONVERGED_M to the end (None if never)."""
    sel = t >= t0
    tt, ee = t[sel], err[sel]
    bad = np.flatnonzero(~(ee <= CONVERGED_M))
    if bad.size == 0:
        return float(tt[0]) if tt.size else None
    k = bad[-1] + 1
    return float(tt[k]) if k < tt.size else None


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
    route: Sequence[tuple[float, float]] = DEFAULT_ROUTE,
    progress: bool = False,
    record: str | Path | None = None,
) -> LocalizeResult:
    """Run the robot along ``route`` for ``duration`` simulated seconds with AMCL; see ``LocalizeResult``.

    ``initial``: AMCL's initial pose (default: the spawn pose (0, 0, 0)); ``global_localization``:
    start from particles spread over the whole map instead. ``kidnap_at``: at that time (s) the robot
    is teleported to the route waypoint farthest from it and continues the route from there.
    ``record``: also write every topic to a rosbag2 (MCAP) in that folder.
    """
    from navlab.sim.gazebo import launch_sim, load_world_named

    if duration <= 0:
        raise LocalizationError(f"duration must be > 0 s, got {duration}")
    if initial is not None and not all(math.isfinite(v) for v in initial):
        raise LocalizationError(f"initial pose {initial} is not finite")
    from navlab.mapping.map_server import MapServer
    from navlab.mapping.mapfile import load_map, save_map

    world_model = load_world_named(world)
    tmp = None
    if map_yaml is not None:
        served = Path(map_yaml)
        grid = load_map(served)
    else:  # serve the world's true map through a map file, as map_server would
        tmp = tempfile.TemporaryDirectory(prefix="navlab-localize-")
        served = Path(tmp.name) / "true_map.yaml"
        grid = true_map(world_model, (0.0, 0.0))
        save_map(grid, served)
    name = str(map_yaml or f"true map of {world}")
    fld = field_from_map(grid, name=name)  # refuse a bad map before running
    if initial is not None and not fld.contains(initial[0], initial[1]):
        x0, y0 = grid.origin[0], grid.origin[1]
        raise LocalizationError(
            f"initial pose ({initial[0]}, {initial[1]}) lies outside the map {name} "
            f"(x {x0:.2f}..{x0 + grid.data.shape[1] * grid.resolution:.2f}, "
            f"y {y0:.2f}..{y0 + grid.data.shape[0] * grid.resolution:.2f})")
    ex = Executor(seed=seed)
    gz = launch_sim(ex, world=world_model, robot=robot, seed=seed)
    sim = gz.sim
    dd = sim.robot.diff_drive
    base = dd.robot_base_frame if dd else sim.robot.root_link
    odom_frame = dd.odometry_frame if dd else "odom"
    scan_topic = sim.robot.lidars[0].topic if sim.robot.lidars else "scan"
    init = initial if initial is not None else (0.0, 0.0, 0.0)
    params = {"base_frame_id": base, "odom_frame_id": odom_frame, "initial_pose_x": init[0],
              "initial_pose_y": init[1], "initial_pose_a": init[2], **(amcl_params or {})}
    with ex.node_context(remappings={"scan": scan_topic}):
        amcl = Amcl(ex, parameters=params)
    if global_localization:
        ex.call_service("/global_localization")
    MapServer(ex, parameters={"yaml_filename": str(served)})
    driver = GroundTruthRoute(ex, route)
    rows: list[tuple[float, ...]] = []
    kidnap: dict[str, Any] = {}

    def sample() -> None:
        truth = sim.base_pose2d(base)
        try:
            est = ex.tf.lookup_pose2d(amcl.global_frame, base) if amcl.estimate is not None else (math.nan,) * 3
        except TfError:
            est = (math.nan,) * 3
        rows.append((ex.now_ns / 1e9, *truth, *est))
        if kidnap_at is not None and not kidnap and ex.now_ns / 1e9 >= kidnap_at:
            far = max(range(len(route)), key=lambda k: math.dist(route[k], truth[:2]))
            nxt = route[(far + 1) % len(route)]
            yaw = math.atan2(nxt[1] - route[far][1], nxt[0] - route[far][0])
            teleport(sim, route[far][0], route[far][1], yaw)
            driver.index = (far + 1) % len(route)
            kidnap.update(t=ex.now_ns / 1e9, distance=math.dist(route[far], truth[:2]))

    sampler = Node("localize_sampler", ex)
    sampler.create_timer(0.1, sample)
    wall0 = time.perf_counter()
    run_for(ex, duration, record=record, quiet=not progress, chunk=1.0, desc="localize")
    wall = time.perf_counter() - wall0
    if tmp is not None:
        tmp.cleanup()
    a = np.array(rows, dtype=np.float64).reshape(-1, 7)
    res = LocalizeResult(t=a[:, 0], truth=a[:, 1:4], estimate=a[:, 4:7], grid=grid)
    res.summary = _summarize(res, amcl, kidnap, wall, duration, world, map_yaml, global_localization)
    return res


def _summarize(res: LocalizeResult, amcl: Amcl, kidnap: dict[str, Any], wall: float, duration: float,
               world: str, map_yaml: Any, global_mode: bool) -> dict[str, Any]:
    err, yerr, t = res.error, res.yaw_error, res.t
    before = t < kidnap["t"] if kidnap else np.ones(t.shape, bool)
    ok = before & np.isfinite(err)
    if global_mode:
        settled = _settled_after(t[before], err[before], 0.0)
        ok &= t >= (settled if settled is not None else math.inf)
    f = amcl.filter

    def r(x: float) -> float | None:
        return None if not math.isfinite(x) else round(float(x), 4)

    out: dict[str, Any] = {
        "world": world,
        "map": str(map_yaml) if map_yaml else "true",
        "mode": "global" if global_mode else "tracking",
        "duration_s": duration,
        "samples": int(t.size),
        "updates": f.n_updates if f else 0,
        "particles_final": f.n_particles if f else 0,
        "mean_error_m": r(err[ok].mean()) if ok.any() else None,
        "max_error_m": r(err[ok].max()) if ok.any() else None,
        "mean_yaw_error_deg": r(math.degrees(yerr[ok].mean())) if ok.any() else None,
        "final_error_m": r(err[-1]) if t.size else None,
        "wall_s": round(wall, 2),
        "realtime_factor": round(duration / wall, 1) if wall > 0 else None,
    }
    if global_mode:
        out["converged_s"] = _settled_after(t[before], err[before], 0.0)
    if kidnap:
        out["kidnap_s"] = round(kidnap["t"], 2)
        out["kidnap_distance_m"] = round(kidnap["distance"], 3)
        rec = _settled_after(t, err, kidnap["t"] + 0.05)
        out["recovered_after_s"] = None if rec is None else round(rec - kidnap["t"], 2)
    return out


def plot_result(res: LocalizeResult, path: str | Path) -> Path:
    """Save a PNG: map with true and estimated paths, and position error over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io.files import save_figure_atomic

    g = res.grid
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1.3, 1]})
    img = np.where(g.data < 0, 0.75, 1.0 - np.clip(g.data, 0, 100) / 100.0)
    x0, y0 = g.origin[0], g.origin[1]
    ax.imshow(img, cmap="gray", vmin=0, vmax=1, origin="lower",
              extent=(x0, x0 + g.data.shape[1] * g.resolution, y0, y0 + g.data.shape[0] * g.resolution))
    truth, est = res.truth.copy(), res.estimate.copy()
    if "kidnap_s" in res.summary:  # do not draw the teleport as a path
        k = int(np.searchsorted(res.t, res.summary["kidnap_s"]))
        truth = np.insert(truth, k, np.nan, axis=0)
        est = np.insert(est, k, np.nan, axis=0)
    ax.plot(truth[:, 0], truth[:, 1], "-", color="tab:green", lw=2, label="ground truth")
    ax.plot(est[:, 0], est[:, 1], "--", color="tab:red", lw=1.2, label="AMCL estimate")
    known = g.known_bounds()
    if known is not None:  # crop to the mapped part (SLAM maps are allocated much larger)
        ax.set_xlim(known[0], known[2])
        ax.set_ylim(known[1], known[3])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"{res.summary.get('world', '')}: {res.summary.get('mode', '')}")
    ax2.plot(res.t, res.error * 100, color="tab:red")
    ax2.axhline(CONVERGED_M * 100, color="gray", ls=":", lw=1)
    if "kidnap_s" in res.summary:
        ax2.axvline(res.summary["kidnap_s"], color="black", ls="--", lw=1, label="kidnapped")
        ax2.legend(fontsize=8)
    ax2.set_yscale("log")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("position error (cm)")
    ax2.set_title(f"mean {res.summary.get('mean_error_m')} m")
    fig.tight_layout()
    out = Path(path)
    try:
        save_figure_atomic(fig, out, format="png", dpi=110)
    finally:
        plt.close(fig)
    return out
