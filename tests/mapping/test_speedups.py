"""The mapping stack's shortcuts give the results of the plain computations they replace: GMapping's hill
climb (no re-scoring, early-stopped candidates), its score (two passes, kernel 1 read from the masks, each
match measured to the mean of its cell's hits), its motion draw
(one numba call), the ray caster's unchecked walk, the Dijkstra graph built in one pass, the lookup field's
bounds and unchecked loops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.geometry import wrap_angle
from navlab.gridline import EXACT_STEPS
from navlab.mapping.gmapping_match import draw_motion, match_score, optimize
from navlab.mapping.gmapping_tiles import MEAN_UNIT, TILE, TilePool, from_dense, raycast_tiles, to_dense
from navlab.mapping.occupancy import L_CLAMP, L_FREE, L_OCC, _raycast, integrate_scan
from navlab.mapping.scanmatch import LookupField, correlative_search


def _tiled(grid: np.ndarray, r: np.ndarray, ang: np.ndarray) -> tuple[tuple, np.ndarray, np.ndarray]:
    """The matcher's map argument (tiles, masks, means, table) of a dense log-odds grid (its occupied cells hit
    once at their centre) with the scan (``r``, ``ang``) from (2, 2, 0) cast into it (its hits' means off the
    centres), and that map's dense log-odds and means."""
    pool, table = from_dense(grid)
    free = pool.free(table.size)  # (may grow the pool: its arrays are read after)
    cow = (pool.tiles, pool.masks, pool.means, table, pool.refs, free, np.zeros(1, dtype=np.int64))
    raycast_tiles(*cow, (0.0, 0.0, 0, 0, 0.05), (2.0, 2.0, 0.0), (r, ang, 8.0, 10.0), (L_OCC, L_FREE, L_CLAMP))
    tiled = (pool.tiles, pool.masks, pool.means, table)
    return tiled, to_dense(pool.tiles, table), to_dense(pool.means, table)


def _plain_climb(tiled, lattice, scan, model, x0, y0, t0, lstep, astep, iterations):
    """GMapping's ScanMatcher::optimize scoring every candidate in full (the reference)."""
    cur = match_score(*tiled, lattice, (x0, y0, t0), scan, model)[0]
    cx, cy, ct = x0, y0, t0
    ld, ad, refinement, best = lstep, astep, 0, -1.0
    while True:
        if best >= cur:
            refinement += 1
            ld, ad = ld * 0.5, ad * 0.5
        if not (cur > best or refinement < iterations):
            break
        best = cur
        bx, by, bt = cx, cy, ct
        for nx, ny, nt in (
            (cx + ld, cy, ct),
            (cx - ld, cy, ct),
            (cx, cy + ld, ct),
            (cx, cy - ld, ct),
            (cx, cy, ct + ad),
            (cx, cy, ct - ad),
        ):
            sc = match_score(*tiled, lattice, (nx, ny, nt), scan, model)[0]
            if sc > cur:
                cur, bx, by, bt = sc, nx, ny, nt
        cx, cy, ct = bx, by, bt
    return cx, cy, ct, cur


