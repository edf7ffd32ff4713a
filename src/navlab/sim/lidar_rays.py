"""A planar lidar's beams and rays in a MuJoCo scene: beam angles and directions (laser frame), which geoms
the rays test (the fast primitive caster's and ``mj_multiRay``'s), and the primitive casts themselves.

Split from :mod:`navlab.sim.simulation`, whose ``Simulation.scan``/``true_ranges`` call these (and which
re-exports ``lidar_angles``). Units: m, rad; frames: the laser's (its site) and the world's.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from navlab.description import LidarConfig
from navlab.sim.builder import GROUP_WORLD, RAY_GEOMGROUP
from navlab.sim.errors import SimError
from navlab.sim.raycast import FAST_TYPES, cast_planar, scan_planar


def lidar_angles(cfg: LidarConfig) -> np.ndarray:
    """Beam angles (rad, laser frame) as Gazebo spaces them: ``samples`` from min to max inclusive."""
    if cfg.samples < 1:
        raise SimError(f"lidar {cfg.name!r}: samples must be >= 1, got {cfg.samples}")
    if cfg.samples == 1:
        return np.array([cfg.min_angle])
    return np.linspace(cfg.min_angle, cfg.max_angle, cfg.samples)


def beam_dirs(cfg: LidarConfig) -> np.ndarray:
    """(2, n) cos, sin of the lidar's beam angles in its frame (C-contiguous)."""
    a = lidar_angles(cfg)
    return np.ascontiguousarray(np.stack([np.cos(a), np.sin(a)]))


def ray_geom_sets(m: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray | None]:
    """(int32 ids of the world's primitive geoms the fast casters test, a 6-entry geom-group mask of the
    rest for ``mj_multiRay`` or None): what every ray sensor sees (the robot's own geoms are not seen)."""
    in_rays = RAY_GEOMGROUP[np.clip(m.geom_group, 0, 5)].astype(bool) & (m.geom_group < 6)
    fast = in_rays & np.isin(m.geom_type, FAST_TYPES) & (m.geom_group == GROUP_WORLD)
    slow = np.unique(m.geom_group[in_rays & ~fast])
    slow_groups = None
    if len(slow):
        slow_groups = np.zeros(6, dtype=np.uint8)
        slow_groups[slow] = 1
    return np.flatnonzero(fast).astype(np.int32), slow_groups


def _increment(cfg: LidarConfig, n: int) -> float:
    """The angle (rad) between neighbouring beams of ``n``."""
    return (cfg.max_angle - cfg.min_angle) / (n - 1) if n > 1 else 0.0


def cast_primitives(
    m: mujoco.MjModel,
    d: mujoco.MjData,
    pnt: np.ndarray,
    rot: np.ndarray,
    angles: np.ndarray,
    cfg: LidarConfig,
    fast: np.ndarray,
) -> np.ndarray:
    """Noise-free ranges (m, float64) from ``pnt`` (world) with the laser's rotation ``rot`` (3x3) along
    ``angles`` (``beam_dirs``) against the primitive geoms ``fast``; no hit is ``inf``."""
    n = angles.shape[1]
    dist = np.empty(n)
    cast_planar(
        pnt,
        rot,
        angles[0],
        angles[1],
        cfg.min_angle,
        _increment(cfg, n),
        fast,
        m.geom_type,
        m.geom_size,
        d.geom_xpos,
        d.geom_xmat,
        cfg.range_min,
        cfg.range_max,
        dist,
    )
    return dist


def scan_args(
    m: mujoco.MjModel, d: mujoco.MjData, site: int, angles: np.ndarray, cfg: LidarConfig, fast: np.ndarray
) -> tuple[Any, ...]:
    """:func:`scan_planar`'s leading arguments for the laser's ``site`` (views of ``d``'s arrays, which MuJoCo
    updates in place: valid for every scan while ``m`` and ``d`` are the simulation's)."""
    n = angles.shape[1]
    return (
        d.site_xpos[site], d.site_xmat[site].reshape(3, 3), angles[0], angles[1], cfg.min_angle, _increment(cfg, n),
        fast, m.geom_type, m.geom_size, d.geom_xpos, d.geom_xmat, cfg.range_min, cfg.range_max,
    )  # fmt: skip


def scan_with(args: tuple[Any, ...], cfg: LidarConfig, normals: np.ndarray) -> np.ndarray:
    """One scan (m, float32) from :func:`scan_args`: the cast and Gazebo's noise (``normals``, standard normal
    draws, or empty without noise) in one compiled call."""
    out = np.empty(args[2].shape[0], dtype=np.float32)
    # mypy takes the unpacked tuple for too many arguments to numba's Dispatcher
    scan_planar(*args, normals, cfg.noise_mean, cfg.noise_stddev, out)  # type: ignore[call-arg]
    return out


def scan_primitives(
    m: mujoco.MjModel,
    d: mujoco.MjData,
    site: int,
    angles: np.ndarray,
    cfg: LidarConfig,
    fast: np.ndarray,
    normals: np.ndarray,
) -> np.ndarray:
    """One scan (m, float32) from the laser's ``site`` against the primitive geoms ``fast``: the cast and
    Gazebo's noise (``normals``, standard normal draws, or empty without noise) in one compiled call."""
    return scan_with(scan_args(m, d, site, angles, cfg, fast), cfg, normals)
