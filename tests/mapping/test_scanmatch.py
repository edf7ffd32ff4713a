"""Scan-matching kernels against brute-force references: the lookup field is the max of the kernels at the
points' cells, the correlative search returns the best lattice pose (first in search order), and ICP pairs
each point with its nearest map point within the radius."""

from __future__ import annotations

import math

import numpy as np

from navlab.mapping.scanmatch import LookupField, correlative_search, icp_point_to_line


def _points(rng: np.random.Generator, n: int) -> np.ndarray:
    """Points along a few random segments (many share a cell, as overlapping scans do) plus a little noise."""
    a, b = rng.uniform(-4, 4, (6, 2)), rng.uniform(-4, 4, (6, 2))
    t = rng.uniform(0, 1, n)
    k = rng.integers(0, 6, n)
    return a[k] + t[:, None] * (b[k] - a[k]) + rng.normal(0, 0.01, (n, 2))


def _reference_field(pts: np.ndarray, f: LookupField, sigma: float) -> np.ndarray:
    res = f.resolution
    k = max(1, math.ceil(2.5 * sigma / res))
    d = np.arange(-k, k + 1) * res
    kernel = np.exp(-(d[None, :] ** 2 + d[:, None] ** 2) / (2 * sigma**2)).astype(np.float32)
    grid = np.zeros((f.height, f.width), dtype=np.float32)
    for x, y in pts:
        ci, cj = math.floor((x - f.origin[0]) / res), math.floor((y - f.origin[1]) / res)
        win = grid[cj - k : cj + k + 1, ci - k : ci + k + 1]
        np.maximum(win, kernel, out=win)
    return grid


def test_lookup_field_is_the_max_of_the_kernels_at_the_points():
    rng = np.random.default_rng(0)
    for res in (0.05, 0.1, 0.2):
        pts = _points(rng, 3000)
        f = LookupField(pts, resolution=res, sigma=res)
        assert f.origin == (pts[:, 0].min() - 1.0, pts[:, 1].min() - 1.0)
        assert np.array_equal(f.grid, _reference_field(pts, f, res))


def test_correlative_search_returns_the_first_best_lattice_pose():
    rng = np.random.default_rng(1)
    pts = _points(rng, 2000)
    f = LookupField(pts, resolution=0.1, sigma=0.1)
    scan = pts[rng.choice(len(pts), 150, replace=False)]
    prior = np.array([0.23, -0.17, 0.05])
    nlin, nang, step = 4, 5, math.radians(1.0)
    pose, score = correlative_search(f, scan, prior, lin_window=0.4, ang_window=5 * step, ang_step=step)
    best, arg = -1.0, None
    for a in range(-nang, nang + 1):
        th = prior[2] + a * step
        c, s = math.cos(th), math.sin(th)
        ri = np.floor((prior[0] + c * scan[:, 0] - s * scan[:, 1] - f.origin[0]) / f.resolution).astype(int)
        rj = np.floor((prior[1] + s * scan[:, 0] + c * scan[:, 1] - f.origin[1]) / f.resolution).astype(int)
        for dj in range(-nlin, nlin + 1):
            for di in range(-nlin, nlin + 1):
                vals = f.grid[rj + dj, ri + di].astype(np.float64)
                tot = float(np.cumsum(vals)[-1])  # summed in point order, as the kernel does
                if tot > best:
                    best, arg = tot, (prior[0] + di * f.resolution, prior[1] + dj * f.resolution, th)
    assert arg is not None
    np.testing.assert_allclose(pose, np.array(arg), rtol=0, atol=1e-12)  # the kernel wraps the heading
    assert score == best / len(scan)
    assert abs(pose[0]) < 0.05 and abs(pose[1]) < 0.05 and abs(pose[2]) < 0.01  # the scan's true pose


def test_icp_recovers_an_offset_scan_against_a_dense_map():
    rng = np.random.default_rng(2)
    # a room corner and a box: points with normals (dense, like a local map of overlapping scans)
    segs = [((0, 0), (6, 0), (0, 1)), ((0, 0), (0, 5), (1, 0)), ((3, 2), (4, 2), (0, -1)), ((4, 2), (4, 3), (1, 0))]
    xy, nrm = [], []
    for a, b, n in segs:
        t = rng.uniform(0, 1, 1500)
        xy.append(np.array(a) + t[:, None] * (np.array(b) - np.array(a)))
        nrm.append(np.tile(n, (1500, 1)))
    map_xy, map_n = np.concatenate(xy).astype(float), np.concatenate(nrm).astype(float)
    truth = np.array([0.5, 0.4, math.radians(3.0)])
    sub = map_xy[rng.choice(len(map_xy), 300, replace=False)]
    c, s = math.cos(truth[2]), math.sin(truth[2])
    d = sub - truth[:2]
    scan = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)  # in the scan's frame
    res = icp_point_to_line(map_xy, map_n, scan, truth + np.array([0.12, -0.1, 0.02]), max_dist=0.3, min_dist=0.08)
    assert np.abs(res.pose - truth).max() < 2e-3
    assert res.inlier_fraction == 1.0
    assert res.rms < 2e-3
