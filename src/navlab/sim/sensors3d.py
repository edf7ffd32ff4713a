"""Depth cameras, 3D lidars and range cones, exact against the world's geometry (no rendering).

Pure functions over a :class:`~navlab.sim.simulation.Simulation`: each places the sensor at its link's true
pose composed with the sensor's ``<pose>``, finds what its grid of rays hits among the primitives — a depth
camera by drawing them into a depth buffer (:mod:`navlab.sim.raster`), a 3D lidar by sweeping each shape's
block of rays (:mod:`navlab.sim.sweep`), a range cone's few rays by :mod:`navlab.sim.raycast3d` — and among
meshes by ``mj_multiRay``, then applies Gazebo's semantics (rays start at the near clip / ``range_min``,
gaussian noise drawn from a stream seeded by the given generator). Frames: the sensor frame is Gazebo's (x
forward, y left, z up).
"""

from __future__ import annotations

import functools

import mujoco
import numpy as np

from navlab.description import CameraConfig, Lidar3dConfig, Origin, RangeConfig
from navlab.geometry import matrix_from_quat, qmul, qrotate, quat_from_rpy
from navlab.io import move_points
from navlab.sim.gauss import seed_state
from navlab.sim.raster import draw_depth, finish_depth
from navlab.sim.raycast3d import ALL, cast_grid, pinhole_dirs, spherical_dirs
from navlab.sim.simulation import Simulation
from navlab.sim.sweep import finish_scan, sweep_grid


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
        np.minimum(out, _cast_meshes(sim, pos, rot, dirs, slow, tmin, tmax), out=out)
    return out


def _cast_meshes(
    sim: Simulation, pos: np.ndarray, rot: np.ndarray, dirs: np.ndarray, groups: np.ndarray, tmin: float, tmax: float
) -> np.ndarray:
    """Distances (m) along ``dirs`` (sensor frame) to the geoms of ``groups`` by ``mj_multiRay``, from ``tmin`` on;
    inf without a hit up to ``tmax``."""
    m, d = sim.model, sim.data
    world = move_points(dirs, rot, (0.0, 0.0, 0.0)).astype(np.float64)
    n = len(world)
    dist = np.empty(n)
    geomid = np.empty(n, dtype=np.int32)
    mujoco.mj_multiRay(m, d, pos + 0.0, world.ravel(), groups, 1, -1, geomid, dist, None, n, tmax)
    dist[geomid < 0] = np.inf
    near = np.flatnonzero(dist < tmin)
    one = np.empty(1, dtype=np.int32)
    for i in near:
        r = mujoco.mj_ray(m, d, pos + tmin * world[i], world[i], groups, 1, -1, one)
        dist[i] = tmin + r if r >= 0 else np.inf
    dist[dist > tmax] = np.inf
    return dist


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


@functools.lru_cache(maxsize=16)
def _pinhole_norm(width: int, height: int, focal: float) -> np.ndarray:
    """Length (height x width) of each pixel's ray (1, -(u - u0)/f, -(v - v0)/f): 1 / cos(angle to the axis)."""
    norm = 1.0 / _pinhole_dirs(width, height, focal)[:, 0].reshape(height, width)
    norm.flags.writeable = False
    return norm


def depth_image(
    sim: Simulation,
    cfg: CameraConfig,
    rng: np.random.Generator | None = None,
    *,
    scratch: np.ndarray | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Depth (float32, height x width, m along the optical axis) as ``gazebo_ros_openni_kinect`` publishes it:
    surfaces between the clip planes, plus the ``<camera><noise>`` (m, drawn from a stream seeded by ``rng``), and
    NaN where the depth is not inside (``pointCloudCutoff``, ``pointCloudCutoffMax``). Primitive shapes are drawn
    into a depth buffer (:mod:`navlab.sim.raster`); meshes are ray cast. ``scratch``: a float64 height x width
    array to draw into, ``out``: a float32 one for the image (kept by a caller that draws every frame); else they
    are made."""
    cam = cfg.camera
    norm = _pinhole_norm(cam.width, cam.height, cam.focal_length)
    pos, rot = sensor_pose(sim, cfg.link, cfg.origin)
    tmax = cam.far * float(norm.max())  # the longest ray that can end before the far clip
    m, d = sim.model, sim.data
    fast, slow = sim.ray_geoms()
    shape = (cam.height, cam.width)
    fits = scratch is not None and scratch.shape == shape and scratch.dtype == np.float64
    depth = scratch if fits and scratch is not None else np.empty(shape)
    params = np.array([cam.focal_length, (cam.width - 1) / 2.0, (cam.height - 1) / 2.0])
    draw_depth(pos, rot, params, norm, fast, m.geom_type, m.geom_size, d.geom_xpos, d.geom_xmat, cam.near, tmax, depth)
    if slow is not None:  # meshes: rays along the unit directions, their distances turned into depths
        dirs = _pinhole_dirs(cam.width, cam.height, cam.focal_length)
        t = _cast_meshes(sim, pos, rot, dirs, slow, cam.near, tmax).reshape(depth.shape)
        np.minimum(depth, t / norm, out=depth)
    noisy = cam.noise_stddev > 0 and rng is not None
    seed = seed_state(rng) if noisy and rng is not None else np.uint64(0)
    if out is None or out.shape != shape or out.dtype != np.float32:
        out = np.empty(shape, dtype=np.float32)
    std = cam.noise_stddev if noisy else 0.0
    finish_depth(
        depth, cam.near, cam.far, cam.noise_mean, std, seed, cfg.point_cloud_cutoff, cfg.point_cloud_cutoff_max, out
    )
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


@functools.lru_cache(maxsize=16)
def _trig(angles: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    a = np.array(angles)
    c, s = np.cos(a), np.sin(a)
    c.flags.writeable = s.flags.writeable = False
    return c, s


def lidar3d_ranges(sim: Simulation, cfg: Lidar3dConfig, rng: np.random.Generator | None = None) -> np.ndarray:
    """Ranges (rings x samples, m) of a 3D lidar: the sensor's ray hits from ``range_min`` with noise added
    (drawn from a stream seeded by ``rng``); misses are ``range_max``, as Gazebo's ray sensor reports them.
    Primitive shapes are swept block by block (:mod:`navlab.sim.sweep`); meshes are ray cast."""
    az, el = lidar3d_angles(cfg)
    cos_az, sin_az = _trig(tuple(az.tolist()))
    cos_el, sin_el = _trig(tuple(el.tolist()))
    pos, rot = sensor_pose(sim, cfg.link, cfg.origin)
    m, d = sim.model, sim.data
    fast, slow = sim.ray_geoms()
    r = np.empty((cfg.rings, cfg.samples))
    sweep_grid(
        pos,
        rot,
        cos_az,
        sin_az,
        cos_el,
        sin_el,
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        cfg.range_min,
        cfg.range_max,
        r,
    )
    if slow is not None:
        dirs = _spherical_dirs(tuple(az.tolist()), tuple(el.tolist()))
        t = _cast_meshes(sim, pos, rot, dirs, slow, cfg.range_min, cfg.range_max)
        np.minimum(r, t.reshape(r.shape), out=r)
    noisy = cfg.noise_stddev > 0 and rng is not None
    seed = seed_state(rng) if noisy and rng is not None else np.uint64(0)
    finish_scan(r, cfg.noise_stddev if noisy else 0.0, seed, cfg.range_max)
    return r


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
