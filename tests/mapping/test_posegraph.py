"""Sparse pose-graph optimisation: a noisy square loop is closed and an outlier edge is ignored."""

from __future__ import annotations

import numpy as np

from navlab.geometry import between2, compose2
from navlab.mapping.posegraph import PoseGraph


def _square(n: int = 40) -> np.ndarray:
    gt = [np.zeros(3)]
    for k in range(n):
        step = np.array([0.5, 0, np.pi / 2]) if k % 10 == 9 else np.array([0.5, 0, 0])
        gt.append(compose2(gt[-1], step))
    return np.array(gt)


def test_loop_closure_pulls_drifted_chain_back_and_outlier_is_ignored():
    rng = np.random.default_rng(3)
    gt = _square()
    n = len(gt)
    g = PoseGraph()
    est = [gt[0]]
    meas = [between2(gt[k - 1], gt[k]) + rng.normal(0, [0.01, 0.01, 0.02]) for k in range(1, n)]
    for z in meas:
        est.append(compose2(est[-1], z))
    for p in est:
        g.add_node(p)
    info = np.diag([1e4, 1e4, 2500.0])
    for k, z in enumerate(meas, 1):
        g.add_edge(k - 1, k, z, info)
    drift_before = np.hypot(*(g.poses[-1] - gt[-1])[:2])
    g.add_edge(0, n - 1, between2(gt[0], gt[-1]), info * 10, robust=True)
    g.add_edge(5, 35, np.array([3.0, 3.0, 1.0]), info * 10, robust=True)  # a wrong loop closure
    g.optimize(iterations=30)
    drift_after = np.hypot(*(g.poses[-1] - gt[-1])[:2])
    assert drift_before > 0.3
    assert drift_after < 0.05
    assert np.abs(g.poses[:, :2] - gt[:, :2]).max() < 0.25
    assert g.edge_distances()[-1] > 10  # the outlier stays unexplained
