"""Ray casting for grids of rays in 3-D over MuJoCo's primitives (Numba): range cones, and the reference that the
depth buffer (:mod:`navlab.sim.raster`) and the lidar sweep (:mod:`navlab.sim.sweep`) are tested against, whose
grid blocks (:func:`_block`) they share.

A sensor's rays form a grid: ``rows`` x ``cols`` unit directions in the sensor frame (x forward, y left, z up).
For each geom the caster bounds the block of the grid that can touch it — for a pinhole grid (``PINHOLE``)
from the image coordinates of its bounding box's corners, for an angle grid (``SPHERICAL``) from the azimuths
of those corners and the elevation cone of its bounding sphere — and runs the exact ray-shape test
(:data:`navlab.sim.raycast.ray_hit`: plane, sphere, box, cylinder) only there. Geoms that straddle the sensor
(or lie behind a pinhole camera's plane) are tested against every ray. Distances are along each ray, from
``tmin``; no hit within ``tmax`` is ``inf``. Meshes are left to ``mj_multiRay`` (see :mod:`navlab.sim.sensors3d`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from navlab.sim.raycast import BOX, CYLINDER, PLANE, ray_hit

PINHOLE = 0  # grid params: (f, u0, v0): col u = u0 - f y/x, row v = v0 - f z/x (0-based pixel centres)
SPHERICAL = 1  # grid params: (az_min, d_az, el_min, d_el): col j at az_min + j d_az, row i at el_min + i d_el
ALL = 2  # no culling (a handful of rays)


@njit(cache=True)
def _half_extents(kind: int, size: np.ndarray) -> tuple[float, float, float]:
    if kind == BOX:
        return size[0], size[1], size[2]
    if kind == CYLINDER:
        return size[0], size[0], size[1]
    return size[0], size[0], size[0]


@njit(cache=True)
def _plane_rows(
    centre: np.ndarray,
    xm: np.ndarray,
    rot: np.ndarray,
    origin: np.ndarray,
    params: np.ndarray,
    rows: int,
    cols: int,
    bounds: np.ndarray,
) -> bool:
    """The image rows whose rays can reach a plane (the camera's side of it faces them): below the horizon of a
    floor. Pixel (u, v)'s ray is f x - (u - u0) y - (v - v0) z in the sensor frame (x forward, y left, z up)."""
    nx, ny, nz = xm[2], xm[5], xm[8]  # the plane's normal in the world
    side = (origin[0] - centre[0]) * nx + (origin[1] - centre[1]) * ny + (origin[2] - centre[2]) * nz
    if side == 0.0:
        return True
    a = params[0] * (rot[0, 0] * nx + rot[1, 0] * ny + rot[2, 0] * nz)
    b = rot[0, 1] * nx + rot[1, 1] * ny + rot[2, 1] * nz
    c = rot[0, 2] * nx + rot[1, 2] * ny + rot[2, 2] * nz
    half = abs(b) * (cols - 1) / 2.0
    # rays towards the plane: a - b (u - u0) - c (v - v0) < 0 (camera above; > 0 below) for some u
    lim = a - half if side > 0 else a + half  # the best u's value of a - b (u - u0)
    sign = 1.0 if side > 0 else -1.0
    # need sign * (lim - c (v - v0)) < 0
    if c == 0.0:
        return sign * lim < 0
    v_edge = params[2] + lim / c
    if sign * c > 0:  # rows below v_edge... solve sign*(lim - c dv) < 0  <=>  sign*c*dv > sign*lim
        r0 = math.floor(v_edge) - 1
        bounds[0] = max(r0, 0)
    else:
        r1 = math.ceil(v_edge) + 1
        bounds[1] = min(r1, rows - 1)
    return bounds[0] <= bounds[1]


@njit(cache=True)
def _block(
    kind: int,
    size: np.ndarray,
    centre: np.ndarray,
    xm: np.ndarray,
    rot: np.ndarray,
    origin: np.ndarray,
    mode: int,
    params: np.ndarray,
    rows: int,
    cols: int,
    bounds: np.ndarray,
) -> bool:
    """Fill ``bounds`` (r0, r1, c0, c1, wrap) with the grid block that may see the geom; False if none."""
    bounds[0], bounds[1], bounds[2], bounds[3], bounds[4] = 0, rows - 1, 0, cols - 1, 0
    if mode == PINHOLE and kind == PLANE:
        return _plane_rows(centre, xm, rot, origin, params, rows, cols, bounds)
    if mode == ALL or kind == PLANE:
        return True
    ex, ey, ez = _half_extents(kind, size)
    radius = math.sqrt(ex * ex + ey * ey + ez * ez)
    # centre in the sensor frame
    rel0, rel1, rel2 = centre[0] - origin[0], centre[1] - origin[1], centre[2] - origin[2]
    sx = rot[0, 0] * rel0 + rot[1, 0] * rel1 + rot[2, 0] * rel2
    sy = rot[0, 1] * rel0 + rot[1, 1] * rel1 + rot[2, 1] * rel2
    sz = rot[0, 2] * rel0 + rot[1, 2] * rel1 + rot[2, 2] * rel2
    dist = math.sqrt(sx * sx + sy * sy + sz * sz)
    if dist <= radius * 1.000001:
        return True  # the sensor may be inside: every ray
    umin, umax, vmin, vmax = np.inf, -np.inf, np.inf, -np.inf
    ac = math.atan2(sy, sx)
    pts = np.empty((8, 3))
    for corner in range(8):
        lx = ex if corner & 1 else -ex
        ly = ey if corner & 2 else -ey
        lz = ez if corner & 4 else -ez
        wx = xm[0] * lx + xm[1] * ly + xm[2] * lz + rel0
        wy = xm[3] * lx + xm[4] * ly + xm[5] * lz + rel1
        wz = xm[6] * lx + xm[7] * ly + xm[8] * lz + rel2
        pts[corner, 0] = rot[0, 0] * wx + rot[1, 0] * wy + rot[2, 0] * wz
        pts[corner, 1] = rot[0, 1] * wx + rot[1, 1] * wy + rot[2, 1] * wz
        pts[corner, 2] = rot[0, 2] * wx + rot[1, 2] * wy + rot[2, 2] * wz
    if mode == PINHOLE:
        # the box clipped to x >= EPS: its front corners and where its edges cross that plane
        eps = 1e-3
        front = 0
        for corner in range(8):
            if pts[corner, 0] >= eps:
                front += 1
                u = params[1] - params[0] * pts[corner, 1] / pts[corner, 0]
                v = params[2] - params[0] * pts[corner, 2] / pts[corner, 0]
                umin, umax, vmin, vmax = min(umin, u), max(umax, u), min(vmin, v), max(vmax, v)
        if front == 0:
            return False  # wholly behind the camera
        if front < 8:
            for a in range(8):
                for bit in (1, 2, 4):
                    b = a | bit
                    if b == a or (pts[a, 0] >= eps) == (pts[b, 0] >= eps):
                        continue
                    s = (eps - pts[a, 0]) / (pts[b, 0] - pts[a, 0])
                    py = pts[a, 1] + s * (pts[b, 1] - pts[a, 1])
                    pz = pts[a, 2] + s * (pts[b, 2] - pts[a, 2])
                    u = params[1] - params[0] * py / eps
                    v = params[2] - params[0] * pz / eps
                    umin, umax, vmin, vmax = min(umin, u), max(umax, u), min(vmin, v), max(vmax, v)
    else:
        for corner in range(8):
            cx, cy = pts[corner, 0], pts[corner, 1]
            if cx * cx + cy * cy < 1e-12:
                return True
            u = (math.atan2(cy, cx) - ac + math.pi) % (2 * math.pi) - math.pi  # azimuth relative to the centre
            umin, umax = min(umin, u), max(umax, u)
    if mode == PINHOLE:
        c0, c1 = math.ceil(umin - 1e-9), math.floor(umax + 1e-9)
        r0, r1 = math.ceil(vmin - 1e-9), math.floor(vmax + 1e-9)
        if c1 < 0 or c0 > cols - 1 or r1 < 0 or r0 > rows - 1:
            return False
        bounds[0], bounds[1], bounds[2], bounds[3] = max(r0, 0), min(r1, rows - 1), max(c0, 0), min(c1, cols - 1)
        return True
    # angle grid: azimuth span of the corners (if the sensor is outside the footprint), elevation cone of the sphere
    half = math.asin(min(1.0, radius / dist))
    el_c = math.asin(max(-1.0, min(1.0, sz / dist)))
    if params[3] > 0:
        r0 = math.ceil((el_c - half - params[2]) / params[3] - 1e-9)
        r1 = math.floor((el_c + half - params[2]) / params[3] + 1e-9)
        if r1 < 0 or r0 > rows - 1:
            return False
        bounds[0], bounds[1] = max(r0, 0), min(r1, rows - 1)
    if umax - umin < math.pi - 1e-6 and params[1] > 0:
        a0 = ac + umin - params[0]
        a1 = ac + umax - params[0]
        bounds[2] = math.ceil(a0 / params[1] - 1e-9)
        bounds[3] = math.floor(a1 / params[1] + 1e-9)
        bounds[4] = 1  # columns may wrap around 2 pi
    return True


@njit(cache=True)
def _lower_bound(kind: int, size: np.ndarray, p: np.ndarray) -> float:
    """A lower bound (m) of any ray's distance from ``p`` (geom frame) to the geom: its distance to the shape's box."""
    if kind == PLANE:
        return abs(p[2])
    ex, ey, ez = _half_extents(kind, size)
    dx = max(abs(p[0]) - ex, 0.0)
    dy = max(abs(p[1]) - ey, 0.0)
    dz = max(abs(p[2]) - ez, 0.0)
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, inline="always")
def in_geom_frame(
    origin: np.ndarray, rot: np.ndarray, centre: np.ndarray, xm: np.ndarray, p: np.ndarray, m: np.ndarray
) -> None:
    """The sensor (at world ``origin``, axes the columns of ``rot``) in the frame of a geom at ``centre`` turned by
    ``xm`` (row-major 3x3): ``p`` = its origin there, ``m[k, a]`` = component k of its axis a there."""
    rx, ry, rz = origin[0] - centre[0], origin[1] - centre[1], origin[2] - centre[2]
    for k in range(3):
        p[k] = xm[k] * rx + xm[3 + k] * ry + xm[6 + k] * rz
        for a in range(3):
            m[k, a] = xm[k] * rot[0, a] + xm[3 + k] * rot[1, a] + xm[6 + k] * rot[2, a]


