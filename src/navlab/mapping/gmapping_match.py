"""GMapping's numba kernels: the scan matcher — the beam-endpoint score of a scan against a particle's log-odds
map and the hill climbing over (x, y, theta) that maximises it (``ScanMatcher::score`` / ``optimize``) — and
the motion model's draw for all particles at once (``MotionModel::drawFromMotion``).

A particle's map is a tiled copy-on-write map (``mapping.gmapping_tiles``: ``tiles``, their ``masks``, ``table``)
whose cells
follow the lattice conventions of ``mapping.occupancy``: a fixed lattice anchored at (``ox``, ``oy``) from
lattice cell (``oi``, ``oj``) on; cells outside it read as unknown.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.mapping.gmapping_tiles import MASK, MEAN_UNIT, NEIGHBOUR_BIT, SHIFT, TILE, cell, from_dense, raycast_tiles
from navlab.mapping.occupancy import L_CLAMP, L_FREE, L_OCC, scan_cells

# the kernels' argument groups (numba tuples)
Lattice = tuple[float, float, int, int, float]  # the lattice: anchor x, y (m), offset column, row, cell size (m)
Pose = tuple[float, float, float]  # x, y (m), theta (rad)
Beams = tuple[np.ndarray, np.ndarray, np.ndarray]  # the scored beams' ranges (m), cos and sin (laser frame)
Scan = tuple[np.ndarray, np.ndarray, np.ndarray, float]  # all ranges, cos and sin of the angles, max_urange (m)
Model = tuple[int, float, float, int]  # GMapping's kernelSize, sigma, lsigma, lskip

SEEN_POSES = 256  # poses whose score one hill climb remembers (it re-visits neighbours it scored before)


@numba.njit(cache=True)
def _valid_beams(scan: Scan, skip: int) -> Beams:
    """(range, cos, sin) of the beams the matcher scores, in order: every ``skip + 1``-th, with a range in
    (0, max_urange)."""
    ranges, cb, sb, max_urange = scan
    n = 0
    for k in range(0, ranges.shape[0], skip + 1):
        if ranges[k] > 0.0 and ranges[k] < max_urange:
            n += 1
    rv, cv, sv = np.empty(n), np.empty(n), np.empty(n)
    n = 0
    for k in range(0, ranges.shape[0], skip + 1):
        if ranges[k] > 0.0 and ranges[k] < max_urange:
            rv[n], cv[n], sv[n] = ranges[k], cb[k], sb[k]
            n += 1
    return rv, cv, sv


@numba.njit(cache=True, inline="always")
def _endpoints(lattice: Lattice, pose: Pose, beams: Beams, fw: np.ndarray, iw: np.ndarray) -> None:
    """For every beam (``beams``: range, cos, sin, laser frame) at ``pose`` (x, y, theta), into ``fw`` (4, n):
    its end point (x, y) in cells from the lattice's anchor; into ``iw`` (4, n): the end cell
    (i, j) and the cell one step back along the beam (i, j), as array indices. One branch-free loop (the
    compiler vectorises it); ``_score_above`` then reads them beam by beam."""
    ox, oy, oi, oj, res = lattice
    px, py, pt = pose
    rv, cv, sv = beams
    ct, st = math.cos(pt), math.sin(pt)
    for k in range(rv.shape[0]):
        r = rv[k]
        ca = ct * cv[k] - st * sv[k]  # cos, sin of (pt + beam angle)
        sa = st * cv[k] + ct * sv[k]
        ex, ey = px + r * ca, py + r * sa
        fx, fy = ex - res * ca, ey - res * sa  # a point one cell back along the beam
        ux, uy = (ex - ox) / res, (ey - oy) / res  # in cells from the anchor
        bi, bj = math.floor(ux), math.floor(uy)  # lattice cell
        fw[0, k], fw[1, k] = ux, uy
        iw[0, k], iw[1, k] = bi - oi, bj - oj
        iw[2, k] = math.floor((fx - ox) / res) - oi
        iw[3, k] = math.floor((fy - oy) / res) - oj


@numba.njit(cache=True, inline="always")
def _mean_d2(means: np.ndarray, e: int, i: int, j: int, ux: float, uy: float) -> float:
    """Squared distance (cells²) from the end point (``ux``, ``uy``) (cells from the anchor) to the mean of the
    hits of lattice cell (``i``, ``j``), whose means are at flat index ``e`` (x 3) of ``means``. In lattice
    cells, not array ones: the same wherever the map's window starts."""
    mx = i + means[numba.uint64(3 * e + 1)] * MEAN_UNIT
    my = j + means[numba.uint64(3 * e + 2)] * MEAN_UNIT
    return (mx - ux) ** 2 + (my - uy) ** 2