def _room_map(rng: np.random.Generator, res: float = 0.05) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A log-odds map of a 4 m x 3 m box room seen from a few poses, and one more scan of it (ranges, angles)."""
    grid = np.zeros((90, 110), dtype=np.float32)
    ang = np.linspace(-np.pi, np.pi, 720, endpoint=False)

    def ranges(x: float, y: float, t: float) -> np.ndarray:
        c, s = np.cos(ang + t), np.sin(ang + t)
        with np.errstate(divide="ignore"):
            tx = np.where(c > 0, (4.5 - x) / c, (0.5 - x) / c)
            ty = np.where(s > 0, (3.5 - y) / s, (0.5 - y) / s)
        return np.minimum(np.abs(tx), np.abs(ty)) + rng.normal(0, 0.01, ang.size)

    for x, y, t in ((2.0, 2.0, 0.0), (3.0, 1.5, 0.4), (1.5, 2.5, -0.3)):
        integrate_scan(grid, (0.0, 0.0), res, np.array([x, y, t]), ranges(x, y, t), ang, max_urange=8.0, max_range=10.0)
    return grid, ranges(2.5, 2.0, 0.1), ang


def test_the_hill_climb_equals_gmappings_plain_climb() -> None:
    rng = np.random.default_rng(4)
    grid, r, ang = _room_map(rng)
    tiled, _grid, _means = _tiled(grid, r, ang)
    for skip in (0, 4):
        for k in range(12):
            x0, y0, t0 = 2.5 + rng.normal(0, 0.08), 2.0 + rng.normal(0, 0.08), 0.1 + rng.normal(0, 0.05)
            lattice, scan, model = (0.0, 0.0, 0, 0, 0.05), (r, np.cos(ang), np.sin(ang), 8.0), (1, 0.05, 0.075, skip)
            got = optimize(*tiled, lattice, (x0, y0, t0), scan, model, (0.05, 0.05, 5))
            want = _plain_climb(tiled, lattice, scan, model, x0, y0, t0, 0.05, 0.05, 5)
            assert got[:4] == want, (skip, k)
            assert got[4] == match_score(*tiled, lattice, got[:3], scan, model)[1]  # the log-likelihood at the result


def _plain_score(grid, means, ox, oy, res, x, y, t, r, ang, max_urange, kernel, sigma, lsigma, skip):
    """GMapping's ScanMatcher::score beam by beam, every cell bounds-checked, each match measured to the mean
    of its cell's hits (``means``: hits, x, y offset per cell) (the reference)."""
    h, w = grid.shape
    s, lik, n = 0.0, 0.0, 0
    ct, st = math.cos(t), math.sin(t)
    for k in range(0, len(r), skip + 1):
        if not 0.0 < r[k] < max_urange:
            continue
        cb, sb = math.cos(ang[k]), math.sin(ang[k])
        ca, sa = ct * cb - st * sb, st * cb + ct * sb
        ex, ey = x + r[k] * ca, y + r[k] * sa
        fx, fy = ex - res * ca, ey - res * sa
        ux, uy = (ex - ox) / res, (ey - oy) / res  # cells
        ei, ej = math.floor(ux), math.floor(uy)
        fi, fj = math.floor((fx - ox) / res), math.floor((fy - oy) / res)
        best = None
        for dj in range(-kernel, kernel + 1):
            for di in range(-kernel, kernel + 1):
                i, j, i2, j2 = ei + di, ej + dj, fi + di, fj + dj
                if 0 <= i < w and 0 <= j < h and 0 <= i2 < w and 0 <= j2 < h and grid[j, i] > 0 and grid[j2, i2] < 0:
                    assert means[j, i, 0] > 0  # an occupied cell was hit
                    mx, my = i + means[j, i, 1] * MEAN_UNIT, j + means[j, i, 2] * MEAN_UNIT
                    d2 = (mx - ux) ** 2 + (my - uy) ** 2
                    best = d2 if best is None else min(best, d2)
        if best is None:
            lik += -0.5 / lsigma
        else:
            best *= res * res
            s += math.exp(-best / sigma)
            lik += -best / lsigma
            n += 1
    return s, lik, n


def test_the_score_equals_gmappings_plain_score_for_every_kernel_and_near_the_edges() -> None:
    rng = np.random.default_rng(6)
    grid, r, ang = _room_map(rng)  # 90 x 110 cells: the room spans tile borders (64 cells), which the beams cross
    tiled, grid, means = _tiled(grid, r, ang)
    assert np.count_nonzero((means[..., 0] > 0) & (means[..., 1] != 128)) > 100  # the scan's hits: off the centres
    cb, sb = np.cos(ang), np.sin(ang)
    # poses in the room, and near the map's edge (beams end outside it: the checked path)
    for x, y, t in ((2.5, 2.0, 0.1), (2.2, 1.7, -0.4), (0.3, 0.2, 0.0), (5.2, 4.2, 2.0)):
        for kernel in (0, 1, 2):
            for skip in (0, 3):
                scan, model = (r, cb, sb, 8.0), (kernel, 0.05, 0.075, skip)
                got = match_score(*tiled, (0.0, 0.0, 0, 0, 0.05), (x, y, t), scan, model)
                want = _plain_score(grid, means, 0.0, 0.0, 0.05, x, y, t, r, ang, 8.0, kernel, 0.05, 0.075, skip)
                assert got == want, (x, y, t, kernel, skip)


def test_the_motion_draw_equals_the_vectorised_motion_model() -> None:
    rng = np.random.default_rng(7)
    poses = rng.normal(0.0, 2.0, (40, 3))
    noise = rng.normal(0.0, 1.0, (40, 3))
    step, sig = (0.03, -0.01, 0.02), (0.004, 0.003, 0.006)
    noisy = np.asarray(step)[None, :] + noise * np.asarray(sig)[None, :]
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    want = np.column_stack(
        [
            poses[:, 0] + c * noisy[:, 0] - s * noisy[:, 1],
            poses[:, 1] + s * noisy[:, 0] + c * noisy[:, 1],
            wrap_angle(poses[:, 2] + noisy[:, 2]),
        ]
    )
    draw_motion(poses, noise, *step, *sig)
    np.testing.assert_array_equal(poses, want)


