"""AMCL's parts alone: ray casting, distance field, motion model, resampling, KLD bound, clustering."""

from __future__ import annotations

import math

import numpy as np

from navlab.localization import build_field, cast_rays
from navlab.localization.models import sample_motion_diff
from navlab.localization.sampling import cluster, kld_count, kld_limit, low_variance_indices


def _box_room() -> np.ndarray:
    g = np.zeros((40, 60), dtype=np.int8)  # 3 m × 2 m at 5 cm
    g[0, :] = g[-1, :] = 100
    g[:, 0] = g[:, -1] = 100
    return g


def test_rays_hit_walls_at_their_faces() -> None:
    field = build_field(_box_room(), 0.05, (-1.0, -0.5, 0.0))
    # robot at map (0.0, 0.5): grid (1.0, 1.0); inner wall faces at grid x = 0.05, 2.95, y = 0.05, 1.95
    g = field.to_grid(np.array([[0.0, 0.5, 0.0]]))
    r = cast_rays(field.occupied, field.resolution, g, np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), 10.0)[0]
    np.testing.assert_allclose(r, [1.95, 0.95, 0.95, 0.95], atol=1e-9)
    diag = cast_rays(field.occupied, field.resolution, g, np.array([math.atan2(0.95, 0.95)]), 10.0)[0, 0]
    assert abs(diag - math.hypot(0.95, 0.95)) < 1e-6
    short = cast_rays(field.occupied, field.resolution, g, np.array([0.0]), 1.0)[0, 0]
    assert short == 1.0  # nothing within max range


def test_rotated_map_origin_round_trips_and_the_field_is_zero_on_walls() -> None:
    field = build_field(_box_room(), 0.05, (2.0, 1.0, 0.7))
    poses = np.array([[2.5, 1.9, 0.3], [0.0, 0.0, -3.0]])
    back = field.from_grid(field.to_grid(poses))
    np.testing.assert_allclose(back, poses, atol=1e-12)
    assert np.all(field.distance[field.occupied] == 0)
    assert math.isclose(float(field.distance[20, 30]), 0.95, abs_tol=1e-6)  # centre of the room
    assert np.all(field.signed[field.occupied] < 0) and np.all(field.signed[field.free] > 0)
    assert not field.is_free(2.0 - 0.01, 1.0 - 0.01)  # just outside cell (0, 0)


def test_motion_model_moves_particles_by_the_odometry_delta_in_their_own_frame() -> None:
    rng = np.random.default_rng(0)
    parts = np.tile([[1.0, 2.0, math.pi / 2]], (4000, 1))
    # odometry: drove 1 m forward while turning 90° left, starting at odom yaw 0
    sample_motion_diff(parts, (0.0, 0.0, 0.0), (1.0, 0.0, math.pi / 2), (0.0, 0.0, 0.0, 0.0), rng)
    np.testing.assert_allclose(parts[0], [1.0, 3.0, -math.pi], atol=1e-9)  # yaw wrapped to [-pi, pi)
    parts = np.tile([[1.0, 2.0, math.pi / 2]], (4000, 1))
    sample_motion_diff(parts, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.1), rng, corrected=True)
    # mean lands about 1 m ahead (a little short: heading noise ~0.3 rad shortens E[cos])
    assert abs(parts[:, 0].mean() - 1.0) < 0.03 and 2.9 < parts[:, 1].mean() < 3.0
    assert 0.2 < parts[:, 1].std() < 0.45  # sqrt(alpha3) * 1 m ≈ 0.32 m
    tiny = np.tile([[0.0, 0.0, 0.0]], (4000, 1))
    sample_motion_diff(tiny, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.1), rng)  # ROS 'diff'
    assert tiny[:, 0].std() < 0.15  # variance used as std: 0.1 m


def test_low_variance_resampling_reproduces_the_weights() -> None:
    rng = np.random.default_rng(0)
    w = np.array([0.1, 0.0, 0.6, 0.3])
    idx = low_variance_indices(w, 1000, rng)
    counts = np.bincount(idx, minlength=4)
    assert counts[1] == 0
    np.testing.assert_allclose(counts / 1000, w, atol=0.002)  # systematic: within one draw


def test_kld_bound_grows_with_occupied_bins_and_is_clamped() -> None:
    n = kld_limit(np.array([1, 2, 10, 100, 1000]), 0.01, 0.99, 100, 5000)
    assert n[0] == 5000  # one bin: ROS keeps drawing up to the maximum
    assert n[1] == 100 and n[1] < n[2] < n[3] and n[-1] == 5000
    rng = np.random.default_rng(1)
    tight = np.column_stack([rng.normal(1.0, 0.05, 5000), rng.normal(1.0, 0.05, 5000), rng.normal(0, 0.02, 5000)])
    wide = np.column_stack([rng.uniform(0, 8, 5000), rng.uniform(0, 6, 5000), rng.uniform(-3, 3, 5000)])
    assert kld_count(tight, 0.01, 0.99, 100, 5000) < 1000  # straddles bin edges: 8 bins
    tight[:, :2] += 0.25  # now inside one 0.5 m bin: as in ROS, one bin keeps drawing to the maximum
    tight[:, 2] = np.abs(tight[:, 2]) + 0.01
    assert kld_count(tight, 0.01, 0.99, 100, 5000) == 5000
    assert kld_count(wide, 0.01, 0.99, 100, 5000) == 5000


def test_clusters_separate_hypotheses_and_wrap_yaw() -> None:
    rng = np.random.default_rng(2)
    a = np.column_stack([rng.normal(1.0, 0.05, 300), rng.normal(1.0, 0.05, 300), rng.normal(math.pi - 0.01, 0.03, 300)])
    a[:, 2] = (a[:, 2] + math.pi) % (2 * math.pi) - math.pi  # straddles ±pi
    b = np.column_stack([rng.normal(5.0, 0.05, 100), rng.normal(3.0, 0.05, 100), np.zeros(100)])
    poses = np.vstack([a, b])
    w = np.full(400, 1 / 400)
    c = cluster(poses, w)
    assert c.weight.size == 2
    best = c.best
    assert math.isclose(c.weight[best], 0.75)
    assert math.dist(c.mean[best, :2], (1.0, 1.0)) < 0.02
    assert abs(math.remainder(c.mean[best, 2] - (math.pi - 0.01), 2 * math.pi)) < 0.01
    assert 0.001 < c.cov[best, 0, 0] < 0.005 and c.cov[best, 2, 2] < 0.005
    w2 = np.where(np.arange(400) < 300, 0.1 / 300, 0.9 / 100)
    assert math.dist(cluster(poses, w2).mean[cluster(poses, w2).best, :2], (5.0, 3.0)) < 0.02
