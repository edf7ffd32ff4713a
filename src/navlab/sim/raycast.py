"""A planar-lidar ray caster over MuJoCo's primitive geoms (Numba), several times faster than ``mj_multiRay``.

The rays of a 2-D lidar lie in its sensor's xy plane. For each geom the caster intersects the geom's
extent with that plane (spheres exactly; boxes and cylinders by the azimuth span of their corners),
turns it into the interval of beam indices that can touch it, and runs the exact ray-shape test
(plane, sphere, box, cylinder) only for those beams. Semantics follow Gazebo: a beam starts at
``range_min`` (a surface entered closer is not seen), hits beyond ``cutoff`` are dropped, no hit is
``inf``. Mesh geoms are not handled here (the simulator casts them with ``mj_multiRay``).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numba import njit

PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
SPHERE = int(mujoco.mjtGeom.mjGEOM_SPHERE)
BOX = int(mujoco.mjtGeom.mjGEOM_BOX)
CYLINDER = int(mujoco.mjtGeom.mjGEOM_CYLINDER)
FAST_TYPES = (PLANE, SPHERE, BOX, CYLINDER)
SPAN_MARGIN = 1e-7  # rad added to each side of a box's or cylinder's azimuth span: far above atan's rounding


@njit(cache=True, inline="always")
def _first(t0: float, t1: float, tmin: float) -> float:
    """The entry distance t0 of an interval [t0, t1] if the ray (starting at tmin) enters there."""
    if t1 < t0 or t0 < tmin:
        return np.inf
    return t0


@njit(cache=True, inline="always")
def _hit(kind: int, size: np.ndarray, p: np.ndarray, d: np.ndarray, tmin: float) -> float:
    """Distance along unit ``d`` from ``p`` (both in the geom frame) to the geom's surface, or inf."""
    if kind == PLANE:
        if d[2] == 0.0:
            return np.inf
        t = -p[2] / d[2]
        if t < tmin:
            return np.inf
        if size[0] > 0 and (abs(p[0] + t * d[0]) > size[0] or abs(p[1] + t * d[1]) > size[1]):
            return np.inf
        return t
    if kind == SPHERE:
        b = p[0] * d[0] + p[1] * d[1] + p[2] * d[2]
        c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - size[0] * size[0]
        disc = b * b - c
        if disc < 0:
            return np.inf
        s = math.sqrt(disc)
        return _first(-b - s, -b + s, tmin)
    if kind == BOX:
        t0, t1 = -np.inf, np.inf
        for k in range(3):
            if d[k] == 0.0:
                if abs(p[k]) > size[k]:
                    return np.inf
                continue
            inv = 1.0 / d[k]
            a = (-size[k] - p[k]) * inv
            b = (size[k] - p[k]) * inv
            if a > b:
                a, b = b, a
            t0 = max(t0, a)
            t1 = min(t1, b)
        return _first(t0, t1, tmin)
    if kind == CYLINDER:
        r, h = size[0], size[1]
        t0, t1 = -np.inf, np.inf
        # slab between the caps
        if d[2] == 0.0:
            if abs(p[2]) > h:
                return np.inf
        else:
            a = (-h - p[2]) / d[2]
            b = (h - p[2]) / d[2]
            if a > b:
                a, b = b, a
            t0, t1 = a, b
        # infinite side surface
        qa = d[0] * d[0] + d[1] * d[1]
        qb = p[0] * d[0] + p[1] * d[1]
        qc = p[0] * p[0] + p[1] * p[1] - r * r
        if qa == 0.0:
            if qc > 0:
                return np.inf
        else:
            disc = qb * qb - qa * qc
            if disc < 0:
                return np.inf
            s = math.sqrt(disc)
            t0 = max(t0, (-qb - s) / qa)
            t1 = min(t1, (-qb + s) / qa)
        return _first(t0, t1, tmin)
    return np.inf