@njit(cache=True)
def cast_grid(
    origin: np.ndarray,
    rot: np.ndarray,
    dirs: np.ndarray,
    rows: int,
    cols: int,
    mode: int,
    params: np.ndarray,
    geoms: np.ndarray,
    geom_type: np.ndarray,
    geom_size: np.ndarray,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    tmin: float,
    tmax: float,
    out: np.ndarray,
) -> None:
    """``out`` (rows*cols) = distance (m) along each ray ``dirs`` (rows*cols x 3, unit, sensor frame ``rot`` whose
    columns are the sensor axes in world, at world ``origin``) to the nearest geom of ``geoms``; inf if none.

    Each ray tries the geoms whose grid block holds it, nearest first, and stops at the first geom that cannot be
    nearer than the hit it has (occlusion: a wall behind a box is not tested for the box's pixels)."""
    ng = geoms.shape[0]
    blocks = np.zeros((ng, 8), dtype=np.int64)  # r0, r1, then up to three column intervals (lo, hi)
    near = np.full(ng, np.inf)
    p_loc = np.empty((ng, 3))
    m = np.empty((ng, 3, 3))  # sensor axes in each geom's frame
    bounds = np.zeros(5, dtype=np.int64)
    period = math.floor(2 * math.pi / params[1] + 0.5) if mode == SPHERICAL and params[1] > 0 else 0
    for gi in range(ng):
        g = geoms[gi]
        kind = geom_type[g]
        xm = geom_xmat[g]
        if not _block(kind, geom_size[g], geom_xpos[g], xm, rot, origin, mode, params, rows, cols, bounds):
            continue
        in_geom_frame(origin, rot, geom_xpos[g], xm, p_loc[gi], m[gi])
        near[gi] = _lower_bound(kind, geom_size[g], p_loc[gi])
        blocks[gi, 0], blocks[gi, 1] = bounds[0], bounds[1]
        for w in range(3):
            blocks[gi, 2 + 2 * w], blocks[gi, 3 + 2 * w] = 1, 0  # empty
        if bounds[4] == 0:
            blocks[gi, 2], blocks[gi, 3] = bounds[2], bounds[3]
        else:  # azimuths wrap around: the block and its copies one turn either side (one column of slack)
            for w in range(3):
                pad = 0 if w == 1 else 1
                lo = max(bounds[2] + (w - 1) * period - pad, 0)
                hi = min(bounds[3] + (w - 1) * period + pad, cols - 1)
                blocks[gi, 2 + 2 * w], blocks[gi, 3 + 2 * w] = lo, hi
    order = np.argsort(near)
    live = 0
    while live < ng and near[order[live]] < np.inf:
        live += 1
    kinds = np.empty(live, dtype=np.int64)
    sizes = np.empty((live, 3))
    near_o = np.empty(live)
    blocks_o = np.empty((live, 8), dtype=np.int64)
    m_o = np.empty((live, 3, 3))
    p_o = np.empty((live, 3))
    for j in range(live):  # the live geoms, nearest first, in contiguous arrays
        gi = order[j]
        kinds[j] = geom_type[geoms[gi]]
        sizes[j] = geom_size[geoms[gi]]
        near_o[j] = near[gi]
        blocks_o[j] = blocks[gi]
        m_o[j] = m[gi]
        p_o[j] = p_loc[gi]
    d_loc = np.empty(3)
    for r in range(rows):
        for c in range(cols):
            i = r * cols + c
            best = np.inf
            dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
            for j in range(live):
                if near_o[j] >= best:
                    break
                if r < blocks_o[j, 0] or r > blocks_o[j, 1]:
                    continue
                if not (
                    (blocks_o[j, 2] <= c <= blocks_o[j, 3])
                    or (blocks_o[j, 4] <= c <= blocks_o[j, 5])
                    or (blocks_o[j, 6] <= c <= blocks_o[j, 7])
                ):
                    continue
                for k in range(3):
                    d_loc[k] = m_o[j, k, 0] * dx + m_o[j, k, 1] * dy + m_o[j, k, 2] * dz
                t = ray_hit(kinds[j], sizes[j], p_o[j], d_loc, tmin)
                if t < best:
                    best = t
            out[i] = best if best <= tmax else np.inf


def pinhole_dirs(width: int, height: int, focal: float) -> np.ndarray:
    """Unit ray directions (height*width x 3, sensor frame: x forward, y left, z up) through the pixel centres of
    a pinhole camera of focal length ``focal`` (px) with its principal point at the image centre."""
    u = np.arange(width) - (width - 1) / 2.0
    v = np.arange(height) - (height - 1) / 2.0
    uu, vv = np.meshgrid(u, v)
    d = np.stack([np.full(uu.shape, focal), -uu, -vv], axis=-1).reshape(-1, 3)
    return np.ascontiguousarray(d / np.linalg.norm(d, axis=1, keepdims=True))


def spherical_dirs(azimuths: np.ndarray, elevations: np.ndarray) -> np.ndarray:
    """Unit directions (len(elevations)*len(azimuths) x 3), row-major by elevation (ring) then azimuth."""
    az, el = np.meshgrid(azimuths, elevations)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1).reshape(-1, 3)
    return np.ascontiguousarray(d)
