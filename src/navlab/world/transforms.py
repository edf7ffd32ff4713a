"""Rigid transforms for poses in SDF/URDF form: (x, y, z, roll, pitch, yaw), fixed-axis RPY in radians."""

from __future__ import annotations

import math

import numpy as np

from navlab.description.model import Origin

Pose6 = tuple[float, float, float, float, float, float]


def rpy_to_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """3x3 rotation R = Rz(yaw) Ry(pitch) Rx(roll) (URDF/SDF convention)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def matrix_to_rpy(r: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`rpy_to_matrix` (pitch in [-pi/2, pi/2])."""
    pitch = math.asin(max(-1.0, min(1.0, -float(r[2, 0]))))
    if abs(math.cos(pitch)) > 1e-9:
        roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
        yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    else:  # gimbal lock: put everything in yaw
        roll = 0.0
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
    return roll, pitch, yaw


def to_matrix(pose: Pose6 | Origin) -> np.ndarray:
    """4x4 homogeneous matrix of a pose (``parent_T_child``)."""
    if isinstance(pose, Origin):
        pose = (*pose.xyz, *pose.rpy)
    m = np.eye(4)
    m[:3, :3] = rpy_to_matrix(pose[3], pose[4], pose[5])
    m[:3, 3] = pose[:3]
    return m


def to_pose(m: np.ndarray) -> Pose6:
    """Pose6 of a 4x4 homogeneous matrix."""
    r, p, y = matrix_to_rpy(m[:3, :3])
    return (float(m[0, 3]), float(m[1, 3]), float(m[2, 3]), r, p, y)


def to_origin(m: np.ndarray) -> Origin:
    """Origin of a 4x4 homogeneous matrix."""
    p = to_pose(m)
    return Origin(xyz=(p[0], p[1], p[2]), rpy=(p[3], p[4], p[5]))


def compose(a: Pose6 | Origin, b: Pose6 | Origin) -> Pose6:
    """``a`` then ``b``: the pose of frame c in frame a's parent, given a = parent_T_b and b = b_T_c."""
    return to_pose(to_matrix(a) @ to_matrix(b))
