"""Log-odds occupancy from laser scans at known poses (numba ray casting), and conversion to ``GridMap``.

Each beam marks the cells it crosses as free and, when it hit something within ``max_urange``, its end
cell as occupied (GMapping's ``maxUrange`` / ``maxRange`` semantics: beams at or beyond ``max_range``
are no-returns; returns beyond ``max_urange`` only clear space up to ``max_urange``).

Growing maps (as GMapping's ``ScanMatcherMap``): cells sit on a fixed lattice, cell ``(I, J)`` covering
``[ox + I*res, ox + (I+1)*res) x [oy + J*res, ...)`` for a fixed anchor ``(ox, oy)``; an array holds the
window of lattice cells starting at ``(oi, oj)``. Growing the window pads the array and never moves a
cell, so cell indices are computed from the same anchor before and after.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.grid import GridMap
from navlab.gridline import TIE_LATE, line, line_cell, line_minor, line_strides

L_OCC = 0.85  # log-odds increment of a hit
L_FREE = -0.4  # log-odds increment of a traversed cell
L_CLAMP = 5.0


@numba.njit(cache=True, inline="always")
def beam_end(
    lattice: tuple[float, float, int, int, float], pose: tuple[float, float, float], r: float, angle: float, cut: float
) -> tuple[int, int, bool]:
    """The cell (column, row) where a beam of range ``r`` at ``angle`` from the laser at ``pose`` (x, y, theta)
    ends, cut to ``cut`` (``max_urange``), and whether it ends on a hit (shorter than ``cut``); ``lattice``:
    (anchor x, y, offset column, row, cell size), cells counted from the offset cell."""
    ox, oy, oi, oj, res = lattice
    px, py, pt = pose
    hit = r < cut
    if not hit:
        r = cut
    a = pt + angle
    ex = px + r * math.cos(a)
    ey = py + r * math.sin(a)
    return math.floor((ex - ox) / res) - oi, math.floor((ey - oy) / res) - oj, hit


@numba.njit(cache=True)
def _raycast(
    logodds: np.ndarray,
    ox: float,
    oy: float,
    oi: int,
    oj: int,
    res: float,
    px: float,
    py: float,
    pt: float,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_urange: float,
    max_range: float,
    l_occ: float,
    l_free: float,
    clamp: float,
) -> None:
    h, w = logodds.shape
    i0 = math.floor((px - ox) / res) - oi
    j0 = math.floor((py - oy) / res) - oj
    start_inside = 0 <= i0 < w and 0 <= j0 < h
    flat = logodds.reshape(-1)  # a view (C-contiguous): the fast path below walks it by flat index
    for k in range(ranges.shape[0]):
        r = ranges[k]
        if not (r > 0.0) or r >= max_range:
            continue
        i1, j1, hit = beam_end((ox, oy, oi, oj, res), (px, py, pt), r, angles[k], max_urange)
        # the line's cells from (i0, j0), the end cell excluded
        ln = line(i0, j0, i1, j1, TIE_LATE)
        if start_inside and 0 <= i1 < w and 0 <= j1 < h:  # the whole line is inside: no per-cell checks
            idx, smaj, smin = line_strides(ln, w)
            for n in range(ln[0]):
                c = numba.uint64(idx + n * smaj + line_minor(ln, n) * smin)
                v = flat[c] + l_free
                flat[c] = v if v > -clamp else -clamp
        else:
            for n in range(ln[0]):
                i, j = line_cell(ln, n)
                if 0 <= i < w and 0 <= j < h:
                    v = logodds[j, i] + l_free
                    logodds[j, i] = v if v > -clamp else -clamp
        if hit and 0 <= i1 < w and 0 <= j1 < h:
            v = logodds[j1, i1] + l_occ
            logodds[j1, i1] = v if v < clamp else clamp


def integrate_scan(
    logodds: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    laser_pose: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    *,
    max_urange: float,
    max_range: float,
) -> None:
    """Add one scan (laser at ``laser_pose`` in the map frame) to a log-odds grid (C-contiguous) in place."""
    if not logodds.flags.c_contiguous:
        raise ValueError("integrate_scan: the log-odds grid must be C-contiguous (it is updated in place)")
    _raycast(
        logodds,
        float(origin[0]),
        float(origin[1]),
        0,
        0,
        float(resolution),
        float(laser_pose[0]),
        float(laser_pose[1]),
        float(laser_pose[2]),
        np.ascontiguousarray(ranges, dtype=np.float64),
        np.ascontiguousarray(angles, dtype=np.float64),
        float(max_urange),
        float(max_range),
        L_OCC,
        L_FREE,
        L_CLAMP,
    )


@numba.njit(cache=True)
def _scan_extent(
    poses: np.ndarray, ranges: np.ndarray, angles: np.ndarray, max_urange: float, max_range: float
) -> tuple[float, float, float, float]:
    """(x min, x max, y min, y max) of the poses (N, 3) and of the scan's beam end points from each."""
    xmin, xmax, ymin, ymax = math.inf, -math.inf, math.inf, -math.inf
    for n in range(poses.shape[0]):
        px, py, pt = poses[n, 0], poses[n, 1], poses[n, 2]
        xmin, xmax, ymin, ymax = min(xmin, px), max(xmax, px), min(ymin, py), max(ymax, py)
        for k in range(ranges.shape[0]):
            r = ranges[k]
            if not (r > 0.0 and r < max_range):
                continue
            rr = r if r < max_urange else max_urange
            a = pt + angles[k]
            x = px + rr * math.cos(a)
            y = py + rr * math.sin(a)
            xmin, xmax, ymin, ymax = min(xmin, x), max(xmax, x), min(ymin, y), max(ymax, y)
    return xmin, xmax, ymin, ymax