def test_the_unchecked_ray_walk_equals_the_checked_one() -> None:
    """A window of the lattice that does not hold the laser (every beam on the checked path) ends with the
    cells of a grid that holds the whole scan (every beam on the unchecked path)."""
    rng = np.random.default_rng(8)
    _grid, r, ang = _room_map(rng)
    args = (0.05, 2.5, 2.0, 0.1, r, ang, 8.0, 10.0, L_OCC, L_FREE, L_CLAMP)
    for dtype in (np.float32, np.float64):  # GMapping's particle maps; build_map's
        whole = np.zeros((90, 110), dtype=dtype)
        _raycast(whole, 0.0, 0.0, 0, 0, *args)
        _raycast(whole, 0.0, 0.0, 0, 0, *args)  # twice: cells near the clamp
        for oi, oj, w, h in ((60, 10, 50, 80), (0, 0, 40, 30), (30, 50, 80, 40)):
            part = np.zeros((h, w), dtype=dtype)
            _raycast(part, 0.0, 0.0, oi, oj, *args)
            _raycast(part, 0.0, 0.0, oi, oj, *args)
            np.testing.assert_array_equal(part, whole[oj : oj + h, oi : oi + w])
    # lines longer than the fixed-point division covers (EXACT_STEPS) divide exactly
    r_long = np.array([EXACT_STEPS * 0.05 + 3.0, 150.0, 40.0])
    ang_long = np.array([0.0, 0.002, -0.004])
    args = (0.05, 0.26, 0.3, 0.0, r_long, ang_long, 300.0, 400.0, L_OCC, L_FREE, L_CLAMP)
    whole = np.zeros((12, EXACT_STEPS + 80), dtype=np.float32)
    _raycast(whole, 0.0, 0.0, 0, 0, *args)
    part = np.zeros((12, EXACT_STEPS + 70), dtype=np.float32)
    _raycast(part, 0.0, 0.0, 10, 0, *args)
    np.testing.assert_array_equal(part, whole[:, 10:])
    assert np.count_nonzero(whole) > EXACT_STEPS
    with pytest.raises(ValueError, match="C-contiguous"):
        integrate_scan(
            np.zeros((20, 20))[:, ::2], (0.0, 0.0), 0.05, np.zeros(3), r, ang, max_urange=8.0, max_range=10.0
        )


