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
from numba import njit

from navlab.geometry import matrix_from_pose6, matrix_from_rpy, rpy_from_matrix
from navlab.localization.errors import LocalizationError

STATE = ("x", "y", "z", "roll", "pitch", "yaw", "vx", "vy", "vz", "vroll", "vpitch", "vyaw", "ax", "ay", "az")
N = 15
ANGLES = (3, 4, 5)
TWO_D_FIXED = (2, 3, 4, 8, 9, 10, 14)  # z roll pitch vz vroll vpitch az
_FIXED = np.array(TWO_D_FIXED)
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
        raise LocalizationError(
            f"{key}: expected 225 finite numbers (a 15x15 matrix, row-major) or 15 (its diagonal), got {got}"
        )
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


@njit(cache=True)
def _step(s: np.ndarray, dt: float, out: np.ndarray) -> None:
    """``transition`` of one state (the compiled twin of the vectorised function above)."""
    for i in range(N):
        out[i] = s[i]
    r, p, y = s[3], s[4], s[5]
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    d0 = s[6] * dt + 0.5 * s[12] * dt * dt
    d1 = s[7] * dt + 0.5 * s[13] * dt * dt
    d2 = s[8] * dt + 0.5 * s[14] * dt * dt
    out[0] += cy * cp * d0 + (cy * sp * sr - sy * cr) * d1 + (cy * sp * cr + sy * sr) * d2
    out[1] += sy * cp * d0 + (sy * sp * sr + cy * cr) * d1 + (sy * sp * cr - cy * sr) * d2
    out[2] += -sp * d0 + cp * sr * d1 + cp * cr * d2
    cps = cp if abs(cp) >= 1e-9 else 1e-9
    tp = sp / cps
    out[3] += (s[9] + sr * tp * s[10] + cr * tp * s[11]) * dt
    out[4] += (cr * s[10] - sr * s[11]) * dt
    out[5] += (sr / cps * s[10] + cr / cps * s[11]) * dt
    for i in range(3):
        out[6 + i] += s[12 + i] * dt
        out[3 + i] = math.atan2(math.sin(out[3 + i]), math.cos(out[3 + i]))