@numba.njit(cache=True, inline="always")
def _score_above(
    tiles: np.ndarray,
    masks: np.ndarray,
    means: np.ndarray,
    table: np.ndarray,
    lattice: Lattice,
    pose: Pose,
    beams: Beams,
    model: tuple[int, float, float],
    bound: float,
    fw: np.ndarray,
    iw: np.ndarray,
    order: np.ndarray,
) -> tuple[float, float, int]:
    """GMapping's score and log-likelihood of a scan at a pose: for each beam endpoint, the nearest mean of
    the hits of an occupied cell within ``kernel`` cells whose cell one step back along the beam is free
    (GMapping's ``cell.mean()``). ``beams``: range, cosine and sine (laser frame) of the beams to score
    (``_valid_beams``); ``model``: (kernel, sigma, lsigma); ``fw`` (4, n), ``iw`` (4, n): work arrays
    (``_endpoints``; row 3 of ``fw`` gets each beam's match's squared distance (m²), -1 if none, and row 2, when
    the scan is scored to the end, its score term).

    A beam adds at most 1 to the score, so once the score so far plus one per beam left cannot exceed
    ``bound`` (rounding included), this returns (-1, 0, -1) without scoring the rest: the hill climb only
    needs to know that such a pose is no better. ``bound`` < 0 scores every beam. The beams are visited in
    ``order`` (a permutation: the hill climb puts first those that scored worst at the pose it climbs from,
    which stops a worse neighbour sooner). While visiting, a term exp(-x) is bounded by 1 - x + x²/2 (its
    Taylor polynomial, above it for x >= 0; plus 1e-15 for exp's rounding): no exp is taken for a pose
    given up, four in five of a climb's. The score's terms and its log-likelihood are then summed in beam
    order, so the order and the bound change nothing but when a pose is given up."""
    oi, oj, res = lattice[2], lattice[3], lattice[4]
    kernel, sigma, lsigma = model
    rv = beams[0]
    th, tw = table.shape
    h, w = th * TILE, tw * TILE
    flat = masks.reshape(-1)  # views (C-contiguous)
    mflat = means.reshape(-1)
    _endpoints(lattice, pose, beams, fw, iw)
    s = 0.0
    null_l = -0.5 / lsigma  # GMapping: nullLikelihood = -0.5
    left = rv.shape[0]
    fw0, fw1, fw3 = fw[0], fw[1], fw[3]  # rows (views), read at unsigned indices: no negative-index wrap
    iw0, iw1, iw2, iw3 = iw[0], iw[1], iw[2], iw[3]
    for q in range(rv.shape[0]):
        k = numba.uint64(order[q])
        ux, uy = fw0[k], fw1[k]
        ei, ej, fi, fj = iw0[k], iw1[k], iw2[k], iw3[k]
        best = 1e9  # the nearest match's squared distance (cells²): a minimum, so the cells' order does not matter
        inside = (
            min(ei, fi) >= kernel and min(ej, fj) >= kernel and max(ei, fi) < w - kernel and max(ej, fj) < h - kernel
        )
        # GMapping's default kernel with both 3 x 3 windows inside one tile each (nearly always; then it is
        # the same tile, as the cell back is a neighbour): each cell's occupied-with-free-behind bit read from
        # the tile's mask, flat unsigned indices
        if (
            inside
            and kernel == 1
            and 1 <= (ei & MASK) < MASK
            and 1 <= (ej & MASK) < MASK
            and 1 <= (fi & MASK) < MASK
            and 1 <= (fj & MASK) < MASK
        ):
            tile = table[numba.uint64(ej >> SHIFT), numba.uint64(ei >> SHIFT)]
            ce = tile * TILE * TILE + (ej & MASK) * TILE + (ei & MASK)
            bit = NEIGHBOUR_BIT[(fj - ej + 1) * 3 + fi - ei + 1]
            for dj in range(-1, 2):
                for di in range(-1, 2):
                    e = ce + dj * TILE + di
                    if flat[numba.uint64(e)] & bit:
                        d2 = _mean_d2(mflat, e, ei + di + oi, ej + dj + oj, ux, uy)
                        best = d2 if d2 < best else best
        else:
            for dj in range(-kernel, kernel + 1):
                for di in range(-kernel, kernel + 1):
                    i, j = ei + di, ej + dj
                    i2, j2 = fi + di, fj + dj
                    if i < 0 or j < 0 or i >= w or j >= h or i2 < 0 or j2 < 0 or i2 >= w or j2 >= h:
                        continue
                    if cell(tiles, table, j, i) > 0.0 and cell(tiles, table, j2, i2) < 0.0:
                        e = table[j >> SHIFT, i >> SHIFT] * TILE * TILE + (j & MASK) * TILE + (i & MASK)
                        d2 = _mean_d2(mflat, e, i + oi, j + oj, ux, uy)
                        best = d2 if d2 < best else best
        left -= 1
        if best < 1e9:
            best *= res * res
            fw3[k] = best
            x = best / sigma
            s += min(1.0 - x + 0.5 * x * x, 1.0) + 1e-15  # >= exp(-x) as computed (see above)
        else:
            fw3[k] = -1.0
        # each later term is in [0, 1] and each rounding adds < 1e-16 relatively (<= 720 beams, in any order):
        # a safe bound
        if (s + left) * (1.0 + 1e-12) <= bound:
            return -1.0, 0.0, -1
    if s * (1.0 + 1e-12) <= bound:  # no better, whatever the order of the sum
        return -1.0, 0.0, -1
    s = 0.0  # the sums in beam order
    lik = 0.0
    n = 0
    for k in range(rv.shape[0]):
        if fw[3, k] >= 0.0:
            term = math.exp(-fw[3, k] / sigma)
            s += term
            lik += -fw[3, k] / lsigma
            n += 1
        else:
            term = 0.0
            lik += null_l
        fw[2, k] = term
    return s, lik, n