@njit(cache=True, inline="always")
def _lower_bound(kind: int, size: np.ndarray, p: np.ndarray) -> float:
    """A distance (m) no hit on the geom can be nearer than, from ``p`` (the ray origin, geom frame): the
    distance to the geom (box, cylinder, sphere), shrunk by far more than rounding; 0 for a plane."""
    if kind == BOX:
        ex = max(abs(p[0]) - size[0], 0.0)
        ey = max(abs(p[1]) - size[1], 0.0)
        ez = max(abs(p[2]) - size[2], 0.0)
        d = math.sqrt(ex * ex + ey * ey + ez * ez)
    elif kind == CYLINDER:
        er = max(math.sqrt(p[0] * p[0] + p[1] * p[1]) - size[0], 0.0)
        ez = max(abs(p[2]) - size[1], 0.0)
        d = math.sqrt(er * er + ez * ez)
    elif kind == SPHERE:
        d = max(math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - size[0], 0.0)
    else:
        return 0.0
    return d * (1.0 - 1e-9) - 1e-9


@njit(cache=True)
def _nearest_first(origin: np.ndarray, geoms: np.ndarray, geom_type: np.ndarray, geom_size: np.ndarray,
                   geom_xpos: np.ndarray, geom_xmat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(``geoms`` ordered by :func:`_lower_bound` from ``origin``, nearest first; the bounds in that order)."""
    ng = geoms.shape[0]
    order = np.empty(ng, dtype=np.int64)
    bound = np.empty(ng)
    p = np.empty(3)
    for gi in range(ng):
        g = geoms[gi]
        xm = geom_xmat[g]
        r0 = origin[0] - geom_xpos[g, 0]
        r1 = origin[1] - geom_xpos[g, 1]
        r2 = origin[2] - geom_xpos[g, 2]
        for k in range(3):
            p[k] = xm[k] * r0 + xm[3 + k] * r1 + xm[6 + k] * r2
        b = _lower_bound(geom_type[g], geom_size[g], p)
        j = gi  # insertion sort: a few dozen geoms
        while j > 0 and bound[j - 1] > b:
            order[j] = order[j - 1]
            bound[j] = bound[j - 1]
            j -= 1
        order[j] = g
        bound[j] = b
    return order, bound


@njit(cache=True)
def cast_planar(
    origin: np.ndarray,
    rot: np.ndarray,
    cos_a: np.ndarray,
    sin_a: np.ndarray,
    angle_min: float,
    increment: float,
    geoms: np.ndarray,
    geom_type: np.ndarray,
    geom_size: np.ndarray,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    range_min: float,
    cutoff: float,
    out: np.ndarray,
) -> None:
    """Fill ``out`` (n) with ranges of beams ``(cos_a, sin_a)`` in the sensor frame ``rot`` (3×3,
    columns = sensor axes in world) at world ``origin``, evenly spaced from ``angle_min`` by ``increment``.

    Broad phase: each geom's beam interval (its azimuth span); the geoms nearest first, and a beam skips a geom
    no nearer than the hit it already has (the distance to a geom bounds any hit on it from below), so an occluded
    geom costs little; each range is the least over the geoms a beam can hit, as testing them all gives."""
    n = out.shape[0]
    out[:] = np.inf
    u = np.empty(3)
    v = np.empty(3)
    p_loc = np.empty(3)
    d_loc = np.empty(3)
    rel = np.empty(3)
    corner_x = np.empty(8)
    corner_y = np.empty(8)
    two_pi = 2.0 * math.pi
    order, bound = _nearest_first(origin, geoms, geom_type, geom_size, geom_xpos, geom_xmat)
    for gi in range(order.shape[0]):
        g = order[gi]
        nearest = bound[gi]
        kind = geom_type[g]
        xm = geom_xmat[g]
        for k in range(3):
            rel[k] = origin[k] - geom_xpos[g, k]
        for k in range(3):  # origin in the geom frame: R^T (origin - c)
            p_loc[k] = xm[k] * rel[0] + xm[3 + k] * rel[1] + xm[6 + k] * rel[2]
        # beam i in the geom frame is u cos_a[i] + v sin_a[i] (u, v: the sensor's x and y axes)
        for k in range(3):
            u[k] = xm[k] * rot[0, 0] + xm[3 + k] * rot[1, 0] + xm[6 + k] * rot[2, 0]
            v[k] = xm[k] * rot[0, 1] + xm[3 + k] * rot[1, 1] + xm[6 + k] * rot[2, 1]
        size = geom_size[g]
        lo, hi = 0, n - 1
        full = True
        centre = 0.0
        half = 0.0
        if kind == PLANE:
            if abs(u[2]) + abs(v[2]) < 1e-12:
                continue  # the scan plane is parallel to this plane
            if abs(p_loc[2]) > cutoff * math.sqrt(u[2] * u[2] + v[2] * v[2]) * (1.0 + 1e-9):
                continue  # every beam meets this plane beyond the cutoff (a nearly level scan over the floor)
        if kind != PLANE:
            # centre of the geom in the sensor frame
            cx = -(rot[0, 0] * rel[0] + rot[1, 0] * rel[1] + rot[2, 0] * rel[2])
            cy = -(rot[0, 1] * rel[0] + rot[1, 1] * rel[1] + rot[2, 1] * rel[2])
            cz = -(rot[0, 2] * rel[0] + rot[1, 2] * rel[1] + rot[2, 2] * rel[2])
            if kind == SPHERE:
                rb = geom_size[g, 0]
                if abs(cz) >= rb:
                    continue
                rc = math.sqrt(rb * rb - cz * cz)
                dist = math.sqrt(cx * cx + cy * cy)
                if dist - rc > cutoff:
                    continue
                if dist > rc and increment > 0:
                    full = False
                    half = math.asin(rc / dist)
                    centre = math.atan2(cy, cx)
            else:
                # box / cylinder: the azimuth span of its bounding box's corners, seen from the sensor
                ex = geom_size[g, 0]
                ey = geom_size[g, 0] if kind == CYLINDER else geom_size[g, 1]
                ez = geom_size[g, 1] if kind == CYLINDER else geom_size[g, 2]
                zmin, zmax = np.inf, -np.inf
                d2min = np.inf
                rc = math.sqrt(cx * cx + cy * cy)
                ahead = rc > 0.0  # every corner in front of the centre's azimuth: its span needs no atan2 each
                cu = cx / rc if ahead else 1.0
                su = cy / rc if ahead else 0.0
                tmin, tmax = np.inf, -np.inf  # tangents of the corners' azimuths about the centre's
                for corner in range(8):
                    lx = ex if corner & 1 else -ex
                    ly = ey if corner & 2 else -ey
                    lz = ez if corner & 4 else -ez
                    # corner in world relative to the sensor origin, then in the sensor frame
                    wx = xm[0] * lx + xm[1] * ly + xm[2] * lz - rel[0]
                    wy = xm[3] * lx + xm[4] * ly + xm[5] * lz - rel[1]
                    wz = xm[6] * lx + xm[7] * ly + xm[8] * lz - rel[2]
                    sx = rot[0, 0] * wx + rot[1, 0] * wy + rot[2, 0] * wz
                    sy = rot[0, 1] * wx + rot[1, 1] * wy + rot[2, 1] * wz
                    sz = rot[0, 2] * wx + rot[1, 2] * wy + rot[2, 2] * wz
                    zmin = min(zmin, sz)
                    zmax = max(zmax, sz)
                    d2min = min(d2min, sx * sx + sy * sy)
                    corner_x[corner] = sx
                    corner_y[corner] = sy
                    fx = sx * cu + sy * su
                    if fx > 0.0:
                        t = (sy * cu - sx * su) / fx
                        tmin = min(tmin, t)
                        tmax = max(tmax, t)
                    else:
                        ahead = False
                if zmin > 0 or zmax < 0:
                    continue  # entirely above or below the scan plane
                if math.sqrt(d2min) > cutoff + 2 * (ex + ey + ez):  # the same test as the least of the sqrt
                    continue
                if increment > 0:
                    centre = math.atan2(cy, cx)
                    if ahead:  # a span a little wider than the corners' (any beam outside it misses)
                        amin = math.atan(tmin)
                        amax = math.atan(tmax)
                        full = False
                        centre += 0.5 * (amin + amax)
                        half = 0.5 * (amax - amin) + SPAN_MARGIN
                    else:  # a corner abeam or behind: each corner's azimuth, wrapped about the centre's
                        amin, amax = np.inf, -np.inf
                        for corner in range(8):
                            a = math.atan2(corner_y[corner], corner_x[corner]) - centre
                            a = (a + math.pi) % two_pi - math.pi
                            amin = min(amin, a)
                            amax = max(amax, a)
                        if amax - amin < math.pi - 1e-6:
                            full = False
                            centre += 0.5 * (amin + amax)
                            half = 0.5 * (amax - amin) + 1e-9
        for wrap in range(-1, 2):
            if full:
                if wrap != 0:
                    continue
            else:
                a0 = centre - half + wrap * two_pi - angle_min
                a1 = centre + half + wrap * two_pi - angle_min
                lo = max(0, math.ceil(a0 / increment - 1e-9))
                hi = min(n - 1, math.floor(a1 / increment + 1e-9))
            for i in range(lo, hi + 1):
                if out[i] < nearest:
                    continue  # a hit nearer than any point of this geom
                for k in range(3):
                    d_loc[k] = u[k] * cos_a[i] + v[k] * sin_a[i]
                t = _hit(kind, size, p_loc, d_loc, range_min)
                if t < out[i]:
                    out[i] = t
    for i in range(n):
        if out[i] > cutoff:
            out[i] = np.inf


@njit(cache=True)
def finish_ranges(
    dist: np.ndarray,
    normals: np.ndarray,
    mean: float,
    stddev: float,
    range_min: float,
    range_max: float,
    out: np.ndarray,
) -> None:
    """``out`` (float32) = hits + mean + stddev·normals clamped to [range_min, range_max]; misses stay inf."""
    for i in range(dist.shape[0]):
        r = dist[i]
        if r <= range_max:
            r += mean + (stddev * normals[i] if normals.shape[0] else 0.0)
            r = min(max(r, range_min), range_max)
        else:
            r = np.inf
        out[i] = r


@njit(cache=True)
def scan_planar(
    origin: np.ndarray,
    rot: np.ndarray,
    cos_a: np.ndarray,
    sin_a: np.ndarray,
    angle_min: float,
    increment: float,
    geoms: np.ndarray,
    geom_type: np.ndarray,
    geom_size: np.ndarray,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    range_min: float,
    range_max: float,
    normals: np.ndarray,
    mean: float,
    stddev: float,
    out: np.ndarray,
) -> None:
    """:func:`cast_planar` then :func:`finish_ranges` in one call (a lidar's whole scan, float32 ``out``): the
    same values as the two calls, one dispatch from Python instead of two."""
    dist = np.empty(out.shape[0])
    cast_planar(
        origin, rot, cos_a, sin_a, angle_min, increment, geoms, geom_type, geom_size, geom_xpos, geom_xmat,
        range_min, range_max, dist,
    )  # fmt: skip
    finish_ranges(dist, normals, mean, stddev, range_min, range_max, out)


#: the exact ray-shape test (a compiled function), for the 3-D casters in :mod:`navlab.sim.raycast3d`
ray_hit = _hit


def multiray(
    m: mujoco.MjModel,
    d: mujoco.MjData,
    range_min: float,
    range_max: float,
    rot: np.ndarray,
    pnt: np.ndarray,
    angles: np.ndarray,
    groups: np.ndarray,
) -> np.ndarray:
    """Ranges (m) of planar beams by MuJoCo's own ``mj_multiRay`` over the geom ``groups`` (meshes too).

    ``pnt`` and ``rot`` are the sensor's world position and rotation matrix, ``angles`` the beams'
    (cos, sin) rows in the sensor frame. Gazebo semantics as :func:`cast_planar`: a beam starts at
    ``range_min``, returns beyond ``range_max`` and misses are ``inf``.
    """
    n = angles.shape[1]
    vec = angles.T @ rot[:, :2].T
    dist = np.empty(n)
    geomid = np.empty(n, dtype=np.int32)
    mujoco.mj_multiRay(m, d, pnt, vec.ravel(), groups, 1, -1, geomid, dist, None, n, range_max)
    dist[geomid < 0] = np.inf
    one = np.empty(1, dtype=np.int32)
    for i in np.flatnonzero(dist < range_min):  # Gazebo's rays begin at range_min: look past
        r = mujoco.mj_ray(m, d, pnt + range_min * vec[i], vec[i], groups, 1, -1, one)
        dist[i] = range_min + r if r >= 0 else np.inf
    dist[dist > range_max] = np.inf
    return dist
