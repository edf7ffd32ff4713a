"""Accuracy metrics: the relations metric of Kümmerle et al. 2009 ("On measuring the accuracy of SLAM").

For each ground-truth relation (t1, t2, relative pose of the scan at t2 in the frame of the scan at
t1), the error is ``relation ⊖ (pose(t1)^-1 ∘ pose(t2))``; the report gives mean ± sample standard
deviation of the absolute translational error (m) and rotational error (deg), and the means of
their squares. Pose files (``timestamp x y theta`` per line) are read and written by
``navlab.io.poses``; ``read_poses``/``write_poses`` are re-exported here.
"""

from __future__ import annotations

import os

import numpy as np

from navlab.geometry import wrap_angle
from navlab.io.poses import read_poses, read_table, write_poses
from navlab.mapping.errors import MappingError

__all__ = ["read_poses", "read_relations", "relations_error", "write_poses"]  # pose files live in navlab.io.poses


def read_relations(path: str | os.PathLike[str]) -> np.ndarray:
    """Relations (M, 5): t1, t2, x, y, yaw from ``t1 t2 x y z roll pitch yaw`` lines (s, m, rad).

    A malformed file raises ``navlab.io.IoError`` naming the file and line.
    """
    t = read_table(path, 8, "relation")
    return t[:, [0, 1, 2, 3, 7]]


def _match(times: np.ndarray, query: np.ndarray, tol: float) -> np.ndarray:
    """Index into ``times`` of the nearest timestamp to each query, or -1 when none is within ``tol`` s."""
    order = np.argsort(times)
    st = times[order]
    k = np.clip(np.searchsorted(st, query), 1, len(st) - 1) if len(st) > 1 else np.zeros(len(query), int)
    left, right = st[k - 1], st[k]
    pick = np.where(np.abs(query - left) <= np.abs(query - right), k - 1, k) if len(st) > 1 else k
    ok = np.abs(st[pick] - query) <= tol
    return np.where(ok, order[pick], -1)


def relations_error(
    timestamps: np.ndarray, poses: np.ndarray, relations: np.ndarray, *, time_tolerance: float = 1e-3
) -> dict[str, float | int]:
    """The Kümmerle et al. relations metric for estimated ``poses`` (N, 3) at ``timestamps`` (N,) s.

    ``relations`` (M, 5): t1, t2, x, y, yaw. Relations whose timestamps match no pose within
    ``time_tolerance`` s are not scored (``n_scored`` < ``n_relations``).
    """
    times = np.asarray(timestamps, dtype=np.float64)
    est = np.asarray(poses, dtype=np.float64)
    rel = np.asarray(relations, dtype=np.float64)
    i1 = _match(times, rel[:, 0], time_tolerance)
    i2 = _match(times, rel[:, 1], time_tolerance)
    ok = (i1 >= 0) & (i2 >= 0)
    out: dict[str, float | int] = {"n_relations": len(rel), "n_scored": int(ok.sum())}
    if not ok.any():
        raise MappingError(
            f"none of the {len(rel)} relations matches the poses' timestamps within {time_tolerance} s "
            f"(poses span {times.min():.3f}..{times.max():.3f}, relations {rel[:, 0].min():.3f}.."
            f"{rel[:, 1].max():.3f})"
        )
    a, b, r = est[i1[ok]], est[i2[ok]], rel[ok]
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    dx, dy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    ex, ey = c * dx + s * dy, -s * dx + c * dy  # estimated relative translation, in the frame at t1
    et = b[:, 2] - a[:, 2]
    # error = relation ⊖ estimate = estimate^-1 ∘ relation; its translation norm is |t_rel - t_est|
    trans = np.hypot(r[:, 2] - ex, r[:, 3] - ey)
    rot = np.degrees(np.abs(wrap_angle(r[:, 4] - et)))
    ddof = 1 if len(trans) > 1 else 0
    out.update(
        trans_abs_mean=float(trans.mean()),
        trans_abs_std=float(trans.std(ddof=ddof)),
        trans_sq_mean=float((trans**2).mean()),
        rot_abs_mean_deg=float(rot.mean()),
        rot_abs_std_deg=float(rot.std(ddof=ddof)),
        rot_sq_mean_deg2=float((rot**2).mean()),
    )
    return out
