"""amcl's compiled passes give what its NumPy expressions gave, bit for bit: the motion model, the cluster
statistics, KLD-sampling over candidates read in place, and the particles' grid coordinates."""

from __future__ import annotations

import math

import numpy as np

from navlab.geometry import wrap_angle
from navlab.localization.field import build_field
from navlab.localization.models import _grid_columns, sample_motion_diff
from navlab.localization.sampling import cluster, kld_count


def _bits(a: np.ndarray) -> bytes:
    return np.ascontiguousarray(a, dtype=np.float64).tobytes()


def _numpy_motion(particles: np.ndarray, old: tuple, new: tuple, alphas: tuple, rng: np.random.Generator) -> None:
    """The motion model as NumPy expressions (``diff``: the variances passed as deviations, as ROS does)."""
    a1, a2, a3, a4 = alphas
    dx, dy = new[0] - old[0], new[1] - old[1]
    dth = float(wrap_angle(np.asarray(new[2]) - np.asarray(old[2])))
    trans = math.hypot(dx, dy)
    rot1 = 0.0 if trans < 0.01 else float(wrap_angle(np.asarray(math.atan2(dy, dx)) - np.asarray(old[2])))
    rot2 = float(wrap_angle(np.asarray(dth) - np.asarray(rot1)))
    r1 = min(abs(float(wrap_angle(np.asarray(rot1)))), abs(float(wrap_angle(np.asarray(rot1) - math.pi))))
    r2 = min(abs(float(wrap_angle(np.asarray(rot2)))), abs(float(wrap_angle(np.asarray(rot2) - math.pi))))
    s_rot1, s_trans, s_rot2 = (
        a1 * r1**2 + a2 * trans**2,
        a3 * trans**2 + a4 * r1**2 + a4 * r2**2,
        a1 * r2**2 + a2 * trans**2,
    )
    noise = rng.standard_normal((3, particles.shape[0]))
    heading = particles[:, 2] + (rot1 - s_rot1 * noise[0])
    trans_hat = trans - s_trans * noise[1]
    particles[:, 0] += trans_hat * np.cos(heading)
    particles[:, 1] += trans_hat * np.sin(heading)
    particles[:, 2] = wrap_angle(heading + (rot2 - s_rot2 * noise[2]))


def test_motion_model_moves_particles_as_the_numpy_expressions() -> None:
    """Forwards, backwards, turning on the spot and across ±pi, from particles spread over every yaw."""
    rng = np.random.default_rng(4)
    start = np.column_stack([rng.normal(0, 3, 2000), rng.normal(0, 3, 2000), rng.uniform(-math.pi, math.pi, 2000)])
    steps = [
        ((0.0, 0.0, 0.0), (0.3, 0.1, 0.2)),
        ((1.0, 1.0, 3.1), (0.8, 1.0, -3.1)),
        ((2.0, 0.0, 0.5), (2.0, 0.0, 1.4)),
    ]
    for old, new in steps:
        mine, ref = start.copy(), start.copy()
        sample_motion_diff(mine, old, new, (0.2, 0.2, 0.2, 0.2), np.random.default_rng(9))
        _numpy_motion(ref, old, new, (0.2, 0.2, 0.2, 0.2), np.random.default_rng(9))
        assert _bits(mine) == _bits(ref)


def test_cluster_statistics_are_the_numpy_formulas() -> None:
    rng = np.random.default_rng(6)
    poses = np.vstack([rng.normal((1, 1, 3.1), (0.3, 0.3, 0.2), (400, 3)), rng.normal((4, -2, 0), 0.1, (30, 3))])
    poses[:, 2] = wrap_angle(poses[:, 2])
    w = rng.random(poses.shape[0])
    w /= w.sum()
    c = cluster(poses, w)
    for k in range(c.weight.size):
        m = c.labels == k
        ws = w[m].sum()
        mx, my = (w[m] * poses[m, 0]).sum() / ws, (w[m] * poses[m, 1]).sum() / ws
        assert math.isclose(c.weight[k], ws, rel_tol=1e-12)
        assert np.allclose(c.mean[k, :2], (mx, my), rtol=1e-12, atol=1e-12)
        assert math.isclose(c.cov[k, 0, 0], max((w[m] * poses[m, 0] ** 2).sum() / ws - mx**2, 0.0), abs_tol=1e-12)
    # bit for bit against the NumPy evaluation of the same per-cluster sums
    acc = np.zeros((c.weight.size, 8))
    for k, label in enumerate(c.labels):
        x, y, t = poses[k]
        wk = w[k]
        acc[label] += [wk, wk * x, wk * y, wk * math.cos(t), wk * math.sin(t), wk * x * x, wk * y * y, wk * x * y]
    mx, my, cth, sth = (acc[:, i] / acc[:, 0] for i in (1, 2, 3, 4))
    assert _bits(c.mean[:, 2]) == _bits(np.arctan2(sth, cth))
    assert _bits(c.cov[:, 2, 2]) == _bits(-2.0 * np.log(np.clip(np.hypot(cth, sth), 1e-12, 1.0)))
    assert _bits(c.cov[:, 0, 0]) == _bits(np.maximum(acc[:, 5] / acc[:, 0] - mx**2, 0.0))
    assert _bits(c.cov[:, 0, 1]) == _bits(acc[:, 7] / acc[:, 0] - mx * my)


def test_kld_count_reads_candidates_in_place() -> None:
    rng = np.random.default_rng(3)
    particles = rng.normal(0, 2, (700, 3))
    for _ in range(5):
        order = rng.integers(0, 700, 5000)
        assert kld_count(particles, 0.01, 0.99, 100, 5000, order=order) == kld_count(
            particles[order], 0.01, 0.99, 100, 5000
        )


def test_grid_columns_are_to_grid_on_a_rotated_origin() -> None:
    field = build_field(np.zeros((20, 20), np.int8), 0.05, (1.3, -0.7, 0.4))
    poses = np.random.default_rng(8).normal(0, 3, (500, 3))
    cols = np.empty((3, 500))
    _grid_columns(poses, *field.origin, math.cos(0.4), math.sin(0.4), cols)
    assert _bits(cols.T) == _bits(field.to_grid(poses))
