"""Sparse laser logs recorded in the simulator, with noisy wheel odometry: test data for global consistency.

``record_log`` drives the robot kinematically along a route (straight legs at ``speed``, turns in place
at ``turn_rate`` at the waypoints), places it in the MuJoCo world at every pose where it has moved
``linear_step`` m or turned ``angular_step`` rad since the last scan (slam_gmapping's ``linearUpdate`` /
``angularUpdate``: 1 m / 0.5 rad by default, as sparse as real logs taken seconds apart), and takes the
lidar's scan there (the sim's ray caster and its Gaussian noise), keeping the front ``fov`` rad of beams
with every ``beam_stride``-th beam. Odometry is integrated from the true steps with
:class:`OdometryNoise` (systematic scale errors, heading drift, random per-step noise; seeded).
``office_log`` does this on the generated office floor (:mod:`navlab.world.office`) along its route.

Poses (x, y, yaw) m, rad; the odometry frame (and so the SLAM map frame) is the robot's true start pose,
as in ``navlab map``: ``SimLog.start`` is its pose in the world. Result: a ``CarmenLog``
(``navlab.io.carmen.write_carmen`` writes it) and the truth.
"""

from __future__ import annotations

import itertools
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from navlab.geometry import between2, compose2, wrap_angle
from navlab.io import CarmenLog, LaserScan2D, OdomRecord
from navlab.mapping.errors import MappingError


@dataclass(frozen=True)
class OdometryNoise:
    """Wheel-odometry errors: per run, a translation and a rotation scale error (std ``scale``) and a
    heading drift rate (std ``heading_drift`` rad per m); per step, noise of std ``scale`` x the step's
    translation (along and across) and rotation, plus a heading random walk of ``heading_walk`` rad/sqrt(m)."""

    scale: float = 0.05
    heading_drift: float = 0.02
    heading_walk: float = 0.01


