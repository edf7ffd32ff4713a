"""The mapping stack's shortcuts give the results of the plain computations they replace: GMapping's hill
climb (no re-scoring, early-stopped candidates), the Dijkstra graph built in one pass, the lookup field's
bounds and unchecked loops."""

from __future__ import annotations

import numpy as np
from scipy import sparse

from navlab.mapping.explore import _grid_graph
from navlab.mapping.gmapping_match import _optimize, _score
from navlab.mapping.occupancy import integrate_scan
from navlab.mapping.scanmatch import LookupField, correlative_search


def _plain_climb(grid, args, x0, y0, t0, lstep, astep, iterations):
    """GMapping's ScanMatcher::optimize scoring every candidate in full (the reference)."""
    cur = _score(grid, *args[:5], x0, y0, t0, *args[5:])[0]
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
        for nx, ny, nt in ((cx + ld, cy, ct), (cx - ld, cy, ct), (cx, cy + ld, ct), (cx, cy - ld, ct),
                           (cx, cy, ct + ad), (cx, cy, ct - ad)):  # fmt: skip
            sc = _score(grid, *args[:5], nx, ny, nt, *args[5:])[0]
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
        integrate_scan(grid, (0.0, 0.0), res, np.array([x, y, t]), ranges(x, y, t), ang, max_urange=8.0,
                       max_range=10.0)  # fmt: skip
    return grid, ranges(2.5, 2.0, 0.1), ang


def test_the_hill_climb_equals_gmappings_plain_climb() -> None:
    rng = np.random.default_rng(4)
    grid, r, ang = _room_map(rng)
    for skip in (0, 4):
        for k in range(12):
            x0, y0, t0 = 2.5 + rng.normal(0, 0.08), 2.0 + rng.normal(0, 0.08), 0.1 + rng.normal(0, 0.05)
            args = (0.0, 0.0, 0, 0, 0.05, r, np.cos(ang), np.sin(ang), 8.0, 1, 0.05, 0.075, skip)
            got = _optimize(grid, *args[:5], x0, y0, t0, *args[5:], 0.05, 0.05, 5)
            want = _plain_climb(grid, args, x0, y0, t0, 0.05, 0.05, 5)
            assert got[:4] == want, (skip, k)
            assert got[4] == _score(grid, *args[:5], *got[:3], *args[5:])[1]  # the log-likelihood at the result


def test_the_one_pass_dijkstra_graph_equals_scipys_from_the_edge_list() -> None:
    rng = np.random.default_rng(2)
    for _ in range(20):
        h, w = rng.integers(1, 30, 2)
        mask = rng.random((h, w)) < 0.7
        cost = 1.0 + 4.0 * rng.integers(0, 253, (h, w)) / 252.0
        rows, cols, vals = [], [], []
        for j, i in zip(*np.nonzero(mask), strict=True):
            for dj, di, length in ((0, 1, 1.0), (1, 0, 1.0), (1, 1, np.sqrt(2.0)), (1, -1, np.sqrt(2.0))):
                j2, i2 = j + dj, i + di
                if 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                    a, b = j * w + i, j2 * w + i2
                    c = length * 0.5 * (cost.flat[a] + cost.flat[b])
                    rows += [a, b]
                    cols += [b, a]
                    vals += [c, c]
        want = sparse.csr_matrix((vals, (rows, cols)), shape=(h * w, h * w))
        indptr, indices, data = _grid_graph(mask, cost.ravel())
        np.testing.assert_array_equal(indptr, want.indptr)
        np.testing.assert_array_equal(indices, want.indices)
        np.testing.assert_array_equal(data, want.data)


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
            pose, score = correlative_search(f, pts, np.array([0.02, -0.03, 0.0]), lin_window=window,
                                             ang_window=0.02, ang_step=0.01)  # fmt: skip
            want = np.zeros(3) if window > 0 else np.array([0.02, -0.03, 0.0])
            np.testing.assert_allclose(pose, want, atol=0.051)
            assert 0.0 < score <= 1.0
