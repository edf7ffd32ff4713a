"""An extended Kalman filter as robot_localization's ``ekf_node`` runs it (pure: numpy in, numpy out).

State (15, robot_localization's order and masks): ``x y z roll pitch yaw`` (pose in the world frame,
m and rad, fixed-axis roll-pitch-yaw), ``vx vy vz vroll vpitch vyaw`` (body-frame velocities, m/s and
rad/s) and ``ax ay az`` (body-frame linear acceleration, m/s²). The motion model is
robot_localization's omnidirectional constant-acceleration model; its Jacobian is taken numerically
(one vectorised pass over 30 perturbed states). ``two_d_mode`` pins z, roll, pitch, their rates and
az to 0. The process noise is scaled by the time step, as robot_localization does.

A measurement is a full 15-vector ``z`` with its 15×15 covariance ``R`` and a 15-boolean ``mask`` of
the entries to fuse (an input's ``*_config``); :meth:`Ekf.correct` rejects it when the Mahalanobis
distance of its innovation exceeds ``threshold``. Helpers build measurements from odometry, IMU and
pose/twist data and carry an input's differential and relative modes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from navlab.geometry import matrix_from_pose6, matrix_from_rpy, rpy_from_matrix
from navlab.localization.errors import LocalizationError

STATE = ("x", "y", "z", "roll", "pitch", "yaw", "vx", "vy", "vz", "vroll", "vpitch", "vyaw", "ax", "ay", "az")
N = 15
ANGLES = (3, 4, 5)
TWO_D_FIXED = (2, 3, 4, 8, 9, 10, 14)  # z roll pitch vz vroll vpitch az
#: robot_localization's default process noise (diagonal) and initial estimate covariance
DEFAULT_PROCESS_NOISE = (0.05, 0.05, 0.06, 0.03, 0.03, 0.06, 0.025, 0.025, 0.04, 0.01, 0.01, 0.02, 0.01, 0.01, 0.015)
DEFAULT_INITIAL_COVARIANCE = (1e-9,) * N


def mask_from(value: Any, key: str) -> np.ndarray:
    """A 15-boolean config mask (``odom0_config``...) as a bool array; a clear error otherwise."""
    if not isinstance(value, list | tuple) or len(value) != N or not all(isinstance(v, bool | np.bool_) for v in value):
        got = f"{len(value)} values" if isinstance(value, list | tuple) else repr(value)
        raise LocalizationError(f"{key}: expected 15 booleans ({' '.join(STATE)}), got {got}")
    return np.array(value, dtype=bool)


def matrix_from(value: Any, key: str) -> np.ndarray:
    """A 15×15 covariance from 225 numbers (row-major) or 15 (the diagonal); symmetric, diagonal >= 0."""
    a = np.asarray(value, dtype=np.float64).ravel() if isinstance(value, list | tuple | np.ndarray) else None
    if a is None or a.size not in (N, N * N) or not np.isfinite(a).all():
        got = f"{len(value)} values" if isinstance(value, list | tuple) else repr(value)
        raise LocalizationError(f"{key}: expected 225 finite numbers (a 15x15 matrix, row-major) or 15 (its "
                                f"diagonal), got {got}")  # fmt: skip
    m = np.diag(a) if a.size == N else a.reshape(N, N)
    if (np.diag(m) < 0).any():
        bad = [STATE[i] for i in np.flatnonzero(np.diag(m) < 0)]
        raise LocalizationError(f"{key}: diagonal entries must be >= 0, negative for {', '.join(bad)}")
    if not np.allclose(m, m.T):
        raise LocalizationError(f"{key}: the matrix must be symmetric")
    return m


def transition(states: np.ndarray, dt: float) -> np.ndarray:
    """Each state (..., 15) moved ``dt`` s ahead by the constant-acceleration model (body-frame rates)."""
    s = np.array(states, dtype=np.float64, copy=True)
    r, p, y = s[..., 3], s[..., 4], s[..., 5]
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    d = s[..., 6:9] * dt + 0.5 * s[..., 12:15] * dt * dt  # body-frame displacement
    s[..., 0] += cy * cp * d[..., 0] + (cy * sp * sr - sy * cr) * d[..., 1] + (cy * sp * cr + sy * sr) * d[..., 2]
    s[..., 1] += sy * cp * d[..., 0] + (sy * sp * sr + cy * cr) * d[..., 1] + (sy * sp * cr - cy * sr) * d[..., 2]
    s[..., 2] += -sp * d[..., 0] + cp * sr * d[..., 1] + cp * cr * d[..., 2]
    wr, wp, wy = s[..., 9], s[..., 10], s[..., 11]
    cp_safe = np.where(np.abs(cp) < 1e-9, 1e-9, cp)
    tp = sp / cp_safe
    s[..., 3] += (wr + sr * tp * wp + cr * tp * wy) * dt
    s[..., 4] += (cr * wp - sr * wy) * dt
    s[..., 5] += (sr / cp_safe * wp + cr / cp_safe * wy) * dt
    s[..., 6:9] += s[..., 12:15] * dt
    s[..., 3:6] = np.arctan2(np.sin(s[..., 3:6]), np.cos(s[..., 3:6]))
    return s


def jacobian(state: np.ndarray, dt: float, eps: float = 1e-6) -> np.ndarray:
    """∂transition/∂state (15×15) by central differences, all 30 perturbed states in one pass."""
    pert = np.concatenate([state + eps * np.eye(N), state - eps * np.eye(N)])
    out = transition(pert, dt)
    diff = out[:N] - out[N:]
    diff[:, 3:6] = np.arctan2(np.sin(diff[:, 3:6]), np.cos(diff[:, 3:6]))
    return (diff / (2 * eps)).T


class Ekf:
    """The filter: ``state`` (15,), ``covariance`` (15, 15); ``predict(dt)`` and ``correct(z, R, mask)``."""

    def __init__(self, *, process_noise: np.ndarray | Sequence[float] = DEFAULT_PROCESS_NOISE,
                 initial_covariance: np.ndarray | Sequence[float] = DEFAULT_INITIAL_COVARIANCE,
                 two_d_mode: bool = False, initial_state: Sequence[float] | None = None) -> None:  # fmt: skip
        self.process_noise = matrix_from(list(np.asarray(process_noise).ravel()), "process_noise_covariance")
        self.covariance = matrix_from(list(np.asarray(initial_covariance).ravel()), "initial_estimate_covariance")
        self.state = np.zeros(N)
        if initial_state is not None:
            init = np.asarray(initial_state, dtype=np.float64).ravel()
            if init.shape != (N,) or not np.isfinite(init).all():
                raise LocalizationError(f"initial_state: expected 15 finite numbers ({' '.join(STATE)})")
            self.state = init.copy()
        self.two_d_mode = bool(two_d_mode)
        self.initialized = False
        self.last_rejected = False  # whether the last correct() was refused by its Mahalanobis threshold
        self._pin()

    def _pin(self) -> None:
        if self.two_d_mode:
            k = list(TWO_D_FIXED)
            self.state[k] = 0.0
            self.covariance[k, :] = 0.0
            self.covariance[:, k] = 0.0

    def predict(self, dt: float) -> None:
        """Advance ``dt`` s: x = f(x), P = J P Jᵀ + Q·dt (``dt`` <= 0: nothing)."""
        if not (dt > 0 and math.isfinite(dt)):
            return
        j = jacobian(self.state, dt)
        self.state = transition(self.state, dt)
        self.covariance = j @ self.covariance @ j.T + self.process_noise * dt
        self._pin()

    def correct(self, z: np.ndarray, r: np.ndarray, mask: np.ndarray, threshold: float = math.inf) -> bool:
        """Fuse the masked entries of measurement ``z`` (15,) with covariance ``r`` (15, 15); False when
        rejected (Mahalanobis distance of the innovation > ``threshold``) or nothing is fused."""
        self.last_rejected = False
        mask = np.asarray(mask, dtype=bool).copy()
        if self.two_d_mode:
            mask[list(TWO_D_FIXED)] = False
        mask &= np.isfinite(z)
        idx = np.flatnonzero(mask)
        if idx.size == 0:
            return False
        z, r = np.asarray(z, dtype=np.float64), np.asarray(r, dtype=np.float64)
        if not self.initialized:  # robot_localization starts from the first measurement's values
            self.state[idx] = z[idx]
            self.initialized = True
            self._pin()
            return True
        innov = z[idx] - self.state[idx]
        ang = np.isin(idx, ANGLES)
        innov[ang] = np.arctan2(np.sin(innov[ang]), np.cos(innov[ang]))
        rr = r[np.ix_(idx, idx)].copy()
        rr[np.diag_indices_from(rr)] = np.maximum(np.diag(rr), 1e-9)  # as robot_localization: no zero variance
        p = self.covariance
        s = p[np.ix_(idx, idx)] + rr
        try:
            s_inv = np.linalg.inv(s)
        except np.linalg.LinAlgError:
            return False
        if math.isfinite(threshold) and float(innov @ s_inv @ innov) > threshold * threshold:
            self.last_rejected = True
            return False
        k = p[:, idx] @ s_inv  # P Hᵀ S⁻¹ with H the rows idx of the identity
        self.state = self.state + k @ innov
        self.state[3:6] = np.arctan2(np.sin(self.state[3:6]), np.cos(self.state[3:6]))
        ikh = np.eye(N)
        ikh[:, idx] -= k
        self.covariance = ikh @ p @ ikh.T + k @ rr @ k.T  # Joseph form
        self._pin()
        return True


# --- measurements ------------------------------------------------------------------------------------


def measurement(values: dict[int, float], cov: np.ndarray | None = None,
                first: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(z, R) with ``values`` at state indices and the block ``cov`` (k×k) placed from index ``first``."""
    z = np.full(N, np.nan)
    for i, v in values.items():
        z[i] = v
    r = np.zeros((N, N))
    if cov is not None:
        k = cov.shape[0]
        r[first:first + k, first:first + k] = cov
    return z, r


