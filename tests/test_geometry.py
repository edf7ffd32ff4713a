"""Property tests of navlab.geometry (seeded, randomized): identities, inverses and round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab import geometry as g

RNG_SEED = 20261123


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(RNG_SEED)


def _pose2(rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-math.pi, math.pi)])


def _tf(rng: np.random.Generator) -> g.Tf:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return g.tf_from_xyz_quat(rng.uniform(-5, 5, 3), q)


def _close_tf(a: g.Tf, b: g.Tf, tol: float = 1e-9) -> bool:
    same_t = np.allclose(a[:3], b[:3], atol=tol)
    qa, qb = np.array(a[3:]), np.array(b[3:])
    return same_t and (np.allclose(qa, qb, atol=tol) or np.allclose(qa, -qb, atol=tol))


def test_wrap_angle_range_and_identity(rng: np.random.Generator) -> None:
    a = rng.uniform(-50, 50, 1000)
    w = g.wrap_angle(a)
    assert np.all(w >= -math.pi) and np.all(w < math.pi)
    assert np.allclose(np.sin(w), np.sin(a)) and np.allclose(np.cos(w), np.cos(a))
    assert isinstance(g.wrap_angle(3 * math.pi), float)
    assert g.angle_diff(math.pi - 0.1, -math.pi + 0.1) == pytest.approx(-0.2)


def test_se2_compose_inverse_identities(rng: np.random.Generator) -> None:
    for _ in range(200):
        a, b, c = _pose2(rng), _pose2(rng), _pose2(rng)
        assert np.allclose(g.compose2(a, g.inverse2(a)), 0.0, atol=1e-9)
        assert np.allclose(g.compose2(g.inverse2(a), a), 0.0, atol=1e-9)
        left = g.compose2(g.compose2(a, b), c)
        right = g.compose2(a, g.compose2(b, c))
        assert np.allclose(left[:2], right[:2]) and abs(g.wrap_angle(float(left[2] - right[2]))) < 1e-9
        assert np.allclose(g.compose2(a, g.between2(a, b))[:2], b[:2])


def test_se2_points_round_trip(rng: np.random.Generator) -> None:
    pose = _pose2(rng)
    pts = rng.uniform(-3, 3, (50, 2))
    world = g.transform_points2(pose, pts)
    assert np.allclose(g.inverse_transform_points2(pose, world), pts)
    # a point transformed equals composing its pose
    p = g.compose2(pose, (pts[0, 0], pts[0, 1], 0.0))
    assert np.allclose(world[0], p[:2])
    many = g.compose2_many(pose, np.column_stack([pts, np.zeros(50)]))
    assert np.allclose(many[:, :2], world)


def test_se3_compose_inverse_identities(rng: np.random.Generator) -> None:
    for _ in range(200):
        a, b, c = _tf(rng), _tf(rng), _tf(rng)
        assert _close_tf(g.compose3(a, g.inverse3(a)), g.IDENTITY_TF)
        assert _close_tf(g.compose3(g.compose3(a, b), c), g.compose3(a, g.compose3(b, c)))
        assert _close_tf(g.inverse3(g.inverse3(a)), a)


def test_se3_agrees_with_matrices(rng: np.random.Generator) -> None:
    for _ in range(50):
        a, b = _tf(rng), _tf(rng)
        ma, mb = np.eye(4), np.eye(4)
        ma[:3, :3], ma[:3, 3] = g.matrix_from_quat(a[3:]), a[:3]
        mb[:3, :3], mb[:3, 3] = g.matrix_from_quat(b[3:]), b[:3]
        ab = g.compose3(a, b)
        mab = ma @ mb
        assert np.allclose(mab[:3, :3], g.matrix_from_quat(ab[3:]))
        assert np.allclose(mab[:3, 3], ab[:3])


def test_quaternion_rpy_round_trips(rng: np.random.Generator) -> None:
    for _ in range(200):
        r, p, y = rng.uniform(-math.pi, math.pi), rng.uniform(-1.5, 1.5), rng.uniform(-math.pi, math.pi)
        q = g.quat_from_rpy(r, p, y)
        assert np.allclose(g.matrix_from_quat(q), g.matrix_from_rpy(r, p, y))
        assert np.allclose(g.rpy_from_quat(q), (r, p, y))
        assert g.yaw_from_quat(g.quat_from_yaw(y)) == pytest.approx(y)
        pose6 = (*rng.uniform(-2, 2, 3), r, p, y)
        assert np.allclose(g.pose6_from_matrix(g.matrix_from_pose6(pose6)), pose6)


def test_mujoco_boundary_order() -> None:
    q = g.quat_from_yaw(0.5)  # (x, y, z, w)
    wxyz = g.wxyz_from_xyzw(q)
    assert wxyz[0] == pytest.approx(math.cos(0.25)) and wxyz[3] == pytest.approx(math.sin(0.25))
    assert g.xyzw_from_wxyz(wxyz) == pytest.approx(q)


def test_interpolate_endpoints_and_midpoint(rng: np.random.Generator) -> None:
    a, b = g.tf_from_pose2(0, 0, 0.0), g.tf_from_pose2(2, 4, 1.0)
    assert _close_tf(g.interpolate3(a, b, 0.0), a) and _close_tf(g.interpolate3(a, b, 1.0), b)
    mid = g.interpolate3(a, b, 0.5)
    assert g.pose2_from_tf(mid) == pytest.approx((1.0, 2.0, 0.5))
    for _ in range(50):
        x, y = _tf(rng), _tf(rng)
        m = g.interpolate3(x, y, float(rng.uniform()))
        assert np.linalg.norm(m[3:]) == pytest.approx(1.0)
