"""The depth buffer (sim/raster.py) and the lidar sweep (sim/sweep.py) against the exact ray caster, ray by ray
(every ray against every geom), and their seeded noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.geometry import matrix_from_quat, quat_from_rpy
from navlab.sim.gauss import fill_normal, seed_state
from navlab.sim.raster import draw_depth, finish_depth
from navlab.sim.raycast import BOX, CYLINDER, PLANE, SPHERE
from navlab.sim.raycast3d import ALL, cast_grid, pinhole_dirs, spherical_dirs
from navlab.sim.sweep import finish_scan, sweep_grid

W, H, FOV, NEAR = 96, 72, 1.4, 0.05


def _scene(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(types, sizes, centres, row-major rotations) of a floor, a small finite plane and 24 tilted shapes."""
    kinds, sizes, centres, mats = [PLANE, PLANE], [(0.0, 0.0, 1.0), (0.6, 0.4, 0.1)], [(0, 0, 0), (1.5, -1, 0.8)], []
    mats += [np.eye(3), matrix_from_quat(quat_from_rpy(1.2, 0.3, 0.5))]
    for _ in range(24):
        kind = int(rng.choice([BOX, CYLINDER, SPHERE]))
        kinds.append(kind)
        sizes.append(tuple(rng.uniform(0.05, 0.6, 3)))
        centres.append((rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(0.0, 1.2)))
        mats.append(matrix_from_quat(quat_from_rpy(*rng.uniform(-math.pi, math.pi, 3))))
    return (
        np.array(kinds, dtype=np.int32),
        np.array(sizes, dtype=np.float64),
        np.array(centres, dtype=np.float64),
        np.array([m.reshape(-1) for m in mats]),
    )


def _views(pos: np.ndarray, rot: np.ndarray, scene: tuple[np.ndarray, ...], far: float) -> tuple[np.ndarray, ...]:
    kinds, sizes, centres, mats = scene
    geoms = np.arange(len(kinds), dtype=np.int32)
    f = W / (2 * math.tan(FOV / 2))
    dirs = pinhole_dirs(W, H, f)
    norm = (1.0 / dirs[:, 0]).reshape(H, W)
    every = np.empty(W * H)
    cast_grid(pos, rot, dirs, 1, W * H, ALL, np.zeros(3), geoms, kinds, sizes, centres, mats, NEAR, far, every)
    drawn = np.empty((H, W))
    cam = np.array([f, (W - 1) / 2, (H - 1) / 2])
    draw_depth(pos, rot, cam, norm, geoms, kinds, sizes, centres, mats, NEAR, far, drawn)
    ray_depth = (every * dirs[:, 0]).reshape(H, W)  # depth along the optical axis
    drawn[drawn * norm > far] = np.inf  # beyond the caster's reach
    return drawn, ray_depth


@pytest.mark.parametrize("seed", range(6))
def test_drawn_depth_equals_the_ray_cast_of_every_pixel(seed: int) -> None:
    rng = np.random.default_rng(seed)
    scene = _scene(rng)
    seen_px = 0
    for _ in range(5):  # cameras anywhere, turned anyhow, some inside shapes, some under the floor
        pos = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-0.3, 1.5)])
        rot = matrix_from_quat(quat_from_rpy(*rng.uniform(-math.pi, math.pi, 3)))
        drawn, ray = _views(pos, rot, scene, 12.0)
        seen = np.isfinite(ray)
        # the same pixels see a surface (a pixel centre may fall exactly on a shared edge: allow a handful)
        assert (seen != np.isfinite(drawn)).sum() <= 3
        both = seen & np.isfinite(drawn)
        assert np.abs(drawn[both] - ray[both]).max(initial=0.0) < 1e-9
        seen_px += int(both.sum())
    assert seen_px > W * H  # surfaces in view, not an empty comparison


