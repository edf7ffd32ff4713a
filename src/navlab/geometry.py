"""SE(2) and SE(3) poses and transforms, with ONE quaternion convention: ROS's (x, y, z, w).

Names say the frames, in the manner of pytransform3d: ``map_T_odom`` maps points from the odom
frame into the map frame; ``compose(map_T_odom, odom_T_base)`` is ``map_T_base``.

- Planar poses are ``(x, y, yaw)`` (m, m, rad; arrays or tuples). ``compose2``, ``inverse2``,
  ``between2`` (``a^-1 ∘ b``), ``transform_points2`` / ``inverse_transform_points2`` for (N, 2) points.
- Spatial transforms are 7-tuples ``(x, y, z, qx, qy, qz, qw)`` (``Tf``): ``compose3``, ``inverse3``,
  ``interpolate3`` (lerp + slerp), and matrices / roll-pitch-yaw helpers for URDF/SDF poses.
- MuJoCo stores quaternions as (w, x, y, z); convert only at that boundary with ``wxyz_from_xyzw``
  and ``xyzw_from_wxyz``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

Quat = tuple[float, float, float, float]  # (x, y, z, w)
Tf = tuple[float, float, float, float, float, float, float]  # (x, y, z, qx, qy, qz, qw)
Pose2 = tuple[float, float, float]  # (x, y, yaw)
Pose6 = tuple[float, float, float, float, float, float]  # (x, y, z, roll, pitch, yaw)
# A vector argument: a tuple/list of floats or a 1-D numpy array (an ndarray is not a typing ``Sequence``).
Vec = Sequence[float] | np.ndarray
IDENTITY_TF: Tf = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)

# --- angles -----------------------------------------------------------------------------------


_NUMBER = (float, int)  # what wrap_angle wraps as a number (a tuple: cheaper to test than float | int)


def wrap_angle(a: Any) -> Any:
    """Wrap angles (rad) to [-pi, pi): a number gives a float, an array (or list) an array."""
    if isinstance(a, _NUMBER):
        return (a + math.pi) % (2.0 * math.pi) - math.pi
    return (np.asarray(a) + math.pi) % (2.0 * math.pi) - math.pi


def angle_diff(a: Any, b: Any) -> Any:
    """``a - b`` wrapped to [-pi, pi) (rad)."""
    return wrap_angle(np.subtract(a, b))


# --- quaternions (x, y, z, w) -------------------------------------------------------------------


def quat_from_yaw(yaw: float) -> Quat:
    """Quaternion (x, y, z, w) of a rotation of ``yaw`` rad about z."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def yaw_from_quat(q: Vec) -> float:
    """Yaw (rad, about z) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = float(q[0]), float(q[1]), float(q[2]), float(q[3])
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> Quat:
    """Quaternion (x, y, z, w) of fixed-axis roll-pitch-yaw (URDF/SDF: R = Rz(yaw) Ry(pitch) Rx(roll))."""
    cr, sr = math.cos(roll / 2.0), math.sin(roll / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def rpy_from_quat(q: Vec) -> tuple[float, float, float]:
    """Fixed-axis (roll, pitch, yaw) of a unit quaternion (x, y, z, w); pitch in [-pi/2, pi/2]."""
    return rpy_from_matrix(matrix_from_quat(q))


def qmul(a: Vec, b: Vec) -> Quat:
    """Hamilton product ``a ⊗ b`` of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def qrotate(q: Vec, v: Vec) -> tuple[float, float, float]:
    """Vector ``v`` (3) rotated by unit quaternion ``q`` (x, y, z, w)."""
    qx, qy, qz, qw = q
    vx, vy, vz = v
    # t = 2 q_vec × v ; v' = v + w t + q_vec × t
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + (qy * tz - qz * ty),
        vy + qw * ty + (qz * tx - qx * tz),
        vz + qw * tz + (qx * ty - qy * tx),
    )


def matrix_from_quat(q: Vec) -> np.ndarray:
    """3×3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def wxyz_from_xyzw(q: Vec) -> np.ndarray:
    """MuJoCo's (w, x, y, z) order from ROS's (x, y, z, w): use only at the MuJoCo boundary."""
    return np.array([q[3], q[0], q[1], q[2]], dtype=np.float64)


def xyzw_from_wxyz(q: Vec) -> Quat:
    """ROS's (x, y, z, w) order from MuJoCo's (w, x, y, z)."""
    return (float(q[1]), float(q[2]), float(q[3]), float(q[0]))


# --- rotation matrices and URDF/SDF poses ------------------------------------------------------


def matrix_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """3×3 rotation R = Rz(yaw) Ry(pitch) Rx(roll) (URDF/SDF convention)."""
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def rpy_from_matrix(r: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`matrix_from_rpy` (pitch in [-pi/2, pi/2]; gimbal lock puts it all in yaw)."""
    pitch = math.asin(max(-1.0, min(1.0, -float(r[2, 0]))))
    if abs(math.cos(pitch)) > 1e-9:
        roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
        yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    else:
        roll = 0.0
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
    return roll, pitch, yaw


def matrix_from_pose6(pose: Vec) -> np.ndarray:
    """4×4 homogeneous ``parent_T_child`` of (x, y, z, roll, pitch, yaw)."""
    m = np.eye(4)
    m[:3, :3] = matrix_from_rpy(pose[3], pose[4], pose[5])
    m[:3, 3] = pose[:3]
    return m


def pose6_from_matrix(m: np.ndarray) -> Pose6:
    """(x, y, z, roll, pitch, yaw) of a 4×4 homogeneous matrix."""
    r, p, y = rpy_from_matrix(m[:3, :3])
    return (float(m[0, 3]), float(m[1, 3]), float(m[2, 3]), r, p, y)


