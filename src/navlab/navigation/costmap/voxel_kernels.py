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
def trace_column(
    clear: np.ndarray,
    w: int,
    x: float,
    y: float,
    z: float,
    ends: np.int64,
    ci: int,
    cj: int,
    rays: np.ndarray,
    ray_t: np.ndarray,
) -> None:
    """Set, in ``clear`` (a uint32 per cell of a ``w`` cells wide grid, row-major), bit ``m`` of the cell of each
    voxel (i, j, m) on the rays from (x, y, z) (continuous voxel coordinates: x, y in cells, z in voxels; in the
    grid) to the centres of the voxels ``ends`` (bit m: voxel m) of the column (``ci``, ``cj``), as a 3-D DDA
    finds them ray by ray (ties: x before y before z; each ray takes exactly the steps between its two voxels).
    The rays share one walk across the cells, for their x and y are the same; only their heights differ, stepped
    ray by ray where one of them crosses a voxel face before the walk's next cell face. ``rays`` (16 x 3 int64:
    voxel, step, end) and ``ray_t`` (16 x 2: next face, face spacing) are scratch."""
    dx, dy = ci + 0.5 - x, cj + 0.5 - y
    i, j, m0 = math.floor(x), math.floor(y), math.floor(z)
    n = 0
    here = 0  # the rays' voxels in the cell being walked (a bit each)
    tz = np.inf  # the first voxel face any ray crosses next
    for m in range(16):
        dz = m + 0.5 - z
        if not (ends >> m) & 1 or (dx == 0.0 and dy == 0.0 and dz == 0.0):
            continue
        dt = abs(1.0 / dz) if dz != 0 else np.inf
        t = ((m0 + 1 - z) if dz > 0 else (z - m0)) * dt if dz != 0 else np.inf
        rays[n, 0], rays[n, 1], rays[n, 2] = m0, 1 if dz > 0 else -1, m
        ray_t[n, 0], ray_t[n, 1] = t, dt
        here = 1 << m0
        tz = min(tz, t)
        n += 1
    if n == 0:
        return
    si = 1 if dx > 0 else -1
    sj = 1 if dy > 0 else -1
    tdx = abs(1.0 / dx) if dx != 0 else np.inf
    tdy = abs(1.0 / dy) if dy != 0 else np.inf
    tx = ((i + 1 - x) if dx > 0 else (x - i)) * tdx if dx != 0 else np.inf
    ty = ((j + 1 - y) if dy > 0 else (y - j)) * tdy if dy != 0 else np.inf
    for _ in range(abs(ci - i) + abs(cj - j)):
        t_next = min(tx, ty)
        bits = here
        if tz < t_next:  # some ray goes up or down before the walk leaves the cell
            here, tz = 0, np.inf
            for r in range(n):
                m, t = rays[r, 0], ray_t[r, 0]
                while t < t_next:
                    m += rays[r, 1]
                    t += ray_t[r, 1]
                    bits |= 1 << m
                rays[r, 0], ray_t[r, 0] = m, t
                here |= 1 << m
                tz = min(tz, t)
        clear[j * w + i] |= np.uint32(bits)
        along_x = tx <= ty  # selects, not a branch: which way a ray turns next is not predictable
        i += si if along_x else 0
        j += 0 if along_x else sj
        tx = tx + tdx if along_x else tx
        ty = ty if along_x else ty + tdy
    bits = here  # the column of the ends: each ray on to its voxel
    for r in range(n):
        m = rays[r, 0]
        while m != rays[r, 2]:
            m += rays[r, 1]
            bits |= 1 << m
    clear[j * w + i] |= np.uint32(bits)


CHUNK = 512  # points whose voxels observe() works out at a time


