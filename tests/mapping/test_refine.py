"""The refinement's pose graph: a verified match's information follows its ICP Hessian (weak along a corridor's
axis, where the scans cannot place it), and the graph's fill-reducing solve equals a dense solve."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.geometry import between2
from navlab.mapping.posegraph import PoseGraph, _System
from navlab.mapping.refine import RefineParams, _match
from navlab.mapping.scanmatch import ScanPoints


def _walls(*walls: tuple[np.ndarray, np.ndarray]) -> ScanPoints:
    """Points every 4 cm along segments (start, end) with their unit normals, in the scan's frame."""
    xy, normals = [], []
    for a, b in walls:
        n = int(np.hypot(*(b - a)) / 0.04)
        t = np.linspace(0.0, 1.0, n)[:, None]
        xy.append(a + t * (b - a))
        d = (b - a) / np.hypot(*(b - a))
        normals.append(np.tile([-d[1], d[0]], (n, 1)))
    return ScanPoints(np.concatenate(xy), np.concatenate(normals))


CORRIDOR = (np.array([-4.0, 1.0]), np.array([4.0, 1.0])), (np.array([-4.0, -1.0]), np.array([4.0, -1.0]))
END_WALL = (np.array([3.0, -1.0]), np.array([3.0, 1.0]))


@pytest.mark.parametrize("theta", [0.0, 0.7])
def test_a_corridor_match_is_weak_along_the_corridor_and_a_closed_one_keeps_the_plain_sigmas(theta):
    p = RefineParams(shape_xy=2.0)
    strong = np.diag([p.sigma_xy**-2, p.sigma_xy**-2, p.sigma_theta**-2])
    rel = np.array([0.1, 0.0, theta])
    c, s = np.cos(theta), np.sin(theta)
    along = np.array([c, -s])  # the corridor's axis (x of scan a) in scan b's frame, where the edge error is
    for walls, open_end in ((CORRIDOR, True), ((*CORRIDOR, END_WALL), False)):
        a = _walls(*walls)
        # scan b sees the same walls from rel: its points in its own frame
        rot = np.array([[c, s], [-s, c]])
        b = ScanPoints((a.xy - rel[:2]) @ rot.T, a.normals @ rot.T)
        pose, ok, info = _match(a, b, rel, p)
        assert ok and np.allclose(pose, rel, atol=1e-3)
        across = np.array([-along[1], along[0]])
        assert along @ info[:2, :2] @ along <= strong[0, 0] * (0.05 if open_end else 1.0)
        assert across @ info[:2, :2] @ across == pytest.approx(strong[0, 0], rel=0.35)
        assert np.all(
            np.linalg.eigvalsh(np.diag(np.diag(strong) ** -0.5) @ info @ np.diag(np.diag(strong) ** -0.5)) <= 1 + 1e-9
        )
        if not open_end:
            assert along @ info[:2, :2] @ along > 0.2 * strong[0, 0]
    assert np.array_equal(_match(a, b, rel, RefineParams())[2], strong)  # shape_xy 0: the plain sigmas


def test_the_graph_solve_equals_a_dense_solve():
    rng = np.random.default_rng(1)
    n = 30
    poses = np.cumsum(rng.normal(0.0, 0.5, (n, 3)), axis=0)
    g = PoseGraph(poses=poses.copy())
    pairs = [(k - 1, k) for k in range(1, n)] + [(int(i), int(j)) for i, j in rng.integers(0, n, (25, 2)) if i < j]
    for i, j in pairs:
        g.add_edge(i, j, between2(poses[i], poses[j]) + rng.normal(0.0, 0.05, 3), np.diag([50.0, 80.0, 300.0]))
    i, j, _z, _info = g._edge_arrays()
    system = _System(i, j, n)
    blocks = rng.normal(0.0, 1.0, (4, len(i), 3, 3))
    blocks[0] = blocks[0] @ blocks[0].transpose(0, 2, 1) + 3 * np.eye(3)  # positive definite diagonal blocks
    blocks[3] = blocks[3] @ blocks[3].transpose(0, 2, 1) + 3 * np.eye(3)
    blocks[2] = blocks[1].transpose(0, 2, 1)
    dense = np.zeros((3 * n, 3 * n))
    for e, (a, b) in enumerate(zip(i, j, strict=True)):
        for blk, (r, c) in zip(blocks, ((a, a), (a, b), (b, a), (b, b)), strict=True):
            dense[3 * r : 3 * r + 3, 3 * c : 3 * c + 3] += blk[e]
    rhs = rng.normal(0.0, 1.0, 3 * n - 3)
    want = np.linalg.solve(dense[3:, 3:] + 1e-9 * np.eye(3 * n - 3), rhs)
    assert np.allclose(system.solve(np.concatenate([b.ravel() for b in blocks]), rhs), want, atol=1e-9)