@pytest.mark.parametrize(
    ("az_span", "samples", "rings"), [((-math.pi, math.pi), 360, 16), ((-1.2, 0.9), 151, 7), ((2.5, 4.0), 40, 1)]
)
def test_swept_lidar_equals_the_ray_cast_of_every_ray(az_span: tuple[float, float], samples: int, rings: int) -> None:
    rng = np.random.default_rng(samples)
    az = np.linspace(*az_span, samples)
    el = np.linspace(-0.4, 0.3, rings) if rings > 1 else np.array([0.05])
    dirs = spherical_dirs(az, el)
    hits = 0
    for _ in range(4):
        kinds, sizes, centres, mats = _scene(rng)
        geoms = np.arange(len(kinds), dtype=np.int32)
        for _ in range(6):  # level, tilted, upside down; inside shapes or not
            pos = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-0.3, 1.5)])
            rot = matrix_from_quat(quat_from_rpy(*rng.uniform(-math.pi, math.pi, 3)))
            every = np.empty(len(dirs))
            cast_grid(
                pos, rot, dirs, 1, len(dirs), ALL, np.zeros(4), geoms, kinds, sizes, centres, mats, 0.3, 9.0, every
            )
            swept = np.empty((len(el), len(az)))
            trig = np.cos(az), np.sin(az), np.cos(el), np.sin(el)
            sweep_grid(pos, rot, *trig, geoms, kinds, sizes, centres, mats, 0.3, 9.0, swept)
            every = every.reshape(swept.shape)
            assert (np.isfinite(every) != np.isfinite(swept)).sum() <= 2  # a ray exactly along an edge
            both = np.isfinite(every) & np.isfinite(swept)
            assert np.abs(every[both] - swept[both]).max(initial=0.0) < 1e-9
            hits += int(both.sum())
    assert hits > 2 * len(dirs)


def test_a_camera_inside_a_box_or_nearer_than_the_clip_sees_past_it() -> None:
    box = (np.array([BOX], np.int32), np.array([[0.5, 0.5, 0.5]]), np.zeros((1, 3)), np.eye(3).reshape(1, 9))
    inside, _ = _views(np.zeros(3), np.eye(3), box, 10.0)
    assert np.isinf(inside).all()  # no ray enters the box from inside
    face = (np.array([BOX], np.int32), np.array([[0.5, 5.0, 5.0]]), np.array([[0.53, 0, 0]]), np.eye(3).reshape(1, 9))
    close, ray = _views(np.zeros(3), np.eye(3), face, 10.0)  # the face 3 cm ahead: before the near clip
    assert np.isinf(close[H // 2, W // 2]) and np.isinf(ray[H // 2, W // 2])
    assert np.array_equal(np.isfinite(close), np.isfinite(ray))  # the oblique rays reach past 5 cm


def test_noise_is_seeded_gaussian_and_the_cutoffs_apply() -> None:
    depth = np.full((200, 500), 2.0)
    depth[0, :3] = (np.inf, 0.01, 7.0)  # no surface; nearer than the near clip; beyond the far clip
    a, b = np.empty(depth.shape, np.float32), np.empty(depth.shape, np.float32)
    finish_depth(depth, 0.05, 6.0, 0.0, 0.01, seed_state(np.random.default_rng(3)), 0.1, 5.0, a)
    finish_depth(depth, 0.05, 6.0, 0.0, 0.01, seed_state(np.random.default_rng(3)), 0.1, 5.0, b)
    np.testing.assert_array_equal(a, b)  # same seed, same image, bit for bit
    assert np.isnan(a[0, :3]).all()
    noise = (a.astype(np.float64) - 2.0)[1:]
    assert abs(noise.mean()) < 2e-4 and noise.std() == pytest.approx(0.01, rel=0.02)
    ranges = np.array([[1.0, np.inf, 2.0], [np.inf, 3.0, 4.0]])
    finish_scan(ranges, 0.0, np.uint64(0), 30.0)
    assert ranges.tolist() == [[1.0, 30.0, 2.0], [30.0, 3.0, 4.0]]  # misses at range_max, no noise: hits as they are
    draws = np.empty(400_000)
    fill_normal(seed_state(np.random.default_rng(0)), draws)
    assert abs(draws.mean()) < 0.01 and draws.std() == pytest.approx(1.0, abs=0.01)
    # the tails: P(|x| > 2) = 0.0455, P(|x| > 3.5) = 4.65e-4 (the ziggurat's tail beyond 3.44)
    assert np.mean(np.abs(draws) > 2) == pytest.approx(0.0455, abs=0.002)
    assert np.mean(np.abs(draws) > 3.5) == pytest.approx(4.65e-4, abs=1.5e-4)