@numba.njit(cache=True, error_model="numpy")
def _chunk_keys(
    xyz: np.ndarray,
    n: int,
    place: np.ndarray,
    origin: np.ndarray,
    base: np.ndarray,
    scale: np.ndarray,
    size: np.ndarray,
    ranges: np.ndarray,
    marking: bool,
    clearing: bool,
    mark_key: np.ndarray,
    end_key: np.ndarray,
) -> None:
    """For the first ``n`` points of ``xyz`` (3 x CHUNK, m): ``mark_key`` the cell * 16 + voxel a point marks,
    ``end_key`` that of the voxel its ray ends in (both -1: none); see :func:`observe` (``size``: w, h, nz;
    ``ranges``: raytrace range and its square, obstacle range squared, min_z, max_z). Selects instead of branches
    (half the time of the branching loop on a depth camera's clouds, whose points scatter about the floor and the
    grid's faces); floats are clamped into the grid's range before they become integers."""
    r00, r01, r02, r10, r11, r12 = place[0, 0], place[0, 1], place[0, 2], place[1, 0], place[1, 1], place[1, 2]
    r20, r21, r22, t0, t1, t2 = place[2, 0], place[2, 1], place[2, 2], place[3, 0], place[3, 1], place[3, 2]
    ox, oy, oz = origin[0], origin[1], origin[2]
    bx, by, bz = base[0], base[1], base[2]
    inv0, inv1, inv2 = 1.0 / scale[0], 1.0 / scale[1], 1.0 / scale[2]
    fw, fh, fnz = size[0], size[1], size[2]
    w = np.int64(fw)
    lx, ly, lz = bx + 1e-6, by + 1e-6, bz + 1e-6
    hx, hy, hz = bx + fw * scale[0] - 1e-6, by + fh * scale[1] - 1e-6, bz + fnz * scale[2] - 1e-6
    rr, rr2, or2, min_z, max_z = ranges[0], ranges[1], ranges[2], ranges[3], ranges[4]
    xs, ys, zs = xyz[0], xyz[1], xyz[2]
    for u in range(np.uint64(n)):
        qx, qy, qz = xs[u], ys[u], zs[u]
        px = r00 * qx + r01 * qy + r02 * qz + t0
        py = r10 * qx + r11 * qy + r12 * qz + t1
        pz = r20 * qx + r21 * qy + r22 * qz + t2
        dx, dy, dz = px - ox, py - oy, pz - oz
        d2 = dx * dx + dy * dy + dz * dz
        finite = d2 < np.inf
        fi = min(max((px - bx) * inv0, -1.0), fw) if finite else -1.0
        fj = min(max((py - by) * inv1, -1.0), fh) if finite else -1.0
        fm = min(max((pz - bz) * inv2, -1.0), fnz) if finite else -1.0
        i, j, m = np.int64(math.floor(fi)), np.int64(math.floor(fj)), np.int64(math.floor(fm))
        ok = marking & finite & (d2 < or2) & (min_z <= pz) & (pz <= max_z)
        ok = ok & (i >= 0) & (i < w) & (j >= 0) & (j < np.int64(fh)) & (m >= 0) & (m < np.int64(fnz))
        mark_key[u] = (j * w + i) * 16 + m if ok else -1
        # where the ray ends: t = min(1, range cut, the grid's faces) along d
        t = 1.0 if d2 <= rr2 else rr / math.sqrt(d2)
        tz = ((hz if dz > 0 else lz) - oz) / dz
        t = min(t, tz if dz != 0 else np.inf)
        ex, ey = ox + t * dx, oy + t * dy
        fx = (hx - ox) / dx if dx > 0 else ((lx - ox) / dx if dx < 0 else np.inf)
        fy = (hy - oy) / dy if dy > 0 else ((ly - oy) / dy if dy < 0 else np.inf)
        cut = min(min(t, fx), fy)
        t = t if (lx <= ex) & (ex <= hx) & (ly <= ey) & (ey <= hy) else cut
        t = max(t, 0.0)
        ei = min(max(math.floor((ox + t * dx - bx) * inv0), 0.0), fw - 1.0) if finite else 0.0
        ej = min(max(math.floor((oy + t * dy - by) * inv1), 0.0), fh - 1.0) if finite else 0.0
        em = min(max(math.floor((oz + t * dz - bz) * inv2), 0.0), fnz - 1.0) if finite else 0.0
        key = (np.int64(ej) * w + np.int64(ei)) * 16 + np.int64(em)
        end_key[u] = key if clearing & finite else -1


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
    nz: int,
    seen: np.ndarray,
    clear: np.ndarray,
) -> None:
    """One observation: the sensor at ``origin`` (costmap frame) and its points ``pts`` (N x 3 or wider, any
    strides; m; NaN: skipped) in a frame placed by ``place`` (4 x 3: rows 0-2 the rotation into the costmap frame,
    row 3 the translation); the grid (``nz`` voxels a column) has its lowest corner at ``base`` and voxels
    ``scale`` (m) in size. ``seen`` and ``clear`` are scratch (a uint32 per cell each; all 0, and left so).

    Clearing: each voxel where a ray ends — cut at ``raytrace_range`` and where it leaves the grid — is traced once,
    from the origin to that voxel's centre (rays ending in the same voxel trace the same cells; none when the
    origin lies outside the grid), and each cell touched turns ``free`` when its column then has at most
    ``mark_threshold`` marked and at most ``unknown_threshold`` unknown voxels. Marking, after it: the voxel of
    each point nearer than ``obstacle_range`` with its height in [``min_z``, ``max_z``]; its cell turns ``lethal``
    when its column holds more than ``mark_threshold`` marked voxels. One pass over the points finds both sets of
    voxels, per cell (``seen``: bit m a ray's end, bit m + 16 a mark)."""
    h, w = columns.shape
    n = pts.shape[0]
    end_cells = np.empty(min(n, h * w) if clearing else 0, dtype=np.int64)
    mark_cells = np.empty(min(n, h * w) if marking else 0, dtype=np.int64)
    n_ends = n_marks = 0
    ox, oy, oz = origin[0], origin[1], origin[2]
    bx, by, bz = base[0], base[1], base[2]
    size = np.array([w, h, nz], dtype=np.float64)
    ranges = np.array([raytrace_range, raytrace_range * raytrace_range, obstacle_range * obstacle_range, min_z, max_z])
    mark_key = np.empty(CHUNK, dtype=np.int64)
    end_key = np.empty(CHUNK, dtype=np.int64)
    xyz = np.empty((3, CHUNK))  # the chunk's points, contiguous (the cloud's may be strided)
    for k0 in range(0, n, CHUNK):
        count = min(CHUNK, n - k0)
        for u in range(count):
            xyz[0, u], xyz[1, u], xyz[2, u] = pts[k0 + u, 0], pts[k0 + u, 1], pts[k0 + u, 2]
        _chunk_keys(xyz, count, place, origin, base, scale, size, ranges, marking, clearing, mark_key, end_key)
        for u in range(count):  # each voxel once, per cell: bit m an end, bit m + 16 a mark
            key = mark_key[u]
            if key >= 0:
                cell = key >> 4
                was = seen[cell]
                bit = np.uint32(1) << np.uint32((key & 15) + 16)
                if not was & bit:
                    if was < 65536:
                        mark_cells[n_marks] = cell
                        n_marks += 1
                    seen[cell] = was | bit
            key = end_key[u]
            if key >= 0:
                cell = key >> 4
                was = seen[cell]
                bit = np.uint32(1) << np.uint32(key & 15)
                if not was & bit:
                    if not was & 0xFFFF:
                        end_cells[n_ends] = cell
                        n_ends += 1
                    seen[cell] = was | bit
    gx, gy, gz = (ox - bx) / scale[0], (oy - by) / scale[1], (oz - bz) / scale[2]
    oi, oj, om = math.floor(gx), math.floor(gy), math.floor(gz)
    inside = 0 <= oi < w and 0 <= oj < h and 0 <= om < nz  # else no ray traces a voxel
    # every ray's voxels gathered per cell first, then each cell touched cleared once: clearing only takes voxels
    # away, so a cell that would turn free at some touch is free after the last, as when clearing ray by ray
    rays = np.empty((16, 3), dtype=np.int64)
    ray_t = np.empty((16, 2))
    i0 = i1 = min(max(oi, 0), w - 1)
    j0 = j1 = min(max(oj, 0), h - 1)
    for e in range(n_ends):
        cell = end_cells[e]
        ends = seen[cell] & np.uint32(0xFFFF)
        seen[cell] ^= ends
        if inside:
            i, j = cell % w, cell // w
            i0, i1, j0, j1 = min(i0, i), max(i1, i), min(j0, j), max(j1, j)
            trace_column(clear, w, gx, gy, gz, np.int64(ends), i, j, rays, ray_t)
    if inside and n_ends:
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                bits = clear[j * w + i]
                if bits == 0:
                    continue
                clear[j * w + i] = 0
                col = np.int64(columns[j, i]) & ~np.int64(bits | (bits << np.uint32(16)))
                columns[j, i] = col
                marked = col >> 16
                unknown = (col & 0xFFFF) ^ marked
                if popcount16(marked) <= mark_threshold and popcount16(unknown) <= unknown_threshold:
                    cost[j, i] = free
    for e in range(n_marks):
        cell = mark_cells[e]
        bits = np.int64(seen[cell] >> np.uint32(16))
        seen[cell] = 0
        i, j = cell % w, cell // w
        col = np.int64(columns[j, i]) | bits | (bits << 16)
        columns[j, i] = col
        if popcount16(col >> 16) > mark_threshold:
            cost[j, i] = lethal