@njit(cache=True)
def _predict(state: np.ndarray, cov: np.ndarray, q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(f(x), J P Jᵀ + Q·dt) with J by central differences."""
    eps = 1e-6
    j = np.empty((N, N))
    plus, minus, work = np.empty(N), np.empty(N), state.copy()
    for k in range(N):
        work[k] = state[k] + eps
        _step(work, dt, plus)
        work[k] = state[k] - eps
        _step(work, dt, minus)
        work[k] = state[k]
        for i in range(N):
            d = plus[i] - minus[i]
            if 3 <= i <= 5:
                d = math.atan2(math.sin(d), math.cos(d))
            j[i, k] = d / (2 * eps)
    out = np.empty(N)
    _step(state, dt, out)
    return out, j @ cov @ j.T + q * dt


@njit(cache=True)
def _correct(
    state: np.ndarray, cov: np.ndarray, z: np.ndarray, r: np.ndarray, idx: np.ndarray, threshold: float
) -> tuple[bool, np.ndarray, np.ndarray]:
    """Kalman update on the entries ``idx``: (accepted, state, covariance); Joseph form."""
    m = idx.size
    innov = np.empty(m)
    s = np.empty((m, m))
    rr = np.empty((m, m))
    for a in range(m):
        ia = idx[a]
        d = z[ia] - state[ia]
        if 3 <= ia <= 5:
            d = math.atan2(math.sin(d), math.cos(d))
        innov[a] = d
        for b in range(m):
            rr[a, b] = r[ia, idx[b]]
        rr[a, a] = max(rr[a, a], 1e-9)
        for b in range(m):
            s[a, b] = cov[ia, idx[b]] + rr[a, b]
    s_inv = np.linalg.inv(s)
    if threshold < np.inf and innov @ s_inv @ innov > threshold * threshold:
        return False, state, cov
    pht = np.empty((N, m))
    for i in range(N):
        for b in range(m):
            pht[i, b] = cov[i, idx[b]]
    k = pht @ s_inv
    new = state + k @ innov
    for i in range(3, 6):
        new[i] = math.atan2(math.sin(new[i]), math.cos(new[i]))
    ikh = np.eye(N)
    for i in range(N):
        for b in range(m):
            ikh[i, idx[b]] -= k[i, b]
    return True, new, ikh @ cov @ ikh.T + k @ rr @ k.T


class Ekf:
    """The filter: ``state`` (15,), ``covariance`` (15, 15); ``predict(dt)`` and ``correct(z, R, mask)``."""

    def __init__(
        self,
        *,
        process_noise: np.ndarray | Sequence[float] = DEFAULT_PROCESS_NOISE,
        initial_covariance: np.ndarray | Sequence[float] = DEFAULT_INITIAL_COVARIANCE,
        two_d_mode: bool = False,
        initial_state: Sequence[float] | None = None,
    ) -> None:
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
            self.state[_FIXED] = 0.0
            self.covariance[_FIXED, :] = 0.0
            self.covariance[:, _FIXED] = 0.0

    def predict(self, dt: float) -> None:
        """Advance ``dt`` s: x = f(x), P = J P Jᵀ + Q·dt (``dt`` <= 0: nothing)."""
        if not (dt > 0 and math.isfinite(dt)):
            return
        self.state, self.covariance = _predict(self.state, self.covariance, self.process_noise, float(dt))
        self._pin()

    def correct(self, z: np.ndarray, r: np.ndarray, mask: np.ndarray, threshold: float = math.inf) -> bool:
        """Fuse the masked entries of measurement ``z`` (15,) with covariance ``r`` (15, 15); False when
        rejected (Mahalanobis distance of the innovation > ``threshold``) or nothing is fused."""
        self.last_rejected = False
        z, r = np.asarray(z, dtype=np.float64), np.asarray(r, dtype=np.float64)
        mask = np.asarray(mask, dtype=bool) & np.isfinite(z)
        if self.two_d_mode:
            mask[_FIXED] = False
        idx = np.flatnonzero(mask)
        if idx.size == 0:
            return False
        if not self.initialized:  # robot_localization starts from the first measurement's values
            self.state[idx] = z[idx]
            self.initialized = True
            self._pin()
            return True
        try:
            ok, state, cov = _correct(self.state, self.covariance, z, r, idx, float(threshold))
        except np.linalg.LinAlgError:  # a singular innovation covariance: nothing fused
            return False
        if not ok:
            self.last_rejected = True
            return False
        self.state, self.covariance = state, cov
        self._pin()
        return True


# --- measurements ------------------------------------------------------------------------------------


def measurement(
    values: dict[int, float], cov: np.ndarray | None = None, first: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """(z, R) with ``values`` at state indices and the block ``cov`` (k×k) placed from index ``first``."""
    z = np.full(N, np.nan)
    for i, v in values.items():
        z[i] = v
    r = np.zeros((N, N))
    if cov is not None:
        k = cov.shape[0]
        r[first : first + k, first : first + k] = cov
    return z, r


def pose_measurement(pose6: Sequence[float], cov6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A pose (x y z roll pitch yaw in the world frame) with its 6×6 covariance."""
    return measurement({i: float(v) for i, v in enumerate(pose6)}, np.asarray(cov6).reshape(6, 6), 0)


def twist_measurement(twist6: Sequence[float] | np.ndarray, cov6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A body-frame twist (vx vy vz vroll vpitch vyaw) with its 6×6 covariance."""
    return measurement({6 + i: float(v) for i, v in enumerate(twist6)}, np.asarray(cov6).reshape(6, 6), 6)


def imu_measurement(
    base_R_imu: np.ndarray,
    *,
    orientation_rpy: Sequence[float] | None,
    orientation_cov: np.ndarray,
    angular_velocity: Sequence[float],
    angular_velocity_cov: np.ndarray,
    linear_acceleration: Sequence[float],
    linear_acceleration_cov: np.ndarray,
    remove_gravity: bool = False,
    gravity: float = 9.80665,
    parts: tuple[bool, bool, bool] = (True, True, True),
) -> tuple[np.ndarray, np.ndarray]:
    """An IMU reading (in the IMU frame) as a base-frame measurement: orientation (the IMU frame's in the
    world, turned into the base's), angular velocity and linear acceleration rotated into the base frame;
    with ``remove_gravity`` the gravity the accelerometer reads is subtracted (using the orientation).
    ``parts``: which of (orientation, angular velocity, acceleration) to fill (the others stay NaN)."""
    rot = np.asarray(base_R_imu, dtype=np.float64)
    z, r = np.full(N, np.nan), np.zeros((N, N))
    world_R_base = None
    if orientation_rpy is not None and all(math.isfinite(v) for v in orientation_rpy):
        world_R_base = matrix_from_rpy(*orientation_rpy) @ rot.T
        if parts[0]:
            z[3:6] = rpy_from_matrix(world_R_base)
            r[3:6, 3:6] = rot @ np.asarray(orientation_cov, dtype=np.float64).reshape(3, 3) @ rot.T
    if parts[1]:
        z[9:12] = rot @ np.asarray(angular_velocity, dtype=np.float64)
        r[9:12, 9:12] = rot @ np.asarray(angular_velocity_cov, dtype=np.float64).reshape(3, 3) @ rot.T
    if parts[2]:
        a = rot @ np.asarray(linear_acceleration, dtype=np.float64)
        if remove_gravity:
            up = np.array([0.0, 0.0, gravity])
            a = a - (world_R_base.T @ up if world_R_base is not None else up)
        z[12:15] = a
        r[12:15, 12:15] = rot @ np.asarray(linear_acceleration_cov, dtype=np.float64).reshape(3, 3) @ rot.T
    return z, r


class PoseInput:
    """An input's pose handling: ``relative`` (poses relative to the first one) and ``differential``
    (consecutive poses differenced into a body-frame twist, fused as velocities)."""

    def __init__(self, *, differential: bool = False, relative: bool = False) -> None:
        self.differential, self.relative = differential, relative
        self._first: np.ndarray | None = None
        self._prev: tuple[np.ndarray, np.ndarray, float] | None = None

    def convert(
        self, pose6: Sequence[float], cov6: np.ndarray, t: float, mask: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
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