@numba.njit(cache=True, inline="always")
def _worst_first(terms: np.ndarray, order: np.ndarray, counts: np.ndarray) -> None:
    """``order``: the beams by their score terms (in [0, 1]) in 64 bins, lowest first (a counting sort)."""
    nbins = counts.shape[0]
    counts[:] = 0
    for k in range(terms.shape[0]):
        counts[min(int(terms[k] * nbins), nbins - 1)] += 1
    start = 0
    for b in range(nbins):
        c = counts[b]
        counts[b] = start
        start += c
    for k in range(terms.shape[0]):
        b = min(int(terms[k] * nbins), nbins - 1)
        order[counts[b]] = k
        counts[b] += 1


@numba.njit(cache=True)
def match_score(
    tiles: np.ndarray,
    masks: np.ndarray,
    means: np.ndarray,
    table: np.ndarray,
    lattice: Lattice,
    pose: Pose,
    scan: Scan,
    model: Model,
) -> tuple[float, float, int]:
    """(score, log-likelihood, matched beams) of the scan at ``pose`` (x, y, theta). ``scan``: (ranges, cos
    and sin of the beam angles (laser frame), max_urange); ``model``: (kernel, sigma, lsigma, skip): every
    ``skip + 1``-th beam with a range in (0, max_urange) is scored. See ``_score_above``."""
    beams = _valid_beams(scan, model[3])
    nb = beams[0].shape[0]
    fw, iw = np.empty((4, nb)), np.empty((4, nb), dtype=np.int64)
    return _score_above(tiles, masks, means, table, lattice, pose, beams, model[:3], -1.0, fw, iw, np.arange(nb))


