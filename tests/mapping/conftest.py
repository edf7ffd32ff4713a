"""A synthetic 2D lidar world for SLAM tests: walls as segments, exact ray casting, noisy odometry."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from navlab.geometry import between2, compose2


class SynthWorld:
    """An 8 m x 6 m room with an inner wall and two boxes; ``scan(pose)`` ray-casts 361 beams over 180°."""

    def __init__(self) -> None:
        segs = [
            ((0, 0), (8, 0)),
            ((8, 0), (8, 6)),
            ((8, 6), (0, 6)),
            ((0, 6), (0, 0)),  # room
            ((3, 2), (5, 2)),
            ((5, 2), (5, 4)),  # an L-shaped inner wall
            ((1.2, 4.2), (1.8, 4.2)),
            ((1.8, 4.2), (1.8, 4.8)),
            ((1.8, 4.8), (1.2, 4.8)),
            ((1.2, 4.8), (1.2, 4.2)),
            ((6.3, 0.8), (7.0, 0.8)),
            ((7.0, 0.8), (7.0, 1.3)),
            ((7.0, 1.3), (6.3, 1.3)),
            ((6.3, 1.3), (6.3, 0.8)),
        ]
        self.a = np.array([s[0] for s in segs], dtype=float)
        self.b = np.array([s[1] for s in segs], dtype=float)
        self.angle_min = -math.pi / 2
        self.angle_increment = math.radians(0.5)
        self.n = 361
        self.max_range = 30.0

    def scan(self, pose: np.ndarray, rng: np.random.Generator | None = None, sigma: float = 0.01) -> np.ndarray:
        ang = pose[2] + self.angle_min + self.angle_increment * np.arange(self.n)
        d = np.stack([np.cos(ang), np.sin(ang)], 1)[:, None, :]  # (n,1,2)
        e = (self.b - self.a)[None]  # (1,m,2)
        w = (self.a - pose[:2])[None]
        den = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[..., 0] * e[..., 1] - w[..., 1] * e[..., 0]) / den
            u = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / den
        ok = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
        r = np.where(ok, t, np.inf).min(axis=1)
        r = np.where(np.isfinite(r), r, self.max_range + 10)
        if rng is not None:
            r = r + rng.normal(0, sigma, r.shape)
        return r.astype(np.float32)

    def route(self) -> np.ndarray:
        """A loop around the inner wall, twice, at ~0.1 m / 3° per scan (laser poses)."""
        way = np.array([[1.5, 1.0], [6.5, 2.3], [6.5, 5.0], [2.5, 5.0], [2.0, 2.0], [1.5, 1.0]])
        pts = []
        for _ in range(2):
            for p, q in itertools.pairwise(way):
                k = int(np.ceil(np.hypot(*(q - p)) / 0.1))
                pts += [p + (q - p) * s for s in np.arange(k) / k]
        pts = np.array(pts)
        th = np.arctan2(np.diff(pts[:, 1], append=pts[0, 1]), np.diff(pts[:, 0], append=pts[0, 0]))
        th = np.unwrap(th)
        return np.stack([pts[:, 0], pts[:, 1], th], 1)


def noisy_odometry(gt: np.ndarray, rng: np.random.Generator, trans: float = 0.05, rot: float = 0.05) -> np.ndarray:
    """Odometry integrated from the true steps with proportional noise (fraction ``trans``/``rot``) + rot drift."""

    odo = [gt[0].copy()]
    for k in range(1, len(gt)):
        z = between2(gt[k - 1], gt[k])
        dist = math.hypot(z[0], z[1])
        z = z + np.array(
            [rng.normal(0, trans * dist), rng.normal(0, trans * dist), rng.normal(0, rot * abs(z[2]) + 0.01 * dist)]
        )
        z[2] += 0.02 * dist  # systematic heading drift, rad/m
        odo.append(compose2(odo[-1], z))
    return np.array(odo)


@pytest.fixture
def synth_world() -> SynthWorld:
    return SynthWorld()


@pytest.fixture
def odometry_noise():
    return noisy_odometry


@pytest.fixture
def masks_hold():
    """A check: every tile the given tables hold has the occupied-with-free-behind mask worked out from
    scratch (``gmapping_tiles.mask_tile``)."""
    from navlab.mapping.gmapping_tiles import TILE, mask_tile

    def check(pool, tables: list[np.ndarray]) -> None:
        expected = np.empty((TILE, TILE), dtype=np.uint16)
        for t in np.unique(np.concatenate([table.ravel() for table in tables])):
            mask_tile(pool.tiles[t], expected)
            np.testing.assert_array_equal(pool.masks[t], expected, err_msg=f"tile {t}")

    return check