def test_the_tiled_ray_cast_writes_the_dense_cells_and_copies_only_shared_tiles(masks_hold) -> None:
    """Two particles share one map's tiles; one integrates a scan: its map equals the dense ray cast's, the
    other's is unchanged, only the tiles the scan wrote were copied, every tile's mask holds, and each cell
    the scan hit holds the mean of its hits."""
    rng = np.random.default_rng(9)
    grid, r, ang = _room_map(rng)
    args = (0.05, 2.5, 2.0, 0.1, r, ang, 8.0, 10.0, L_OCC, L_FREE, L_CLAMP)
    pool, mine = from_dense(grid)
    theirs = mine.copy()
    pool.recount([mine, theirs])
    in_use = pool.in_use()
    for _ in range(2):  # the second time every tile written is already private: no copies
        free = pool.free(mine.size)  # (may grow the pool: its arrays are read after)
        cow = (pool.tiles, pool.masks, pool.means, mine, pool.refs, free, np.zeros(1, dtype=np.int64))
        raycast_tiles(*cow, (0.0, 0.0, 0, 0, 0.05), (2.5, 2.0, 0.1), (r, ang, 8.0, 10.0), (L_OCC, L_FREE, L_CLAMP))
    whole = grid.copy()
    _raycast(whole, 0.0, 0.0, 0, 0, *args)
    _raycast(whole, 0.0, 0.0, 0, 0, *args)
    np.testing.assert_array_equal(to_dense(pool.tiles, mine)[:90, :110], whole)
    np.testing.assert_array_equal(to_dense(pool.tiles, theirs)[:90, :110], grid)
    masks_hold(pool, [mine, theirs])
    # the means: cells the scan hit that held no hit before hold its end points' mean (twice each)
    hit = (r > 0) & (r < 8.0)
    u = np.column_stack([2.5 + r[hit] * np.cos(0.1 + ang[hit]), 2.0 + r[hit] * np.sin(0.1 + ang[hit])]) / 0.05
    cells = np.floor(u).astype(int)
    means, theirs_means = to_dense(pool.means, mine), to_dense(pool.means, theirs)
    keys, inv = np.unique(cells, axis=0, return_inverse=True)
    fresh = 0
    for n, (i, j) in enumerate(keys):
        if grid[j, i] > 0:
            continue  # hit once at its centre by from_dense
        pts = u[inv.ravel() == n]
        assert means[j, i, 0] == 2 * len(pts)
        np.testing.assert_allclose(means[j, i, 1:] * MEAN_UNIT, pts.mean(axis=0) - (i, j), atol=1 / 128)
        assert theirs_means[j, i, 0] == 0
        fresh += 1
    assert fresh > 20
    written = np.unique(np.argwhere(whole != grid) // TILE, axis=0)
    assert pool.in_use() == in_use + len(written)
    assert np.count_nonzero(mine != theirs) == len(written)
    pool.recount([mine])  # the other particle dropped: its tiles are free again
    assert pool.in_use() == len(written) + np.count_nonzero((mine == theirs) & (mine > 0))
    assert len(TilePool(2).free(40)) >= 40  # the pool grows when short of free tiles


def test_a_ray_over_cells_at_the_clamp_copies_no_shared_tile(masks_hold) -> None:
    """Cells already at -clamp stay as they are, so a scan cast again from the same pose into a map two particles
    share copies only the tiles where some cell changes (here the far wall's), not the tiles its rays only
    cross, and the map still equals the dense ray cast's."""
    ang = np.linspace(-0.02, 0.02, 21)
    r = 14.0 / np.cos(ang)  # a 15 m corridor's far wall, 14 m ahead of the laser at (0.5, 1.0)
    args = (0.05, 0.5, 1.0, 0.0, r, ang, 20.0, 25.0, L_OCC, L_FREE, L_CLAMP)
    pool, mine = from_dense(np.zeros((40, 300), dtype=np.float32))
    whole = np.zeros((40, 300), dtype=np.float32)

    def cast(table: np.ndarray) -> int:
        free, used = pool.free(table.size), np.zeros(1, dtype=np.int64)
        cow = (pool.tiles, pool.masks, pool.means, table, pool.refs, free, used)
        raycast_tiles(*cow, (0.0, 0.0, 0, 0, 0.05), (0.5, 1.0, 0.0), (r, ang, 20.0, 25.0), (L_OCC, L_FREE, L_CLAMP))
        _raycast(whole, 0.0, 0.0, 0, 0, *args)
        return int(used[0])

    for _ in range(int(L_CLAMP / -L_FREE) + 2):  # every cell the rays cross at the clamp
        cast(mine)
    theirs = mine.copy()
    pool.recount([mine, theirs])
    before = to_dense(pool.tiles, mine)
    copied = cast(mine)
    np.testing.assert_array_equal(to_dense(pool.tiles, mine)[:40, :300], whole)
    np.testing.assert_array_equal(to_dense(pool.tiles, theirs), before)
    crossed = np.unique(np.argwhere(before == -L_CLAMP) // TILE, axis=0)
    assert len(crossed) == 5  # the corridor's five tiles
    assert copied == np.count_nonzero(mine != theirs) == 1  # the far wall's tile only
    masks_hold(pool, [mine, theirs])


def test_lookup_field_and_correlative_search_near_and_off_the_edges() -> None:
    rng = np.random.default_rng(5)
    pts = rng.normal(0, 2.0, (300, 2))
    for margin in (0.0, 1.0):
        f = LookupField(pts, margin=margin)
        assert f.origin == (float(pts[:, 0].min() - margin), float(pts[:, 1].min() - margin))
        # every splatted point's own cell holds the kernel's peak
        ci = np.floor((pts[:, 0] - f.origin[0]) / f.resolution).astype(int)
        cj = np.floor((pts[:, 1] - f.origin[1]) / f.resolution).astype(int)
        assert np.all(f.grid[cj, ci] == np.float32(1.0))
        for window in (0.0, 0.3, 5.0):  # 5 m: shifts leave the field (the checked path)
            pose, score = correlative_search(
                f, pts, np.array([0.02, -0.03, 0.0]), lin_window=window, ang_window=0.02, ang_step=0.01
            )
            want = np.zeros(3) if window > 0 else np.array([0.02, -0.03, 0.0])
            np.testing.assert_allclose(pose, want, atol=0.051)
            assert 0.0 < score <= 1.0
