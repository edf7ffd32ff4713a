"""Depth cameras, 3D lidars and range cones by exact ray casting against the world's geometry (no rendering).

Pure functions over a :class:`~navlab.sim.simulation.Simulation`: each places the sensor at its link's true
pose composed with the sensor's ``<pose>``, casts its grid of rays (:mod:`navlab.sim.raycast3d` for primitives,
``mj_multiRay`` for meshes) and applies Gazebo's semantics (rays start at the near clip / ``range_min``,
gaussian noise from the given generator). Frames: the sensor frame is Gazebo's (x forward, y left, z up).
"""

from __future__ import annotations

import functools

import mujoco
import numpy as np

from navlab.description import CameraConfig, Lidar3dConfig, Origin, RangeConfig
from navlab.geometry import matrix_from_quat, qmul, qrotate, quat_from_rpy
from navlab.io import move_points
from navlab.sim.raycast3d import ALL, PINHOLE, SPHERICAL, cast_grid, pinhole_dirs, spherical_dirs
from navlab.sim.simulation import Simulation


def sensor_pose(sim: Simulation, link: str, origin: Origin) -> tuple[np.ndarray, np.ndarray]:
    """(world position (3,), rotation 3x3 whose columns are the sensor axes in world) of a sensor on ``link``
    at ``origin`` (an :class:`~navlab.description.model.Origin`)."""
    pose = sim.link_pose(link)
    xyz, rpy = origin.xyz, origin.rpy
    q = qmul(tuple(pose.quaternion), quat_from_rpy(*rpy))
    pos = np.asarray(pose.position) + np.asarray(qrotate(tuple(pose.quaternion), xyz))
    return pos, matrix_from_quat(q)


def cast(
    sim: Simulation,
    pos: np.ndarray,
    rot: np.ndarray,
    dirs: np.ndarray,
    rows: int,
    cols: int,
    mode: int,
    params: np.ndarray,
    tmin: float,
    tmax: float,
) -> np.ndarray:
    """Distances (m, rows*cols) along ``dirs`` (sensor frame) from ``pos``; inf without a hit in [tmin, tmax]."""
    m, d = sim.model, sim.data
    fast, slow = sim.ray_geoms()
    out = np.empty(rows * cols)
    cast_grid(
        pos,
        rot,
        dirs,
        rows,
        cols,
        mode,
        params,
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        tmin,
        tmax,
        out,
    )
    if slow is not None:  # meshes: MuJoCo's ray caster, from tmin on
        world = move_points(dirs, rot, (0.0, 0.0, 0.0)).astype(np.float64)
        n = len(world)
        dist = np.empty(n)
        geomid = np.empty(n, dtype=np.int32)
        mujoco.mj_multiRay(m, d, pos + 0.0, world.ravel(), slow, 1, -1, geomid, dist, None, n, tmax)
        dist[geomid < 0] = np.inf
        near = np.flatnonzero(dist < tmin)
        one = np.empty(1, dtype=np.int32)
        for i in near:
            r = mujoco.mj_ray(m, d, pos + tmin * world[i], world[i], slow, 1, -1, one)
            dist[i] = tmin + r if r >= 0 else np.inf
        dist[dist > tmax] = np.inf
        np.minimum(out, dist, out=out)
    return out


@functools.lru_cache(maxsize=16)
def _pinhole_dirs(width: int, height: int, focal: float) -> np.ndarray:
    dirs = pinhole_dirs(width, height, focal)
    dirs.flags.writeable = False
    return dirs


@functools.lru_cache(maxsize=16)
def _spherical_dirs(azimuths: tuple[float, ...], elevations: tuple[float, ...]) -> np.ndarray:
    dirs = spherical_dirs(np.array(azimuths), np.array(elevations))
    dirs.flags.writeable = False
    return dirs