def pose_measurement(pose6: Sequence[float], cov6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A pose (x y z roll pitch yaw in the world frame) with its 6×6 covariance."""
    return measurement({i: float(v) for i, v in enumerate(pose6)}, np.asarray(cov6).reshape(6, 6), 0)


def twist_measurement(twist6: Sequence[float] | np.ndarray, cov6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A body-frame twist (vx vy vz vroll vpitch vyaw) with its 6×6 covariance."""
    return measurement({6 + i: float(v) for i, v in enumerate(twist6)}, np.asarray(cov6).reshape(6, 6), 6)


def merge(*parts: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """One measurement from several (entries given in a later part win)."""
    z, r = np.full(N, np.nan), np.zeros((N, N))
    for zi, ri in parts:
        ok = np.isfinite(zi)
        z[ok] = zi[ok]
        blk = np.ix_(ok, ok)
        r[blk] = ri[blk]
    return z, r


def imu_measurement(base_R_imu: np.ndarray, *, orientation_rpy: Sequence[float] | None, orientation_cov: np.ndarray,
                    angular_velocity: Sequence[float], angular_velocity_cov: np.ndarray,
                    linear_acceleration: Sequence[float], linear_acceleration_cov: np.ndarray,
                    remove_gravity: bool = False,
                    gravity: float = 9.80665) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """An IMU reading (in the IMU frame) as a base-frame measurement: orientation (the IMU frame's in the
    world, turned into the base's), angular velocity and linear acceleration rotated into the base frame;
    with ``remove_gravity`` the gravity the accelerometer reads is subtracted (using the orientation)."""
    rot = np.asarray(base_R_imu, dtype=np.float64)
    parts = []
    world_R_base = None
    if orientation_rpy is not None and all(math.isfinite(v) for v in orientation_rpy):
        world_R_base = matrix_from_rpy(*orientation_rpy) @ rot.T
        oc = rot @ np.asarray(orientation_cov).reshape(3, 3) @ rot.T
        parts.append(measurement(dict(zip((3, 4, 5), rpy_from_matrix(world_R_base), strict=True)), oc, 3))
    w = rot @ np.asarray(angular_velocity, dtype=np.float64)
    parts.append(measurement(dict(zip((9, 10, 11), w, strict=True)),
                             rot @ np.asarray(angular_velocity_cov).reshape(3, 3) @ rot.T, 9))  # fmt: skip
    a = rot @ np.asarray(linear_acceleration, dtype=np.float64)
    if remove_gravity:
        up = world_R_base.T @ np.array([0.0, 0.0, gravity]) if world_R_base is not None else np.array([0, 0, gravity])
        a = a - up
    parts.append(measurement(dict(zip((12, 13, 14), a, strict=True)),
                             rot @ np.asarray(linear_acceleration_cov).reshape(3, 3) @ rot.T, 12))  # fmt: skip
    return merge(*parts)


class PoseInput:
    """An input's pose handling: ``relative`` (poses relative to the first one) and ``differential``
    (consecutive poses differenced into a body-frame twist, fused as velocities)."""

    def __init__(self, *, differential: bool = False, relative: bool = False) -> None:
        self.differential, self.relative = differential, relative
        self._first: np.ndarray | None = None
        self._prev: tuple[np.ndarray, np.ndarray, float] | None = None

    def convert(self, pose6: Sequence[float], cov6: np.ndarray, t: float,
                mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:  # fmt: skip
        """(z, R, mask) of a pose at time ``t`` (s), or None (the first pose of a differential input)."""
        m = matrix_from_pose6([float(v) for v in pose6])
        cov = np.asarray(cov6, dtype=np.float64).reshape(6, 6)
        if self.relative:
            if self._first is None:
                self._first = m
            m = np.linalg.inv(self._first) @ m
        if not self.differential:
            return (*pose_measurement(_pose6(m), cov), mask)
        prev, self._prev = self._prev, (m, cov, t)
        if prev is None or t <= prev[2]:
            return None
        pm, pcov, pt = prev
        dt = t - pt
        delta = np.linalg.inv(pm) @ m  # the motion in the previous body frame
        rot = np.zeros((6, 6))
        rot[:3, :3] = rot[3:, 3:] = pm[:3, :3].T
        tw_cov = rot @ (cov + pcov) @ rot.T / (dt * dt)
        twist = np.array(_pose6(delta)) / dt
        vmask = np.zeros(N, dtype=bool)
        vmask[6:12] = mask[0:6]  # the pose flags become velocity flags
        z, r = twist_measurement(twist, tw_cov)
        return z, r, vmask


def _pose6(m: np.ndarray) -> tuple[float, float, float, float, float, float]:
    r, p, y = rpy_from_matrix(m[:3, :3])
    return float(m[0, 3]), float(m[1, 3]), float(m[2, 3]), r, p, y
