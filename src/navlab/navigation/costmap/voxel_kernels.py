"""The voxel layer's compiled work: one observation (a sensor origin and its points) cleared and marked in one call.

Voxel columns are packed as costmap_2d's ``voxel_grid`` packs them (see :mod:`navlab.navigation.costmap.voxel_layer`):
bit ``z`` and bit ``z + 16`` of a uint32 — both set: marked; only the low one: unknown; none: free.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def popcount16(v: np.int64) -> np.int64:
    """Number of set bits of a 16-bit value."""
    v = v - ((v >> 1) & 0x5555)
    v = (v & 0x3333) + ((v >> 2) & 0x3333)
    v = (v + (v >> 4)) & 0x0F0F
    return (v + (v >> 8)) & 0x1F


@numba.njit(cache=True)
def clear_ray(
    columns: np.ndarray,
    cost: np.ndarray,
    x: float,
    y: float,
    z: float,
    ex: float,
    ey: float,
    ez: float,
    z_voxels: int,
    mark_threshold: int,
    unknown_threshold: int,
    free: np.uint8,
) -> None:
    """Clear the voxels on the segment (x, y, z) -> (ex, ey, ez) (continuous voxel coordinates: x, y in cells, z in
    voxels) by a 3-D DDA; each cell touched becomes ``free`` in ``cost`` when its column then has at most
    ``mark_threshold`` marked and at most ``unknown_threshold`` unknown voxels."""
    h, w = columns.shape
    dx, dy, dz = ex - x, ey - y, ez - z
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return
    i, j, m = math.floor(x), math.floor(y), math.floor(z)
    steps = abs(math.floor(ex) - i) + abs(math.floor(ey) - j) + abs(math.floor(ez) - m)
    si = 1 if dx > 0 else -1
    sj = 1 if dy > 0 else -1
    sm = 1 if dz > 0 else -1
    tdx = abs(1.0 / dx) if dx != 0 else np.inf
    tdy = abs(1.0 / dy) if dy != 0 else np.inf
    tdz = abs(1.0 / dz) if dz != 0 else np.inf
    tx = ((i + 1 - x) if dx > 0 else (x - i)) * tdx if dx != 0 else np.inf
    ty = ((j + 1 - y) if dy > 0 else (y - j)) * tdy if dy != 0 else np.inf
    tz = ((m + 1 - z) if dz > 0 else (z - m)) * tdz if dz != 0 else np.inf
    for _ in range(steps + 1):
        if i < 0 or j < 0 or i >= w or j >= h or m < 0 or m >= z_voxels:
            break
        col = np.int64(columns[j, i]) & ~np.int64((1 << m) | (1 << (m + 16)))
        columns[j, i] = col
        if cost[j, i] != free:
            marked = col >> 16
            if popcount16(marked) <= mark_threshold and popcount16((col & 0xFFFF) ^ marked) <= unknown_threshold:
                cost[j, i] = free
        if tx <= ty and tx <= tz:
            i += si
            tx += tdx
        elif ty <= tz:
            j += sj
            ty += tdy
        else:
            m += sm
            tz += tdz


@numba.njit(cache=True, error_model="numpy")
def observe(
    columns: np.ndarray,
    cost: np.ndarray,
    origin: np.ndarray,
    pts: np.ndarray,
    place: np.ndarray,
    base: np.ndarray,
    scale: np.ndarray,
    clearing: bool,
    raytrace_range: float,
    marking: bool,
    obstacle_range: float,
    min_z: float,
    max_z: float,
    mark_threshold: int,
    unknown_threshold: int,
    free: np.uint8,
    lethal: np.uint8,
    flags: np.ndarray,
) -> None:
    """One observation: the sensor at ``origin`` (costmap frame) and its points ``pts`` (N x 3 or wider, any
    strides; m; NaN: skipped) in a frame placed by ``place`` (4 x 3: rows 0-2 the rotation into the costmap frame,
    row 3 the translation); the grid's lowest corner is ``base`` and a voxel ``scale`` (m) in size. ``flags`` is
    scratch (a uint8 per voxel, all 0, and left so).

    Clearing: each voxel where a ray ends — cut at ``raytrace_range`` and where it leaves the grid — is traced once,
    from the origin to that voxel's centre (rays ending in the same voxel trace the same cells). Marking, after it:
    the voxel of each point nearer than ``obstacle_range`` with its height in [``min_z``, ``max_z``]; its cell
    turns ``lethal`` when its column holds more than ``mark_threshold`` marked voxels. One pass over the points
    finds both sets of voxels (each voxel once)."""
    h, w = columns.shape
    nz = flags.shape[0] // (h * w)
    n = pts.shape[0]
    ends = np.empty(n if clearing else 0, dtype=np.int64)
    marks = np.empty(n if marking else 0, dtype=np.int64)
    n_ends = n_marks = 0
    ox, oy, oz = origin[0], origin[1], origin[2]
    lx, ly, lz = base[0] + 1e-6, base[1] + 1e-6, base[2] + 1e-6
    hx, hy, hz = base[0] + w * scale[0] - 1e-6, base[1] + h * scale[1] - 1e-6, base[2] + nz * scale[2] - 1e-6
    rr2, or2 = raytrace_range * raytrace_range, obstacle_range * obstacle_range
    inv0, inv1, inv2 = 1.0 / scale[0], 1.0 / scale[1], 1.0 / scale[2]
    for k in range(n):
        qx, qy, qz = np.float64(pts[k, 0]), np.float64(pts[k, 1]), np.float64(pts[k, 2])
        px = place[0, 0] * qx + place[0, 1] * qy + place[0, 2] * qz + place[3, 0]
        py = place[1, 0] * qx + place[1, 1] * qy + place[1, 2] * qz + place[3, 1]
        pz = place[2, 0] * qx + place[2, 1] * qy + place[2, 2] * qz + place[3, 2]
        dx, dy, dz = px - ox, py - oy, pz - oz
        d2 = dx * dx + dy * dy + dz * dz
        if not math.isfinite(d2):
            continue
        if marking and d2 < or2 and min_z <= pz <= max_z:
            i = math.floor((px - base[0]) * inv0)
            j = math.floor((py - base[1]) * inv1)
            m = math.floor((pz - base[2]) * inv2)
            if 0 <= i < w and 0 <= j < h and 0 <= m < nz:
                key = (m * h + j) * w + i
                if not flags[key] & 2:
                    flags[key] |= 2
                    marks[n_marks] = key
                    n_marks += 1
        if not clearing:
            continue
        # where the ray ends: t = min(1, range cut, the grid's faces) along d; the height cut without a branch
        # (points scattered about the floor would make one unpredictable)
        t = 1.0 if d2 <= rr2 else raytrace_range / math.sqrt(d2)
        tz = ((hz if dz > 0 else lz) - oz) / dz
        t = min(t, tz if dz != 0 else np.inf)
        ex, ey = ox + t * dx, oy + t * dy
        if not (lx <= ex <= hx and ly <= ey <= hy):
            t = min(t, (hx - ox) / dx) if dx > 0 else (min(t, (lx - ox) / dx) if dx < 0 else t)
            t = min(t, (hy - oy) / dy) if dy > 0 else (min(t, (ly - oy) / dy) if dy < 0 else t)
        t = max(t, 0.0)
        i = min(max(math.floor((ox + t * dx - base[0]) * inv0), 0), w - 1)
        j = min(max(math.floor((oy + t * dy - base[1]) * inv1), 0), h - 1)
        m = min(max(math.floor((oz + t * dz - base[2]) * inv2), 0), nz - 1)
        key = (m * h + j) * w + i
        if not flags[key] & 1:
            flags[key] |= 1
            ends[n_ends] = key
            n_ends += 1
    gx, gy, gz = (ox - base[0]) / scale[0], (oy - base[1]) / scale[1], (oz - base[2]) / scale[2]
    for e in range(n_ends):
        key = ends[e]
        flags[key] = 0
        i, j, m = key % w, (key // w) % h, key // (w * h)
        clear_ray(columns, cost, gx, gy, gz, i + 0.5, j + 0.5, m + 0.5, nz, mark_threshold, unknown_threshold, free)
    for e in range(n_marks):
        key = marks[e]
        flags[key] = 0
        i, j, m = key % w, (key // w) % h, key // (w * h)
        col = np.int64(columns[j, i]) | np.int64((1 << m) | (1 << (m + 16)))
        columns[j, i] = col
        if popcount16(col >> 16) > mark_threshold:
            cost[j, i] = lethal