def _pinhole(cfg: CameraConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ray directions, their cosine to the optical axis, grid params) of a camera (directions cached by geometry)."""
    cam = cfg.camera
    dirs = _pinhole_dirs(cam.width, cam.height, cam.focal_length)
    params = np.array([cam.focal_length, (cam.width - 1) / 2.0, (cam.height - 1) / 2.0])
    return dirs, dirs[:, 0], params


def depth_image(sim: Simulation, cfg: CameraConfig, rng: np.random.Generator | None = None) -> np.ndarray:
    """Depth (float32, height x width, m along the optical axis) as ``gazebo_ros_openni_kinect`` publishes it:
    surfaces between the clip planes, plus the ``<camera><noise>`` (m, from ``rng``), and NaN where the depth
    is not inside (``pointCloudCutoff``, ``pointCloudCutoffMax``)."""
    cam = cfg.camera
    dirs, cos, params = _pinhole(cfg)
    pos, rot = sensor_pose(sim, cfg.link, cfg.origin)
    # rays begin at the near clip plane and end at the far one (depth = t cos)
    t = cast(sim, pos, rot, dirs, cam.height, cam.width, PINHOLE, params, cam.near / 1.0, cam.far / cos.min())
    depth = t * cos
    depth[depth > cam.far] = np.inf
    depth[t * cos < cam.near] = np.inf
    if cam.noise_stddev > 0 and rng is not None:
        depth += cam.noise_mean + cam.noise_stddev * rng.standard_normal(depth.shape)
    out = depth.astype(np.float32).reshape(cam.height, cam.width)
    out[~((out > cfg.point_cloud_cutoff) & (out < cfg.point_cloud_cutoff_max))] = np.nan
    return out


def depth_points(depth: np.ndarray, cfg: CameraConfig) -> np.ndarray:
    """Points (height x width x 3, float32, optical frame: x right, y down, z forward) of a depth image, NaN where
    the depth is NaN (``FillPointCloudHelper``: x = d tan(yaw angle), y = d tan(pitch angle), z = d)."""
    h, w = depth.shape
    f = cfg.camera.focal_length
    xs = (np.arange(w, dtype=np.float32) - 0.5 * (w - 1)) / f
    ys = (np.arange(h, dtype=np.float32) - 0.5 * (h - 1)) / f
    out = np.empty((h, w, 3), dtype=np.float32)
    out[..., 0] = depth * xs[None, :]
    out[..., 1] = depth * ys[:, None]
    out[..., 2] = depth
    return out


def lidar3d_angles(cfg: Lidar3dConfig) -> tuple[np.ndarray, np.ndarray]:
    """(azimuths (samples,), ring elevations (rings,)) in rad, Gazebo's spacing (both ends inclusive)."""
    az = np.linspace(cfg.min_angle, cfg.max_angle, cfg.samples) if cfg.samples > 1 else np.array([cfg.min_angle])
    el = (
        np.linspace(cfg.vertical_min_angle, cfg.vertical_max_angle, cfg.rings)
        if cfg.rings > 1
        else np.array([cfg.vertical_min_angle])
    )
    return az, el


def lidar3d_ranges(sim: Simulation, cfg: Lidar3dConfig, rng: np.random.Generator | None = None) -> np.ndarray:
    """Ranges (rings x samples, m) of a 3D lidar: the sensor's ray hits from ``range_min`` with noise added
    (``rng``); misses are ``range_max``, as Gazebo's ray sensor reports them."""
    az, el = lidar3d_angles(cfg)
    dirs = _spherical_dirs(tuple(az.tolist()), tuple(el.tolist()))
    d_az = (az[-1] - az[0]) / (len(az) - 1) if len(az) > 1 else 0.0
    d_el = (el[-1] - el[0]) / (len(el) - 1) if len(el) > 1 else 0.0
    params = np.array([az[0], d_az, el[0], d_el])
    pos, rot = sensor_pose(sim, cfg.link, cfg.origin)
    r = cast(sim, pos, rot, dirs, cfg.rings, cfg.samples, SPHERICAL, params, cfg.range_min, cfg.range_max)
    hit = np.isfinite(r)
    if cfg.noise_stddev > 0 and rng is not None:
        r[hit] += cfg.noise_stddev * rng.standard_normal(int(hit.sum()))
    r[~hit] = cfg.range_max
    return r.reshape(cfg.rings, cfg.samples)


def range_rays(cfg: RangeConfig) -> np.ndarray:
    """Unit directions of a range sensor's rays (its ``<scan>`` grid), sensor frame."""
    h = np.linspace(cfg.min_angle, cfg.max_angle, cfg.samples) if cfg.samples > 1 else np.array([cfg.min_angle])
    v = (
        np.linspace(cfg.vertical_min_angle, cfg.vertical_max_angle, cfg.vertical_samples)
        if cfg.vertical_samples > 1
        else np.array([cfg.vertical_min_angle])
    )
    return spherical_dirs(h, v)


def range_reading(sim: Simulation, cfg: RangeConfig, rng: np.random.Generator | None = None) -> float:
    """``gazebo_ros_range``'s reading (m): the nearest of the sensor's rays (``range_max`` without a hit), plus
    gaussian noise on a hit (``rng``), capped at ``range_max``."""
    dirs = range_rays(cfg)
    pos, rot = sensor_pose(sim, cfg.link, cfg.origin)
    r = float(cast(sim, pos, rot, dirs, 1, len(dirs), ALL, np.zeros(4), cfg.range_min, cfg.range_max).min())
    if not np.isfinite(r):
        return float(cfg.range_max)
    if cfg.noise_stddev > 0 and rng is not None:
        r = min(r + float(rng.normal(0.0, cfg.noise_stddev)), cfg.range_max)
    return r