def route_poses(
    waypoints: np.ndarray,
    *,
    linear_step: float = 1.0,
    angular_step: float = 0.5,
    speed: float = 0.35,
    turn_rate: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    """(times (N,) s from 0, poses (N, 3)) of the scans taken along ``waypoints`` (M, 2): the robot faces
    its first leg at the start, drives the legs straight and turns in place (the shorter way) between
    them; a scan is taken at the start and whenever it moved ``linear_step`` m or turned ``angular_step``
    rad since the last one, and at the end."""
    w = np.asarray(waypoints, dtype=np.float64).reshape(-1, 2)
    if len(w) < 2:
        raise MappingError(f"a route needs at least 2 waypoints, got {len(w)}")
    heads = [math.atan2(b[1] - a[1], b[0] - a[0]) for a, b in itertools.pairwise(w)]
    x, y, th = float(w[0, 0]), float(w[0, 1]), heads[0]
    t = 0.0
    out_t, out_p = [0.0], [(x, y, th)]
    moved = turned = 0.0
    dl, da = 0.01, 0.005  # integration steps (m, rad)

    def maybe_scan() -> None:
        nonlocal moved, turned
        if moved >= linear_step - 1e-9 or turned >= angular_step - 1e-9:
            out_t.append(t)
            out_p.append((x, y, th))
            moved = turned = 0.0

    for k, (a, b) in enumerate(itertools.pairwise(w)):
        target = heads[k]
        turn = wrap_angle(target - th)
        for _ in range(int(abs(turn) / da)):
            th = wrap_angle(th + math.copysign(da, turn))
            t += da / turn_rate
            turned += da
            maybe_scan()
        th = target
        length = float(np.hypot(*(b - a)))
        n = int(length / dl)
        for i in range(1, n + 1):
            x, y = float(a[0] + (b[0] - a[0]) * i / n), float(a[1] + (b[1] - a[1]) * i / n)
            t += length / n / speed
            moved += length / n
            maybe_scan()
    if moved > 0 or turned > 0:
        out_t.append(t)
        out_p.append((x, y, th))
    return np.array(out_t), np.array(out_p)


def noisy_odometry(truth: np.ndarray, noise: OdometryNoise, rng: np.random.Generator) -> np.ndarray:
    """Odometry poses (N, 3) integrated from the steps between consecutive ``truth`` poses (N, 3), with
    ``noise``; the odometry frame starts at the first true pose (the first odometry pose is (0, 0, 0))."""
    g = np.asarray(truth, dtype=np.float64)
    s_lin = 1.0 + noise.scale * float(np.clip(rng.standard_normal(), -2, 2))
    s_rot = 1.0 + noise.scale * float(np.clip(rng.standard_normal(), -2, 2))
    drift = noise.heading_drift * float(np.clip(rng.standard_normal(), -2, 2))
    odo = [np.zeros(3)]
    for k in range(1, len(g)):
        z = between2(g[k - 1], g[k])
        d = math.hypot(z[0], z[1])
        zz = np.array(
            [
                z[0] * s_lin + rng.normal(0.0, noise.scale * d),
                z[1] * s_lin + rng.normal(0.0, noise.scale * d * 0.5),
                z[2] * s_rot
                + rng.normal(0.0, noise.scale * abs(z[2]))
                + drift * d
                + rng.normal(0.0, noise.heading_walk * math.sqrt(d)),
            ]
        )
        odo.append(compose2(odo[-1], zz))
    return np.array(odo)


@dataclass
class SimLog:
    """A recorded log (odometry-frame poses) and the truth: robot poses (N, 3) in the world per scan, and
    ``start``, the world pose of the odometry frame (the first true pose)."""

    log: CarmenLog
    truth: np.ndarray
    timestamps: np.ndarray
    start: tuple[float, float, float]
    world_file: Path | None = None


def record_log(
    world_file: str | Path,
    waypoints: np.ndarray,
    *,
    seed: int = 0,
    robot: str = "mybot",
    noise: OdometryNoise | None = None,
    linear_step: float = 1.0,
    angular_step: float = 0.5,
    fov: float = math.pi,
    beam_stride: int = 2,
    t0: float = 1000.0,
) -> SimLog:
    """Record a sparse log along ``waypoints`` in the world file (see the module docstring). ``seed`` drives
    the lidar noise and the odometry noise (``noise``, default 5 % scale errors and heading drift)."""
    from navlab.description import load_robot_named
    from navlab.sim import Simulation, lidar_angles
    from navlab.world import load_world

    rng = np.random.default_rng(seed)
    model = load_robot_named(robot)
    if not model.lidars:
        raise MappingError(f"robot {robot!r} has no lidar to record a log with")
    cfg = model.lidars[0]
    times, truth = route_poses(waypoints, linear_step=linear_step, angular_step=angular_step)
    sim = Simulation(model, load_world(world_file), seed=rng, visuals=False, robot_pose=tuple(truth[0]))
    angles = lidar_angles(cfg)
    keep = np.flatnonzero(np.abs(angles) <= fov / 2 + 1e-9)[::beam_stride]
    inc = float(angles[keep[1]] - angles[keep[0]]) if len(keep) > 1 else 0.0
    # the laser's pose in the robot frame, measured in the sim at the start pose
    sim.teleport(*truth[0])
    lp = sim.link_pose(cfg.link)
    link_pose = (float(lp.position[0]), float(lp.position[1]), lp.yaw)
    offset = compose2(between2(sim.base_pose2d(), link_pose), (cfg.origin.xyz[0], cfg.origin.xyz[1], cfg.origin.rpy[2]))
    odom = noisy_odometry(truth, noise or OdometryNoise(), rng)
    log = CarmenLog(None)
    for t, pose, od in zip(times, truth, odom, strict=True):
        sim.teleport(*pose)
        ranges = sim.scan(rng=rng)[keep]
        ranges = np.where(ranges >= cfg.range_max, np.inf, ranges).astype(np.float32)
        od_t = (float(od[0]), float(od[1]), float(od[2]))
        laser = compose2(od, offset)
        log.scans.append(
            LaserScan2D(
                float(t0 + t),
                ranges,
                float(angles[keep[0]]),
                inc,
                float(cfg.range_max),
                (float(laser[0]), float(laser[1]), float(laser[2])),
                od_t,
                kind="ROBOTLASER1",
            )
        )
        log.odometry.append(OdomRecord(float(t0 + t), od_t, 0.0, 0.0))
    start = (float(truth[0, 0]), float(truth[0, 1]), float(truth[0, 2]))
    return SimLog(log, truth, t0 + times, start, Path(world_file))


def office_log(seed: int = 0, *, noise: OdometryNoise | None = None, workdir: str | Path | None = None) -> SimLog:
    """``record_log`` on the default generated office floor along its route (``workdir``: where the
    ``.world`` file is written; default a temporary directory, removed afterwards)."""
    from navlab.world import generate_office

    office = generate_office()
    if workdir is not None:
        path = office.write_world(Path(workdir) / f"{office.name}.world")
        return record_log(path, office.route(), seed=seed, noise=noise)
    with tempfile.TemporaryDirectory(prefix="navlab-office-") as tmp:
        path = office.write_world(Path(tmp) / f"{office.name}.world")
        out = record_log(path, office.route(), seed=seed, noise=noise)
    out.world_file = None
    return out
