"""Scan-matching primitives shared by the SLAM modes (pure numpy/numba; poses are (x, y, theta)).

- ``scan_points``: ranges -> points in the laser frame (m), with per-point normals from beam neighbours.
- ``LookupField``: a smoothed hit grid over a point set; ``correlative_search`` finds the pose on a
  (x, y, theta) lattice maximising the summed field at the transformed scan points (Olson 2009).
- ``icp_point_to_line``: fine refinement against a point set with normals (Gauss-Newton, Huber).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from navlab.geometry import wrap_angle


@dataclass
class ScanPoints:
    """Hit points of one scan in the laser frame: ``xy`` (N, 2) m, ``normals`` (N, 2) unit (0 if unknown)."""

    xy: np.ndarray
    normals: np.ndarray


def scan_points(
    ranges: np.ndarray,
    angle_min: float,
    angle_increment: float,
    *,
    range_min: float = 0.05,
    range_max: float = 30.0,
    voxel: float = 0.0,
    normal_gap: float = 0.25,
) -> ScanPoints:
    """Valid hits (range_min < r < range_max) of a scan as laser-frame points with normals.

    A normal comes from the two neighbouring beams when both are hits within ``normal_gap`` m;
    ``voxel`` > 0 keeps one point per voxel of that size (m).
    """
    r = np.asarray(ranges, dtype=np.float64)
    ang = angle_min + angle_increment * np.arange(len(r))
    ok = np.isfinite(r) & (r > range_min) & (r < range_max)
    rr = np.where(ok, r, 0.0)
    xy = np.stack([rr * np.cos(ang), rr * np.sin(ang)], axis=1)
    normals = np.zeros_like(xy)
    prev_ok = np.zeros_like(ok)
    next_ok = np.zeros_like(ok)
    prev_ok[1:] = ok[:-1]
    next_ok[:-1] = ok[1:]
    tang = np.zeros_like(xy)
    tang[1:-1] = xy[2:] - xy[:-2]
    gap = np.zeros(len(r))
    gap[1:-1] = np.hypot(tang[1:-1, 0], tang[1:-1, 1])
    good = ok & prev_ok & next_ok & (gap > 1e-6) & (gap < 2 * normal_gap)
    normals[good, 0] = -tang[good, 1] / gap[good]
    normals[good, 1] = tang[good, 0] / gap[good]
    xy, normals = xy[ok], normals[ok]
    if voxel > 0 and len(xy):
        keys = np.floor(xy / voxel).astype(np.int64)
        _, first = np.unique(keys[:, 0] * 1_000_003 + keys[:, 1], return_index=True)
        first.sort()
        xy, normals = xy[first], normals[first]
    return ScanPoints(xy, normals)


# --- correlative search ----------------------------------------------------------------------------


@numba.njit(cache=True)
def _bounds(pts: np.ndarray) -> tuple[float, float, float, float]:
    """(min x, min y, max x, max y) of points (N, 2), N >= 1 (numpy's axis-0 reductions are slow on (N, 2))."""
    x0 = x1 = pts[0, 0]
    y0 = y1 = pts[0, 1]
    for n in range(1, pts.shape[0]):
        x, y = pts[n, 0], pts[n, 1]
        x0 = min(x0, x)
        x1 = max(x1, x)
        y0 = min(y0, y)
        y1 = max(y1, y)
    return x0, y0, x1, y1


@numba.njit(cache=True)
def _splat(pts: np.ndarray, ox: float, oy: float, res: float, w: int, h: int, kernel: np.ndarray) -> np.ndarray:
    grid = np.zeros((h, w), dtype=np.float32)
    k = kernel.shape[0] // 2
    # a point whose cell already holds the kernel's peak adds nothing (its cell was splatted before): skip it,
    # which is exact when the peak is the centre and every other kernel value is below it
    peak = np.float32(kernel[k, k])
    dedup = True
    for dj in range(-k, k + 1):
        for di in range(-k, k + 1):
            if (dj != 0 or di != 0) and np.float32(kernel[dj + k, di + k]) >= peak:
                dedup = False
    for n in range(pts.shape[0]):
        ci = math.floor((pts[n, 0] - ox) / res)
        cj = math.floor((pts[n, 1] - oy) / res)
        if dedup and 0 <= ci < w and 0 <= cj < h and grid[cj, ci] >= peak:
            continue
        for dj in range(-k, k + 1):
            j = cj + dj
            if j < 0 or j >= h:
                continue
            for di in range(-k, k + 1):
                i = ci + di
                if i < 0 or i >= w:
                    continue
                v = kernel[dj + k, di + k]
                if v > grid[j, i]:
                    grid[j, i] = v
    return grid


class LookupField:
    """Max-of-Gaussians hit likelihood on a grid covering ``points`` (world frame) plus a margin."""

    def __init__(self, points: np.ndarray, *, resolution: float = 0.05, sigma: float = 0.05, margin: float = 1.0):
        pts = np.ascontiguousarray(points, dtype=np.float64)
        x0, y0, x1, y1 = _bounds(pts)
        lo = (x0 - margin, y0 - margin)
        hi = (x1 + margin, y1 + margin)
        self.resolution = resolution
        self.origin = (float(lo[0]), float(lo[1]))
        self.width = math.ceil((hi[0] - lo[0]) / resolution) + 1
        self.height = math.ceil((hi[1] - lo[1]) / resolution) + 1
        k = max(1, math.ceil(2.5 * sigma / resolution))
        d = np.arange(-k, k + 1) * resolution
        kernel = np.exp(-(d[None, :] ** 2 + d[:, None] ** 2) / (2 * sigma**2))
        self.grid = _splat(
            pts,
            self.origin[0],
            self.origin[1],
            resolution,
            self.width,
            self.height,
            kernel,
        )


@numba.njit(cache=True)
def _correlative(
    grid: np.ndarray,
    ox: float,
    oy: float,
    res: float,
    pts: np.ndarray,
    x0: float,
    y0: float,
    t0: float,
    nlin: int,
    lin_step: float,
    nang: int,
    ang_step: float,
) -> tuple[float, float, float, float]:
    h, w = grid.shape
    best = -1.0
    bx, by, bt = x0, y0, t0
    n = pts.shape[0]
    ri = np.empty(n, dtype=np.int64)
    rj = np.empty(n, dtype=np.int64)
    side = 2 * nlin + 1
    acc = np.empty(side * side)
    acc2 = acc.reshape(side, side)  # a view: acc2[dj + nlin, di + nlin] is offset (di, dj)'s sum
    for a in range(-nang, nang + 1):
        th = t0 + a * ang_step
        c, s = math.cos(th), math.sin(th)
        for k in range(n):
            ri[k] = math.floor((x0 + c * pts[k, 0] - s * pts[k, 1] - ox) / res)
            rj[k] = math.floor((y0 + s * pts[k, 0] + c * pts[k, 1] - oy) / res)
        # every offset's sum over the points, accumulated point by point (each sum adds the same values in
        # the same order as a sum per offset would: identical results, but reading the grid patch row by row)
        acc[:] = 0.0
        for k in range(n):
            i_lo = max(-nlin, -ri[k])
            i_hi = min(nlin, w - 1 - ri[k])
            if i_lo > i_hi:
                continue
            rk = ri[k]
            for dj in range(max(-nlin, -rj[k]), min(nlin, h - 1 - rj[k]) + 1):
                # row slices: the compiler vectorises the row's additions (each sum still adds in point order)
                grow = grid[rj[k] + dj, rk + i_lo : rk + i_hi + 1]
                arow = acc2[dj + nlin, nlin + i_lo : nlin + i_hi + 1]
                for q in range(grow.shape[0]):
                    arow[q] += grow[q]
        # a linear penalty keeps ties near the prior
        for dj in range(-nlin, nlin + 1):
            for di in range(-nlin, nlin + 1):
                tot = acc[(dj + nlin) * side + di + nlin]
                if tot > best:
                    best = tot
                    bx = x0 + di * lin_step
                    by = y0 + dj * lin_step
                    bt = th
    return bx, by, bt, best / max(n, 1)


def correlative_search(
    field: LookupField,
    pts: np.ndarray,
    prior: np.ndarray,
    *,
    lin_window: float,
    ang_window: float,
    ang_step: float,
) -> tuple[np.ndarray, float]:
    """Best pose (x, y, theta) within ±lin_window m / ±ang_window rad of ``prior`` and its mean field score.

    Translations step one field cell; ``pts`` are scan points (N, 2) in the laser frame.
    """
    nlin = max(0, round(lin_window / field.resolution))
    nang = max(0, round(ang_window / ang_step))
    bx, by, bt, score = _correlative(
        field.grid,
        field.origin[0],
        field.origin[1],
        field.resolution,
        np.ascontiguousarray(pts, dtype=np.float64),
        float(prior[0]),
        float(prior[1]),
        float(prior[2]),
        nlin,
        field.resolution,
        nang,
        ang_step,
    )
    return np.array([bx, by, wrap_angle(bt)]), float(score)


# --- ICP ----------------------------------------------------------------------------------------------


@numba.njit(cache=True)
def _build_hash(pts: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, float, float, int, int]:
    """Bucket points into a dense grid of ``cell``-sized bins (a counting sort: ascending index within a bin):
    (order, start, ox, oy, w, h); bin ``c`` holds ``order[start[c]:start[c + 1]]``."""
    n = pts.shape[0]
    x0, y0, x1, y1 = _bounds(pts)
    ox = x0 - cell
    oy = y0 - cell
    w = int((x1 - ox) / cell) + 2
    h = int((y1 - oy) / cell) + 2
    keys = np.empty(n, dtype=np.int64)
    start = np.zeros(w * h + 1, dtype=np.int64)
    for k in range(n):
        keys[k] = int((pts[k, 1] - oy) / cell) * w + int((pts[k, 0] - ox) / cell)
        start[keys[k] + 1] += 1
    for c in range(w * h):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for k in range(n):
        order[fill[keys[k]]] = k
        fill[keys[k]] += 1
    return order, start, ox, oy, w, h


@numba.njit(cache=True)
def _icp(
    map_xy: np.ndarray,
    map_n: np.ndarray,
    scan: np.ndarray,
    x0: float,
    y0: float,
    t0: float,
    max_dist: float,
    min_dist: float,
    iterations: int,
    huber: float,
) -> tuple[float, float, float, float, float, np.ndarray]:
    # the nearest map point within the search radius (at most max_dist), from the bins of max_dist that reach
    # within the radius (equally near points: the first in bin order); 3 x 3 bins per point at most (bins of
    # half max_dist, up to 5 x 5 of them, cost CSAIL's refinement 20 % more ICP time)
    cell = max_dist
    order, start, ox, oy, w, h = _build_hash(map_xy, cell)
    x, y, t = x0, y0, t0
    n = scan.shape[0]
    half = max(iterations // 2, 1)
    ratio = (min_dist / max_dist) ** (1.0 / max(half - 1, 1))
    frac, rms = 0.0, 1e9
    hess = np.zeros((3, 3))
    for it in range(iterations):
        dmax = max_dist * ratio ** min(it, half - 1)
        reach = dmax * (1.0 + 1e-9) + 1e-12  # bins reaching within dmax of the point (slack for rounding)
        c, s = math.cos(t), math.sin(t)
        hess = np.zeros((3, 3))
        g = np.zeros(3)
        matched = 0
        sq = 0.0
        rows = 0
        for k in range(n):
            px = x + c * scan[k, 0] - s * scan[k, 1]
            py = y + s * scan[k, 0] + c * scan[k, 1]
            best = dmax * dmax
            bi = -1
            i_lo = max(0, math.floor((px - reach - ox) / cell))
            i_hi = min(w - 1, math.floor((px + reach - ox) / cell))
            j_lo = max(0, math.floor((py - reach - oy) / cell))
            j_hi = min(h - 1, math.floor((py + reach - oy) / cell))
            for j in range(j_lo, j_hi + 1):
                for i in range(i_lo, i_hi + 1):
                    b = j * w + i
                    for q in range(start[b], start[b + 1]):
                        m = order[q]
                        d2 = (map_xy[m, 0] - px) ** 2 + (map_xy[m, 1] - py) ** 2
                        if d2 < best:
                            best = d2
                            bi = m
            if bi < 0:
                continue
            matched += 1
            rx, ry = px - x, py - y
            dthx, dthy = -ry, rx  # d(p)/d(theta)
            ex, ey = px - map_xy[bi, 0], py - map_xy[bi, 1]
            nx, ny = map_n[bi, 0], map_n[bi, 1]
            point_to_line = nx != 0.0 or ny != 0.0
            # one point-to-line residual along the normal, or two point-to-point residuals (x, y)
            for ax in range(1 if point_to_line else 2):
                if point_to_line:
                    r = ex * nx + ey * ny
                    jx, jy, jt = nx, ny, dthx * nx + dthy * ny
                else:
                    r = ex if ax == 0 else ey
                    jx = 1.0 if ax == 0 else 0.0
                    jy = 1.0 - jx
                    jt = dthx if ax == 0 else dthy
                a = abs(r)
                wt = 1.0 if a <= huber else huber / a
                hess[0, 0] += wt * jx * jx
                hess[0, 1] += wt * jx * jy
                hess[0, 2] += wt * jx * jt
                hess[1, 1] += wt * jy * jy
                hess[1, 2] += wt * jy * jt
                hess[2, 2] += wt * jt * jt
                g[0] += wt * jx * r
                g[1] += wt * jy * r
                g[2] += wt * jt * r
                sq += r * r
                rows += 1
        frac = matched / max(n, 1)
        if matched < 6:
            break
        hess[1, 0] = hess[0, 1]
        hess[2, 0] = hess[0, 2]
        hess[2, 1] = hess[1, 2]
        rms = math.sqrt(sq / max(rows, 1))
        for d in range(3):
            hess[d, d] += 1e-9
        delta = -np.linalg.solve(hess, g)
        x += delta[0]
        y += delta[1]
        t += delta[2]
        if it >= half and abs(delta[0]) + abs(delta[1]) < 1e-4 and abs(delta[2]) < 1e-4:
            break
    return x, y, t, frac, rms, hess


@dataclass
class IcpResult:
    """Refined pose, the fraction of scan points with a correspondence, and the RMS point-to-line residual (m)."""

    pose: np.ndarray
    inlier_fraction: float
    rms: float
    hessian: np.ndarray


def icp_point_to_line(
    map_xy: np.ndarray,
    map_normals: np.ndarray,
    scan_xy: np.ndarray,
    init: np.ndarray,
    *,
    max_dist: float = 0.3,
    min_dist: float = 0.1,
    iterations: int = 12,
    huber: float = 0.03,
) -> IcpResult:
    """Refine the pose of a scan (points ``scan_xy`` in its own frame) against map points with normals.

    Correspondences are nearest neighbours within a radius shrinking from ``max_dist`` to ``min_dist``
    (m); map points without a normal pair point-to-point. Gauss-Newton with a Huber kernel (m).
    """
    x, y, t, frac, rms, hess = _icp(
        np.ascontiguousarray(map_xy, dtype=np.float64),
        np.ascontiguousarray(map_normals, dtype=np.float64),
        np.ascontiguousarray(scan_xy, dtype=np.float64),
        float(init[0]),
        float(init[1]),
        float(init[2]),
        float(max_dist),
        float(min_dist),
        int(iterations),
        float(huber),
    )
    return IcpResult(np.array([x, y, wrap_angle(t)]), float(frac), float(rms), hess)


def warmup() -> None:
    """Compile the numba kernels on a tiny input (they are cached on disk afterwards)."""
    pts = np.array([[1.0, 0.0], [1.0, 0.5], [0.5, 1.0]])
    f = LookupField(pts)
    correlative_search(f, pts, np.zeros(3), lin_window=0.1, ang_window=0.01, ang_step=0.01)
    icp_point_to_line(pts, np.zeros_like(pts), pts, np.zeros(3))
    from navlab.mapping.occupancy import integrate_scan

    integrate_scan(
        np.zeros((4, 4)), (-0.1, -0.1), 0.05, np.zeros(3), np.ones(2), np.zeros(2), max_urange=1, max_range=2
    )
