"""3-D lidar scans shape by shape (Numba): each geom tests only the rays of its block of the ring x azimuth grid.

A lidar's rays form a grid: ring ``i`` at elevation ``el_i``, column ``j`` at azimuth ``az_j``, direction
``cos(el) (cos az, sin az, 0) + sin(el) (0, 0, 1)`` in the sensor frame. For each primitive geom the block of the
grid that can touch it (:func:`navlab.sim.raycast3d._block`: the azimuth span of its box's corners, the elevation
cone of its bounding sphere) is swept column by column: a column's horizontal direction is turned into the geom's
frame once, each ring adds its vertical part, and the exact ray-shape test
(:data:`navlab.sim.raycast.ray_hit`) runs there; the buffer keeps the nearest hit. The result equals
:func:`navlab.sim.raycast3d.cast_grid`'s (every ray against every geom), at a cost that grows with the rays each
shape's block holds rather than with rays times shapes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64

from navlab.sim.gauss import normal
from navlab.sim.raycast import BOX, PLANE, ray_hit
from navlab.sim.raycast3d import SPHERICAL, _block, _lower_bound, in_geom_frame


@njit(cache=True)
def _columns(bounds: np.ndarray, period: int, cols: int, spans: np.ndarray) -> None:
    """``spans`` (3 x 2): the column intervals of ``bounds`` (c0, c1 in bounds[2:4], wrapping if bounds[4]): the
    block and its copies one turn either side, one column of slack; empty intervals have lo > hi."""
    for w in range(3):
        spans[w, 0], spans[w, 1] = 1, 0
    if bounds[4] == 0:
        spans[0, 0], spans[0, 1] = bounds[2], bounds[3]
        return
    for w in range(3):
        pad = 0 if w == 1 else 1
        spans[w, 0] = max(bounds[2] + (w - 1) * period - pad, 0)
        spans[w, 1] = min(bounds[3] + (w - 1) * period + pad, cols - 1)


@njit(cache=True)
def _face_columns(
    m: np.ndarray, p: np.ndarray, k: int, level: float, size: np.ndarray, params: np.ndarray, bounds: np.ndarray
) -> None:
    """Set bounds[2:5] to the azimuth columns of the box face ``q_k = level`` (its corners' azimuths in the sensor
    frame; every column when the face spans the sensor's vertical axis)."""
    j, jj = (k + 1) % 3, (k + 2) % 3
    first, amin, amax = 0.0, 0.0, 0.0
    q = np.empty(3)
    for corner in range(4):
        q[k] = level - p[k]
        q[j] = (size[j] if corner & 1 else -size[j]) - p[j]
        q[jj] = (size[jj] if corner & 2 else -size[jj]) - p[jj]
        sx = m[0, 0] * q[0] + m[1, 0] * q[1] + m[2, 0] * q[2]
        sy = m[0, 1] * q[0] + m[1, 1] * q[1] + m[2, 1] * q[2]
        if sx * sx + sy * sy < 1e-18:
            return  # a corner on the vertical axis: every column
        az = math.atan2(sy, sx)
        if corner == 0:
            first = az
            continue
        rel = (az - first + math.pi) % (2 * math.pi) - math.pi
        amin, amax = min(amin, rel), max(amax, rel)
    if amax - amin >= math.pi - 1e-6 or params[1] <= 0:
        return
    bounds[2] = math.ceil((first + amin - params[0]) / params[1] - 1e-9)
    bounds[3] = math.floor((first + amax - params[0]) / params[1] + 1e-9)
    bounds[4] = 1


@njit(cache=True)
def sweep_grid(
    origin: np.ndarray,
    rot: np.ndarray,
    cos_az: np.ndarray,
    sin_az: np.ndarray,
    cos_el: np.ndarray,
    sin_el: np.ndarray,
    geoms: np.ndarray,
    geom_type: np.ndarray,
    geom_size: np.ndarray,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    tmin: float,
    tmax: float,
    out: np.ndarray,
) -> None:
    """``out`` (rings x samples) = distance (m) along each ray of the grid (evenly spaced azimuths ``cos_az``,
    ``sin_az`` and elevations ``cos_el``, ``sin_el``; sensor frame ``rot``, columns its axes in world, at world
    ``origin``) to the nearest geom of ``geoms`` from ``tmin`` on; inf without a hit up to ``tmax``."""
    rows, cols = out.shape
    out[:] = np.inf
    az0 = math.atan2(sin_az[0], cos_az[0])
    d_az = 0.0
    if cols > 1:  # the azimuth step: the angle from the first direction to the second
        d_az = math.atan2(sin_az[1] * cos_az[0] - cos_az[1] * sin_az[0], cos_az[1] * cos_az[0] + sin_az[1] * sin_az[0])
    el0 = math.atan2(sin_el[0], cos_el[0])
    d_el = math.atan2(sin_el[rows - 1], cos_el[rows - 1]) - el0
    d_el = d_el / (rows - 1) if rows > 1 else 0.0
    params = np.array([az0, d_az, el0, d_el])
    period = math.floor(2 * math.pi / d_az + 0.5) if d_az > 0 else 0
    bounds = np.zeros(5, dtype=np.int64)
    spans = np.zeros((3, 2), dtype=np.int64)
    p = np.empty(3)
    m = np.empty((3, 3))  # sensor axes in the geom frame
    d = np.empty(3)
    extent = np.zeros(3)
    for gi in range(geoms.shape[0]):
        g = geoms[gi]
        kind = geom_type[g]
        size = geom_size[g]
        xm = geom_xmat[g]
        in_geom_frame(origin, rot, geom_xpos[g], xm, p, m)
        if _lower_bound(kind, size, p) > tmax:
            continue
        if not _block(kind, size, geom_xpos[g], xm, rot, origin, SPHERICAL, params, rows, cols, bounds):
            continue
        if kind == BOX:  # each face turned towards the sensor, over its own azimuth span
            for k in range(3):
                for side in (-1.0, 1.0):
                    if side * p[k] > size[k]:
                        bounds[2], bounds[3], bounds[4] = 0, cols - 1, 0
                        _face_columns(m, p, k, side * size[k], size, params, bounds)
                        _columns(bounds, period, cols, spans)
                        _sweep_face(
                            out, p, m, k, side * size[k], size, cos_az, sin_az, cos_el, sin_el, bounds, spans, tmin
                        )
            continue
        if kind == PLANE:  # both sides, every column: as a face (unbounded: past the range)
            reach = abs(p[0]) + abs(p[1]) + tmax + 1.0
            extent[0], extent[1] = (size[0], size[1]) if size[0] > 0 else (reach, reach)
            _columns(bounds, period, cols, spans)
            _sweep_face(out, p, m, 2, 0.0, extent, cos_az, sin_az, cos_el, sin_el, bounds, spans, tmin)
            continue
        _columns(bounds, period, cols, spans)
        for w in range(3):
            for c in range(spans[w, 0], spans[w, 1] + 1):
                hx = m[0, 0] * cos_az[c] + m[0, 1] * sin_az[c]
                hy = m[1, 0] * cos_az[c] + m[1, 1] * sin_az[c]
                hz = m[2, 0] * cos_az[c] + m[2, 1] * sin_az[c]
                for r in range(bounds[0], bounds[1] + 1):
                    d[0] = cos_el[r] * hx + sin_el[r] * m[0, 2]
                    d[1] = cos_el[r] * hy + sin_el[r] * m[1, 2]
                    d[2] = cos_el[r] * hz + sin_el[r] * m[2, 2]
                    t = ray_hit(kind, size, p, d, tmin)
                    if t < out[r, c]:
                        out[r, c] = t
    for r in range(rows):
        for c in range(cols):
            if out[r, c] > tmax:
                out[r, c] = np.inf


@njit(cache=True)
def _sweep_face(
    out: np.ndarray,
    p: np.ndarray,
    m: np.ndarray,
    k: int,
    level: float,
    size: np.ndarray,
    cos_az: np.ndarray,
    sin_az: np.ndarray,
    cos_el: np.ndarray,
    sin_el: np.ndarray,
    bounds: np.ndarray,
    spans: np.ndarray,
    tmin: float,
) -> None:
    """The rays of rows bounds[0:2] x ``spans`` that meet the box face ``q_k = level`` (geom frame; the sensor at
    ``p``, its axes ``m``) first: the face's distance where it is nearer than ``out``'s."""
    j, jj = (k + 1) % 3, (k + 2) % 3
    num = level - p[k]
    for w in range(3):
        for c in range(spans[w, 0], spans[w, 1] + 1):
            hk = m[k, 0] * cos_az[c] + m[k, 1] * sin_az[c]
            hj = m[j, 0] * cos_az[c] + m[j, 1] * sin_az[c]
            hjj = m[jj, 0] * cos_az[c] + m[jj, 1] * sin_az[c]
            for r in range(bounds[0], bounds[1] + 1):
                dk = cos_el[r] * hk + sin_el[r] * m[k, 2]
                if dk == 0.0:
                    continue
                t = num / dk
                if not (t >= tmin) or t >= out[r, c]:
                    continue
                if abs(p[j] + t * (cos_el[r] * hj + sin_el[r] * m[j, 2])) > size[j]:
                    continue
                if abs(p[jj] + t * (cos_el[r] * hjj + sin_el[r] * m[jj, 2])) > size[jj]:
                    continue
                out[r, c] = t


@njit(cache=True)
def finish_scan(ranges: np.ndarray, noise_stddev: float, seed: np.uint64, range_max: float) -> None:
    """In place: gaussian noise (std dev m, from the stream seeded with ``seed``, hit by hit in row-major order) on
    each hit when ``noise_stddev`` > 0; misses (inf) become ``range_max``, as Gazebo's ray sensor reports them."""
    z = uint64(seed)
    for r in range(ranges.shape[0]):
        for c in range(ranges.shape[1]):
            if not math.isfinite(ranges[r, c]):
                ranges[r, c] = range_max
            elif noise_stddev > 0.0:
                n, z = normal(z)
                ranges[r, c] += noise_stddev * n


@njit(cache=True)
def scan_cloud(
    ranges: np.ndarray,
    unit: np.ndarray,
    lo: float,
    hi: float,
    cap: float,
    organize: bool,
    words: np.ndarray,
    bits: np.ndarray,
) -> int:
    """Fill the Velodyne plugin's points (32 bytes: float32 x y z at words 0-2, intensity 0 at word 4, the ring as
    uint16 at byte 20) into ``words`` (float32, rings*samples x 8; ``bits`` the same buffer as uint32): each range
    capped at ``cap`` along its ``unit`` direction (rings x samples x 3), kept if ``lo`` < r < ``hi``. Organised:
    every ray in order, NaN where not kept; else only the kept ones. Returns the number of points written."""
    n = 0
    for ring in range(ranges.shape[0]):
        for c in range(ranges.shape[1]):
            r = min(ranges[ring, c], cap)
            keep = lo < r < hi
            if not keep and not organize:
                continue
            for k in range(3):
                words[n, k] = np.float32(r * unit[ring, c, k]) if keep else np.nan
            bits[n, 3] = 0
            bits[n, 4] = 0
            bits[n, 5] = ring
            bits[n, 6] = 0
            bits[n, 7] = 0
            n += 1
    return n