def compose6(a: Vec, b: Vec) -> Pose6:
    """``a ∘ b`` for (x, y, z, roll, pitch, yaw) poses: ``parent_T_c`` from ``parent_T_b`` and ``b_T_c``."""
    return pose6_from_matrix(matrix_from_pose6(a) @ matrix_from_pose6(b))


# --- SE(3) transforms as (x, y, z, qx, qy, qz, qw) ---------------------------------------------


def tf_from_xyz_quat(xyz: Vec, q: Vec) -> Tf:
    """A ``Tf`` from a translation and a quaternion (x, y, z, w)."""
    return (float(xyz[0]), float(xyz[1]), float(xyz[2]), float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def tf_from_pose2(x: float, y: float, yaw: float, z: float = 0.0) -> Tf:
    """A ``Tf`` of a planar pose (plus height ``z``)."""
    return (float(x), float(y), float(z), *quat_from_yaw(yaw))


def pose2_from_tf(tf: Vec) -> Pose2:
    """(x, y, yaw) of a ``Tf``."""
    return float(tf[0]), float(tf[1]), yaw_from_quat(tf[3:7])


def compose3(a: Tf, b: Tf) -> Tf:
    """``a ∘ b``: with ``a = A_T_B`` and ``b = B_T_C`` the result is ``A_T_C``."""
    qx, qy, qz, qw = a[3], a[4], a[5], a[6]
    vx, vy, vz, bx, by, bz, bw = b[0], b[1], b[2], b[3], b[4], b[5], b[6]
    # qrotate(a's rotation, b's translation) and qmul(a's rotation, b's), written out (tf lookups run this often)
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        a[0] + (vx + qw * tx + (qy * tz - qz * ty)),
        a[1] + (vy + qw * ty + (qz * tx - qx * tz)),
        a[2] + (vz + qw * tz + (qx * ty - qy * tx)),
        qw * bx + qx * bw + qy * bz - qz * by,
        qw * by - qx * bz + qy * bw + qz * bx,
        qw * bz + qx * by - qy * bx + qz * bw,
        qw * bw - qx * bx - qy * by - qz * bz,
    )


def inverse3(a: Tf) -> Tf:
    """``B_T_A`` from ``A_T_B``."""
    qi = (-a[3], -a[4], -a[5], a[6])
    t = qrotate(qi, (-a[0], -a[1], -a[2]))
    return (*t, *qi)


def interpolate3(a: Tf, b: Tf, s: float) -> Tf:
    """Linear interpolation of translation and slerp of rotation, ``s`` in [0, 1]."""
    ax, ay, az, aw = a[3], a[4], a[5], a[6]
    bx, by, bz, bw = b[3], b[4], b[5], b[6]
    dot = 0.0 + ax * bx + ay * by + az * bz + aw * bw  # summed left to right from 0.0, as sum() does
    if dot < 0.0:
        bx, by, bz, bw, dot = -bx, -by, -bz, -bw, -dot
    if dot > 0.9995:
        qx, qy, qz, qw = ax + s * (bx - ax), ay + s * (by - ay), az + s * (bz - az), aw + s * (bw - aw)
    else:
        th = math.acos(min(1.0, dot))
        sa, sb = math.sin((1 - s) * th) / math.sin(th), math.sin(s * th) / math.sin(th)
        qx, qy, qz, qw = sa * ax + sb * bx, sa * ay + sb * by, sa * az + sb * bz, sa * aw + sb * bw
    n = math.sqrt(0.0 + qx * qx + qy * qy + qz * qz + qw * qw)
    return (
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
        qx / n,
        qy / n,
        qz / n,
        qw / n,
    )


# --- SE(2) poses (x, y, yaw) --------------------------------------------------------------------


def compose2(a: Vec, b: Vec) -> np.ndarray:
    """``a ∘ b`` for planar poses (yaw wrapped to [-pi, pi)): ``map_T_base = compose2(map_T_odom, odom_T_base)``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(float(a[2] + b[2]))])


def inverse2(a: Vec) -> np.ndarray:
    """``a^-1`` for a planar pose: ``odom_T_map`` from ``map_T_odom``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2]])


def between2(a: Vec, b: Vec) -> np.ndarray:
    """``a^-1 ∘ b``: the pose ``b`` seen from the frame of ``a`` (both in one parent frame)."""
    return compose2(inverse2(a), b)


def compose2_many(a: Vec, b: np.ndarray) -> np.ndarray:
    """``a ∘ b[k]`` for every pose of ``b`` (N, 3) (yaw not wrapped)."""
    bb = np.asarray(b, dtype=np.float64).reshape(-1, 3)
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.column_stack([a[0] + c * bb[:, 0] - s * bb[:, 1], a[1] + s * bb[:, 0] + c * bb[:, 1], a[2] + bb[:, 2]])


def transform_points2(pose: Vec, pts: np.ndarray) -> np.ndarray:
    """Points (N, 2) given in the frame at ``pose`` -> the same points in the parent frame."""
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    out = np.empty_like(p)
    out[:, 0] = pose[0] + c * p[:, 0] - s * p[:, 1]
    out[:, 1] = pose[1] + s * p[:, 0] + c * p[:, 1]
    return out


def inverse_transform_points2(pose: Vec, pts: np.ndarray) -> np.ndarray:
    """Points (N, 2) in the parent frame -> the same points in the frame at ``pose``."""
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = p[:, 0] - pose[0], p[:, 1] - pose[1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=1)


def rotate_vectors2(theta: float, v: np.ndarray) -> np.ndarray:
    """Vectors (N, 2) rotated by ``theta`` rad."""
    c, s = math.cos(theta), math.sin(theta)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=1)
