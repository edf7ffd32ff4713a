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


@numba.njit(cache=True)
def observe(
    columns: np.ndarray,
    cost: np.ndarray,
    origin: np.ndarray,
    pts: np.ndarray,
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
    seen: np.ndarray,
) -> None:
    """One observation: the sensor at ``origin`` and its points ``pts`` (N x 3, m, NaN: skipped), both in the
    costmap frame; the grid's lowest corner is ``base`` and a voxel ``scale`` (m) in size. ``seen`` is scratch
    (one flag per voxel, all false, and left so).

    Clearing: each voxel where a ray ends — cut at ``raytrace_range`` and where it leaves the grid — is traced once,
    from the origin to that voxel's centre (rays ending in the same voxel trace the same cells). Marking, after it:
    the voxel of each point nearer than ``obstacle_range`` with its height in [``min_z``, ``max_z``]; its cell
    turns ``lethal`` when its column holds more than ``mark_threshold`` marked voxels."""
    h, w = columns.shape
    nz = seen.shape[0] // (h * w)
    dims = (w, h, nz)
    n = pts.shape[0]
    if clearing:
        ends = np.empty(n, dtype=np.int64)
        count = 0
        lo = np.empty(3)
        hi = np.empty(3)
        for a in range(3):
            lo[a] = base[a] + 1e-6
            hi[a] = base[a] + dims[a] * scale[a] - 1e-6
        r2 = raytrace_range * raytrace_range
        for k in range(n):
            px, py, pz = pts[k, 0], pts[k, 1], pts[k, 2]
            dx, dy, dz = px - origin[0], py - origin[1], pz - origin[2]
            if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(dz)):
                continue
            d2 = dx * dx + dy * dy + dz * dz
            if not (d2 <= r2 and lo[0] <= px <= hi[0] and lo[1] <= py <= hi[1] and lo[2] <= pz <= hi[2]):
                t = 1.0 if d2 <= r2 else raytrace_range / math.sqrt(d2)
                for a, da in ((0, dx), (1, dy), (2, dz)):
                    if da > 0:
                        t = min(t, (hi[a] - origin[a]) / da)
                    elif da < 0:
                        t = min(t, (lo[a] - origin[a]) / da)
                t = max(t, 0.0)
                px, py, pz = origin[0] + t * dx, origin[1] + t * dy, origin[2] + t * dz
            i = min(max(math.floor((px - base[0]) / scale[0]), 0), w - 1)
            j = min(max(math.floor((py - base[1]) / scale[1]), 0), h - 1)
            m = min(max(math.floor((pz - base[2]) / scale[2]), 0), nz - 1)
            key = (m * h + j) * w + i
            if not seen[key]:
                seen[key] = True
                ends[count] = key
                count += 1
        ox, oy = (origin[0] - base[0]) / scale[0], (origin[1] - base[1]) / scale[1]
        oz = (origin[2] - base[2]) / scale[2]
        for e in range(count):
            key = ends[e]
            seen[key] = False
            i, j, m = key % w, (key // w) % h, key // (w * h)
            clear_ray(columns, cost, ox, oy, oz, i + 0.5, j + 0.5, m + 0.5, nz, mark_threshold, unknown_threshold, free)
    if marking:
        r2 = obstacle_range * obstacle_range
        for k in range(n):
            x, y, z = pts[k, 0], pts[k, 1], pts[k, 2]
            dx, dy, dz = x - origin[0], y - origin[1], z - origin[2]
            if not (dx * dx + dy * dy + dz * dz < r2 and min_z <= z <= max_z):
                continue  # NaN fails too
            i = math.floor((x - base[0]) / scale[0])
            j = math.floor((y - base[1]) / scale[1])
            m = math.floor((z - base[2]) / scale[2])
            if i < 0 or j < 0 or m < 0 or i >= w or j >= h or m >= nz:
                continue
            col = np.int64(columns[j, i]) | np.int64((1 << m) | (1 << (m + 16)))
            columns[j, i] = col
            if popcount16(col >> 16) > mark_threshold:
                cost[j, i] = lethal