@numba.njit(cache=True)
def optimize(
    tiles: np.ndarray,
    masks: np.ndarray,
    means: np.ndarray,
    table: np.ndarray,
    lattice: Lattice,
    start: Pose,
    scan: Scan,
    model: Model,
    steps: tuple[float, float, int],
) -> tuple[float, float, float, float, float]:
    """GMapping's hill climbing from ``start`` (``scan``, ``model``: as ``match_score``'s): try ±lstep in x,
    y and ±astep in theta; halve the steps when no move improves the score, ``iterations`` times
    (``steps``: (lstep, astep, iterations)). Returns the pose, its score and its log-likelihood.

    A pose already scored in this climb (bit for bit: the one just left, a neighbour tried before) is
    not scored again, and a candidate's scoring stops once it cannot beat the best so far (its beams
    visited worst first, as they scored at the pose climbed from); the result is the same as scoring every
    candidate in full."""
    lstep, astep, iterations = steps
    beams = _valid_beams(scan, model[3])
    scoring = model[:3]
    nb = beams[0].shape[0]
    fw, iw = np.empty((4, nb)), np.empty((4, nb), dtype=np.int64)
    order, counts = np.arange(nb), np.empty(64, dtype=np.int64)
    terms = np.empty(nb)  # the score terms of the best pose found in this step of the climb
    seen = np.empty((SEEN_POSES, 5))  # x, y, theta, score (-1: no better than the pose it was tried from), lik
    cx, cy, ct = start
    cur, cur_lik, _n = _score_above(tiles, masks, means, table, lattice, start, beams, scoring, -1.0, fw, iw, order)
    _worst_first(fw[2], order, counts)
    seen[0, 0], seen[0, 1], seen[0, 2], seen[0, 3], seen[0, 4] = cx, cy, ct, cur, cur_lik
    n_seen = 1
    ld, ad = lstep, astep
    refinement = 0
    best = -1.0
    for _ in range(200):
        if best >= cur:
            refinement += 1
            ld *= 0.5
            ad *= 0.5
        if not (cur > best or refinement < iterations):
            break
        best = cur
        bx, by, bt = cx, cy, ct
        for move in range(6):
            nx, ny, nt = cx, cy, ct
            if move == 0:
                nx += ld
            elif move == 1:
                nx -= ld
            elif move == 2:
                ny += ld
            elif move == 3:
                ny -= ld
            elif move == 4:
                nt += ad
            else:
                nt -= ad
            q = 0
            while q < n_seen and not (seen[q, 0] == nx and seen[q, 1] == ny and seen[q, 2] == nt):
                q += 1
            if q < n_seen:
                sc, lik = seen[q, 3], seen[q, 4]
            else:
                at = (nx, ny, nt)
                sc, lik, _n = _score_above(tiles, masks, means, table, lattice, at, beams, scoring, cur, fw, iw, order)
                if n_seen < SEEN_POSES:
                    seen[n_seen, 0], seen[n_seen, 1], seen[n_seen, 2] = nx, ny, nt
                    seen[n_seen, 3], seen[n_seen, 4] = sc, lik
                    n_seen += 1
                if sc > cur:  # (a pose remembered from before never beats the best so far)
                    terms[:] = fw[2]
            if sc > cur:
                cur, cur_lik = sc, lik
                bx, by, bt = nx, ny, nt
        if bx != cx or by != cy or bt != ct:
            _worst_first(terms, order, counts)
        cx, cy, ct = bx, by, bt
    return cx, cy, ct, cur, cur_lik


@numba.njit(cache=True)
def draw_motion(
    poses: np.ndarray, noise: np.ndarray, dx: float, dy: float, dt: float, sx: float, sy: float, st: float
) -> None:
    """GMapping's MotionModel::drawFromMotion for every particle, in place: pose n (row of ``poses``, (N, 3))
    moves by the odometry step (``dx``, ``dy``, ``dt``) in its own frame plus ``noise[n]`` (standard normal
    draws) scaled by (``sx``, ``sy``, ``st``); the heading is wrapped to [-pi, pi)."""
    for n in range(poses.shape[0]):
        nx = dx + noise[n, 0] * sx
        ny = dy + noise[n, 1] * sy
        nt = dt + noise[n, 2] * st
        c, s = math.cos(poses[n, 2]), math.sin(poses[n, 2])
        poses[n, 0] = poses[n, 0] + c * nx - s * ny
        poses[n, 1] = poses[n, 1] + s * nx + c * ny
        poses[n, 2] = (poses[n, 2] + nt + math.pi) % (2.0 * math.pi) - math.pi


def warmup() -> None:
    """Load the matcher's, the motion model's and the map integration's kernels (numba: compiled once, then
    read from its disk cache, ~0.25 s) on a tiny input, with the argument types GMapping passes; without it
    that load would stall the first map update (a live run's simulation at its first second)."""
    pool, table = from_dense(np.zeros((4, 4), dtype=np.float32))
    free, used = pool.free(1), np.zeros(1, dtype=np.int64)
    tiles, masks, means = pool.tiles, pool.masks, pool.means  # (after free(), which may grow the pool)
    r, c = np.ones(2), np.ones(2)
    lattice, pose, scan, model = (0.0, 0.0, 0, 0, 0.05), (0.1, 0.1, 0.0), (r, c, c, 1.0), (1, 0.05, 0.075, 0)
    optimize(tiles, masks, means, table, lattice, pose, scan, model, (0.05, 0.05, 1))
    match_score(tiles, masks, means, table, lattice, pose, scan, model)
    raycast_tiles(
        tiles, masks, means, table, pool.refs, free, used, lattice, pose, (r, c, 1.0, 2.0), (L_OCC, L_FREE, L_CLAMP)
    )
    draw_motion(np.zeros((2, 3)), np.zeros((2, 3)), 0.1, 0.0, 0.0, 0.1, 0.1, 0.1)
    scan_cells(np.zeros((2, 3)), r, c, (0.0, 0.0), 0.05, max_urange=1.0, max_range=2.0)
