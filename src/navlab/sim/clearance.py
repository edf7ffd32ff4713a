"""The robot's clearance: the distance (m) between its collision geoms and the world's, from MuJoCo's
``mj_geomDistance``, asked only for the pairs that can still be the nearest.

Pairs are visited nearest bounding spheres first (``bound``: centre distance minus both bounding radii, a lower
bound of the pair's distance) and the walk stops at the first pair whose bound is not below the best distance
found so far. A pair is asked only if a tighter lower bound — the robot geom's bounding sphere against the world
geom's own shape (box, cylinder, sphere, capsule) — is below the best distance by more than ``SKIP_MARGIN``: a
pair skipped so could not have lowered it, so the calls made (and the distance limits passed to them) and the
result are those of asking every pair in that order, bit for bit. (Pairs of equal bound go in table order: NumPy's
argsort, used before, left them in no set order.)
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numba import njit

CYLINDER = int(mujoco.mjtGeom.mjGEOM_CYLINDER)
BOX = int(mujoco.mjtGeom.mjGEOM_BOX)
SKIP_MARGIN = 1e-3  # m: a pair is skipped only when its tight bound exceeds the best distance by this much


@njit(cache=True)
def pair_bounds(
    xpos: np.ndarray,
    xmat: np.ndarray,
    rbound: np.ndarray,
    gtype: np.ndarray,
    size: np.ndarray,
    robot: np.ndarray,
    world: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(bound, tight), both (len(robot) * len(world),) row-major by robot geom: ``bound`` is the bounding
    spheres' gap (centre distance - both radii, computed as NumPy's norm does), ``tight`` the gap between the
    robot geom's bounding sphere and the world geom's shape (m); both are <= the pair's distance."""
    nr, nw = len(robot), len(world)
    bound = np.empty(nr * nw)
    tight = np.empty(nr * nw)
    for i in range(nr):
        a = robot[i]
        ra = rbound[a]
        for j in range(nw):
            b = world[j]
            dx, dy, dz = xpos[a, 0] - xpos[b, 0], xpos[a, 1] - xpos[b, 1], xpos[a, 2] - xpos[b, 2]
            k = i * nw + j
            bound[k] = math.sqrt(dx * dx + dy * dy + dz * dz) - ra - rbound[b]
            t = gtype[b]
            if t in (BOX, CYLINDER):
                r = xmat[b]  # the geom's axes are its columns: local = R^T (p - centre)
                lx = r[0] * dx + r[3] * dy + r[6] * dz
                ly = r[1] * dx + r[4] * dy + r[7] * dz
                lz = r[2] * dx + r[5] * dy + r[8] * dz
                if t == BOX:
                    qx = max(abs(lx) - size[b, 0], 0.0)
                    qy = max(abs(ly) - size[b, 1], 0.0)
                    qz = max(abs(lz) - size[b, 2], 0.0)
                    gap = math.sqrt(qx * qx + qy * qy + qz * qz)
                else:
                    qr = max(math.sqrt(lx * lx + ly * ly) - size[b, 0], 0.0)
                    qz = max(abs(lz) - size[b, 1], 0.0)
                    gap = math.sqrt(qr * qr + qz * qz)
                # a centre inside the shape: no bound but the spheres' (the geom may reach deeper than its radius)
                tight[k] = max(gap - ra, bound[k]) if gap > 0.0 else bound[k]
            else:  # spheres: the bounding spheres' gap is exact; other shapes (meshes ...): no better bound here
                tight[k] = bound[k]
    return bound, tight


@njit(cache=True)
def candidates(bound: np.ndarray, tight: np.ndarray, order: np.ndarray, max_distance: float) -> np.ndarray:
    """The pairs (flat indices, in ``order``) that the walk may ask: those before the first whose bound is not
    below ``max_distance`` and whose tight bound could still beat it."""
    out = np.empty(len(order), dtype=np.int64)
    n = 0
    for k in order:
        if bound[k] >= max_distance:
            break
        if tight[k] - SKIP_MARGIN >= max_distance:
            continue
        out[n] = k
        n += 1
    return out[:n]


@njit(cache=True)
def asked_pairs(
    xpos: np.ndarray,
    xmat: np.ndarray,
    rbound: np.ndarray,
    gtype: np.ndarray,
    size: np.ndarray,
    robot: np.ndarray,
    world: np.ndarray,
    max_distance: float,
) -> np.ndarray:
    """The pairs the walk may ask, as rows (robot geom, world geom, bound, tight), nearest bound first (equal bounds
    in table order): :func:`candidates` over :func:`pair_bounds` in one compiled call, only the pairs whose bound is
    below ``max_distance`` sorted (by insertion: a few dozen)."""
    bound, tight = pair_bounds(xpos, xmat, rbound, gtype, size, robot, world)
    keep = np.flatnonzero(bound < max_distance)
    for n in range(len(keep)):  # insertion sort by bound, stable
        k, i = keep[n], n
        while i > 0 and bound[keep[i - 1]] > bound[k]:
            keep[i] = keep[i - 1]
            i -= 1
        keep[i] = k
    ks = candidates(bound, tight, keep, max_distance)
    nw = len(world)
    out = np.empty((len(ks), 4))
    for i in range(len(ks)):
        k = ks[i]
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = robot[k // nw], world[k % nw], bound[k], tight[k]
    return out


def clearance(m: mujoco.MjModel, d: mujoco.MjData, robot: np.ndarray, world: np.ndarray, max_distance: float) -> float:
    """Signed distance (m) between the ``robot`` geoms and the ``world`` geoms (negative: interpenetrating),
    ``max_distance`` when nothing is closer; see the module docstring."""
    if not len(robot) or not len(world):
        return max_distance
    pairs = asked_pairs(d.geom_xpos, d.geom_xmat, m.geom_rbound, m.geom_type, m.geom_size, robot, world, max_distance)
    best = max_distance
    for a, b, bnd, t in pairs.tolist():
        if bnd >= best:
            break
        if t - SKIP_MARGIN >= best:
            continue
        best = min(best, mujoco.mj_geomDistance(m, d, int(a), int(b), best, None))
    return float(best)
