"""Depth images by drawing the world's shapes into a depth buffer (Numba): exact depth per pixel, cost per shape.

A pinhole camera's pixel (row r, column c) looks along D = (1, -(c - u0)/f, -(r - v0)/f) in the sensor frame (x
forward, y left, z up), so the point s D lies at depth s (m) along the optical axis; in a geom's frame D is affine
in (r, c). Each primitive geom (plane, box, sphere, cylinder) is drawn only over the pixels its projection can cover:

- a flat face (a box face turned towards the camera, a plane, a cylinder's cap): its outline clipped at the near
  plane and projected; row by row the columns between its edges (with slack), and per pixel the exact crossing of
  that pixel's ray with the face's plane, kept if it lies on the face;
- a curved surface (a sphere, a cylinder's side): the projection of its bounding box, per pixel the nearer root.

A pixel keeps the nearest surface whose distance along the unit ray is at least ``near`` (Gazebo's rays begin at
the near clip), as :func:`navlab.sim.raycast3d.cast_grid` finds it ray by ray; the work here grows with the pixels
each shape covers, not with pixels times shapes. Shapes wholly outside the view or beyond the far clip are skipped.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64

from navlab.sim.gauss import normal
from navlab.sim.raycast import BOX, CYLINDER, PLANE, SPHERE
from navlab.sim.raycast3d import PINHOLE, _block, _lower_bound, in_geom_frame

_PLANE_REACH = 1.0  # m beyond the far clip that an unbounded plane is drawn to


@njit(cache=True, error_model="numpy")
def _face(
    out: np.ndarray,
    norm: np.ndarray,
    near: float,
    clip_x: float,
    cam: np.ndarray,
    geo: np.ndarray,
    g: np.ndarray,
    k: int,
    level: float,
    ej: float,
    el: float,
    disk: bool,
) -> None:
    """Draw the face ``q_k = level`` of a geom (geom-frame point q; in-plane half extents ``ej``, ``el`` along the
    next two axes, or a disk of radius ``ej``). ``geo`` rows: the camera p in the geom frame, then a, bc, br (the
    pixel ray in the geom frame is ``a + bc c + br r``); ``g`` (3x3) turns geom-frame offsets into the sensor
    frame; ``cam`` = (f, u0, v0)."""
    rows, cols = out.shape
    f, u0, v0 = cam[0], cam[1], cam[2]
    p, a, bc, br = geo[0], geo[1], geo[2], geo[3]
    poly = np.empty((4, 3))
    proj = np.empty((5, 2))
    j, jj = (k + 1) % 3, (k + 2) % 3
    # the outline (a rectangle; a disk's bounding square) in the sensor frame, in order around it
    n = 0
    for corner in range(4):
        sj = -1.0 if corner == 0 or corner == 3 else 1.0
        sl = -1.0 if corner < 2 else 1.0
        dq0, dq1, dq2 = 0.0, 0.0, 0.0
        off_k, off_j, off_l = level - p[k], sj * ej - p[j], sl * el - p[jj]
        if k == 0:
            dq0, dq1, dq2 = off_k, off_j, off_l
        elif k == 1:
            dq1, dq2, dq0 = off_k, off_j, off_l
        else:
            dq2, dq0, dq1 = off_k, off_j, off_l
        for axis in range(3):
            poly[corner, axis] = g[0, axis] * dq0 + g[1, axis] * dq1 + g[2, axis] * dq2
    # clip at the near plane x >= clip_x (Sutherland-Hodgman, one plane): at most five corners, projected
    for i in range(4):
        x0, x1 = poly[i, 0], poly[(i + 1) % 4, 0]
        if x0 >= clip_x:
            proj[n, 0] = u0 - f * poly[i, 1] / x0
            proj[n, 1] = v0 - f * poly[i, 2] / x0
            n += 1
        if (x0 >= clip_x) != (x1 >= clip_x):
            s = (clip_x - x0) / (x1 - x0)
            y = poly[i, 1] + s * (poly[(i + 1) % 4, 1] - poly[i, 1])
            z = poly[i, 2] + s * (poly[(i + 1) % 4, 2] - poly[i, 2])
            proj[n, 0] = u0 - f * y / clip_x
            proj[n, 1] = v0 - f * z / clip_x
            n += 1
    if n < 3:
        return
    vmin, vmax = np.inf, -np.inf
    for i in range(n):
        vmin, vmax = min(vmin, proj[i, 1]), max(vmax, proj[i, 1])
    r0 = max(math.ceil(vmin - 1e-7), 0)
    r1 = min(math.floor(vmax + 1e-7), rows - 1)
    depth_num = level - p[k]
    bck, bcj, bcjj, pj, pjj, ej2 = bc[k], bc[j], bc[jj], p[j], p[jj], ej * ej
    for r in range(r0, r1 + 1):
        umin, umax = np.inf, -np.inf
        for i in range(n):
            ua, va = proj[i, 0], proj[i, 1]
            ub, vb = proj[(i + 1) % n, 0], proj[(i + 1) % n, 1]
            if min(va, vb) - 1e-7 <= r <= max(va, vb) + 1e-7:
                if abs(vb - va) < 1e-12:
                    umin, umax = min(umin, ua, ub), max(umax, ua, ub)
                else:
                    s = min(max((r - va) / (vb - va), 0.0), 1.0)
                    u = ua + s * (ub - ua)
                    umin, umax = min(umin, u), max(umax, u)
        if umin > umax:
            continue
        c0 = max(math.floor(max(umin, -1.0)), 0)
        c1 = min(math.ceil(min(umax, cols + 0.0)), cols - 1)
        ak, aj, ajj = a[k] + br[k] * r, a[j] + br[j] * r, a[jj] + br[jj] * r
        # the row without branches (each pixel's depth kept or not by a select) and with unsigned indices, so
        # that the compiler vectorises it; a pixel whose ray is parallel to the face (dk 0) is never kept
        row, norm_row = out[r, c0 : c1 + 1], norm[r, c0 : c1 + 1]
        for u in range(c1 + 1 - c0):
            cu = uint64(u)
            c = float(c0 + u)
            dk = ak + bck * c
            s = depth_num / dk
            qj = pj + s * (aj + bcj * c)
            qjj = pjj + s * (ajj + bcjj * c)
            old = row[cu]
            inside = (qj * qj + qjj * qjj <= ej2) if disk else ((abs(qj) <= ej) & (abs(qjj) <= el))
            keep = (dk != 0.0) & (s > 0.0) & (s < old) & inside & (s * norm_row[cu] >= near)
            row[cu] = s if keep else old


@njit(cache=True)
def _curved(
    out: np.ndarray,
    norm: np.ndarray,
    near: float,
    kind: int,
    size: np.ndarray,
    p: np.ndarray,
    a: np.ndarray,
    bc: np.ndarray,
    br: np.ndarray,
    bounds: np.ndarray,
) -> None:
    """Draw a sphere or a cylinder's side over the pixel block ``bounds`` (r0, r1, c0, c1): the ray's entry root."""
    rad = size[0]
    if kind == SPHERE:
        qc = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - rad * rad
    else:
        qc = p[0] * p[0] + p[1] * p[1] - rad * rad
    if qc <= 0.0:
        return  # the camera is inside: no ray enters here
    half = size[1]
    for r in range(bounds[0], bounds[1] + 1):
        a0, a1, a2 = a[0] + br[0] * r, a[1] + br[1] * r, a[2] + br[2] * r
        for c in range(bounds[2], bounds[3] + 1):
            dx, dy, dz = a0 + bc[0] * c, a1 + bc[1] * c, a2 + bc[2] * c
            if kind == SPHERE:
                qa = dx * dx + dy * dy + dz * dz
                qb = p[0] * dx + p[1] * dy + p[2] * dz
            else:
                qa = dx * dx + dy * dy
                qb = p[0] * dx + p[1] * dy
            disc = qb * qb - qa * qc
            if qa == 0.0 or disc < 0.0:
                continue
            s = (-qb - math.sqrt(disc)) / qa
            if s <= 0.0 or s >= out[r, c]:
                continue
            if kind == CYLINDER and abs(p[2] + s * dz) > half:
                continue
            if s * norm[r, c] >= near:
                out[r, c] = s


@njit(cache=True)
def draw_depth(
    origin: np.ndarray,
    rot: np.ndarray,
    cam: np.ndarray,
    norm: np.ndarray,
    geoms: np.ndarray,
    geom_type: np.ndarray,
    geom_size: np.ndarray,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    near: float,
    tmax: float,
    out: np.ndarray,
) -> None:
    """``out`` (rows x cols) = depth (m along the optical axis) of the nearest surface of ``geoms`` at each pixel,
    inf where none: a camera at world ``origin``, ``rot`` (columns: its x forward, y left, z up axes in world),
    ``cam`` = (f, u0, v0) in pixels, ``norm`` the length of each pixel's D (so that the distance along the ray is
    depth x norm, at least ``near``). Shapes whose nearest point is beyond ``tmax`` (m) are skipped."""
    rows, cols = out.shape
    out[:] = np.inf
    f, u0, v0 = cam[0], cam[1], cam[2]
    clip_x = near * 0.999 / max(norm[0, 0], norm[rows - 1, cols - 1], norm[0, cols - 1], norm[rows - 1, 0])
    geo = np.empty((4, 3))  # the camera in the geom frame, then the pixel ray's a, bc, br (see _face)
    p, a, bc, br = geo[0], geo[1], geo[2], geo[3]
    g = np.empty((3, 3))
    bounds = np.zeros(5, dtype=np.int64)
    params = np.array([f, u0, v0])
    for gi in range(geoms.shape[0]):
        gid = geoms[gi]
        kind = geom_type[gid]
        size = geom_size[gid]
        xm = geom_xmat[gid]
        in_geom_frame(origin, rot, geom_xpos[gid], xm, p, g)
        for k in range(3):
            a[k] = g[k, 0] + (u0 * g[k, 1] + v0 * g[k, 2]) / f
            bc[k] = -g[k, 1] / f
            br[k] = -g[k, 2] / f
        if _lower_bound(kind, size, p) > tmax:
            continue
        if kind == PLANE:
            if p[2] == 0.0:
                continue
            if size[0] > 0:
                ej, el = size[0], size[1]
            else:  # unbounded: a square reaching past the far clip
                ej = el = abs(p[0]) + abs(p[1]) + tmax + _PLANE_REACH
            _face(out, norm, near, clip_x, cam, geo, g, 2, 0.0, ej, el, False)
        elif kind == BOX:
            for k in range(3):
                for side in (-1.0, 1.0):
                    if side * p[k] > size[k]:  # the face turned towards the camera
                        ej, el = size[(k + 1) % 3], size[(k + 2) % 3]
                        _face(out, norm, near, clip_x, cam, geo, g, k, side * size[k], ej, el, False)
        elif kind in (CYLINDER, SPHERE):
            if not _block(kind, size, geom_xpos[gid], xm, rot, origin, PINHOLE, params, rows, cols, bounds):
                continue
            _curved(out, norm, near, kind, size, p, a, bc, br, bounds)
            if kind == CYLINDER:
                for side in (-1.0, 1.0):
                    if side * p[2] > size[1]:  # the cap turned towards the camera
                        _face(out, norm, near, clip_x, cam, geo, g, 2, side * size[1], size[0], size[0], True)


@njit(cache=True)
def finish_depth(
    depth: np.ndarray,
    near: float,
    far: float,
    noise_mean: float,
    noise_stddev: float,
    seed: np.uint64,
    cutoff: float,
    cutoff_max: float,
    out: np.ndarray,
) -> None:
    """``out`` (float32, as ``depth``) = the published depth image of ``depth`` (m, float64): inf outside the clip
    planes [``near``, ``far``], plus gaussian noise (mean, std dev in m) when ``noise_stddev`` > 0 (from the stream
    seeded with ``seed``, pixel by pixel in row-major order), NaN unless ``cutoff`` < depth < ``cutoff_max``."""
    rows, cols = depth.shape
    z = uint64(seed)
    noisy = noise_stddev > 0.0
    for r in range(rows):
        for c in range(cols):
            d = depth[r, c]
            if d > far or d < near:
                d = np.inf
            if noisy:
                n, z = normal(z)
                d += noise_mean + noise_stddev * n
            v = np.float32(d)
            out[r, c] = v if cutoff < v < cutoff_max else np.nan


@njit(cache=True)
def depth_cloud(depth: np.ndarray, focal: float, rgb: np.ndarray, words: np.ndarray, bits: np.ndarray) -> bool:
    """Fill the organised cloud of a depth image (m, float32, NaN: no point): ``words`` (height*width x 8,
    float32) x y z at 0 1 2 in the optical frame (x right, y down, z forward: x = d (c - u0)/f, y = d (r - v0)/f,
    z = d, as ``FillPointCloudHelper``), word 4 PCL's packed b g r from ``rgb`` (height x width x 3, or 0 rows: 0),
    the rest 0; ``bits`` is the same buffer as uint32. Returns whether every point is finite (``is_dense``)."""
    rows, cols = depth.shape
    colour = rgb.shape[0] == rows and rgb.shape[1] == cols
    u0, v0 = np.float32(0.5 * (cols - 1)), np.float32(0.5 * (rows - 1))
    fl = np.float32(focal)
    dense = True
    for r in range(rows):
        ys = (np.float32(r) - v0) / fl
        for c in range(cols):
            i = r * cols + c
            d = depth[r, c]
            words[i, 0] = d * ((np.float32(c) - u0) / fl)
            words[i, 1] = d * ys
            words[i, 2] = d
            bits[i, 3] = 0
            if colour:
                bits[i, 4] = np.uint32(rgb[r, c, 2]) | (np.uint32(rgb[r, c, 1]) << 8) | (np.uint32(rgb[r, c, 0]) << 16)
            else:
                bits[i, 4] = 0
            bits[i, 5] = 0
            bits[i, 6] = 0
            bits[i, 7] = 0
            if d != d:
                dense = False
    return dense