def scan_cells(
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    anchor: tuple[float, float],
    resolution: float,
    *,
    max_urange: float,
    max_range: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Lattice cell range ``(lo, hi)`` (int (2,) each, ``hi`` inclusive, (column, row)) that integrating the scan
    from each laser pose in ``poses`` (N, 3) can touch: the poses and the beams' end points (no-returns
    excluded, long returns cut at ``max_urange``), exactly as the ray caster treats them."""
    xmin, xmax, ymin, ymax = _scan_extent(
        np.ascontiguousarray(poses, dtype=np.float64).reshape(-1, 3),
        np.ascontiguousarray(ranges, dtype=np.float64),
        np.ascontiguousarray(angles, dtype=np.float64),
        float(max_urange),
        float(max_range),
    )
    lo = np.array([math.floor((xmin - anchor[0]) / resolution), math.floor((ymin - anchor[1]) / resolution)])
    hi = np.array([math.floor((xmax - anchor[0]) / resolution), math.floor((ymax - anchor[1]) / resolution)])
    return lo.astype(np.int64), hi.astype(np.int64)


def logodds_to_grid(
    logodds: np.ndarray, resolution: float, origin: tuple[float, float], *, frame_id: str = "map"
) -> GridMap:
    """``GridMap`` from log-odds: untouched cells (0) unknown, else occupancy percent rounded."""
    seen = np.flatnonzero(logodds)  # usually a small part of a SLAM map's allocation
    data = np.full(logodds.shape, -1, dtype=np.int8)
    data.flat[seen] = np.rint(100.0 - 100.0 / (1.0 + np.exp(logodds.flat[seen]))).astype(np.int8)
    return GridMap(data, resolution, (float(origin[0]), float(origin[1]), 0.0), frame_id)


def build_map(
    laser_poses: np.ndarray,
    scans: list[tuple[np.ndarray, np.ndarray]],
    *,
    resolution: float = 0.05,
    max_urange: float = 30.0,
    max_range: float = 80.0,
    margin: float = 1.0,
    frame_id: str = "map",
) -> GridMap:
    """Occupancy grid of ``scans`` ((ranges, angles) in the laser frame) taken at ``laser_poses`` (N, 3)."""
    pts = [laser_poses[:, :2]]
    for pose, (r, a) in zip(laser_poses, scans, strict=True):
        ok = (r > 0) & (r < max_range)
        rr = np.minimum(r[ok], max_urange)
        pts.append(np.stack([pose[0] + rr * np.cos(pose[2] + a[ok]), pose[1] + rr * np.sin(pose[2] + a[ok])], 1))
    allp = np.concatenate(pts)
    lo = allp.min(axis=0) - margin
    hi = allp.max(axis=0) + margin
    w = math.ceil((hi[0] - lo[0]) / resolution)
    h = math.ceil((hi[1] - lo[1]) / resolution)
    logodds = np.zeros((h, w), dtype=np.float64)
    for pose, (r, a) in zip(laser_poses, scans, strict=True):
        integrate_scan(logodds, (lo[0], lo[1]), resolution, pose, r, a, max_urange=max_urange, max_range=max_range)
    return logodds_to_grid(logodds, resolution, (float(lo[0]), float(lo[1])), frame_id=frame_id)
