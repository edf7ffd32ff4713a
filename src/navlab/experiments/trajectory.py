"""Absolute trajectory error (ATE): a global-consistency measure beside the (local) relations metric.

``ate(est, truth)`` aligns the estimated positions to the true ones by the rigid SE(2) transform that
minimises the squared position error (Umeyama 1991 / Horn 1987, without scale), then reports RMSE,
mean, median and max of the position error (m), the share of poses off by more than ``far`` m, and
the mean yaw error (deg). ``read_trajectory`` reads the trajectory files navlab writes (``t x y theta``;
``navlab map``'s ``t x y theta true_x true_y true_theta``), TUM files (``t x y yaw`` or
``t x y z qx qy qz qw``) and CARMEN logs (``FLASER`` robot poses or ``ODOM`` poses);
``associate`` pairs two trajectories by nearest timestamp. Pure numpy; poses (x m, y m, yaw rad).
Bad arrays raise ``MappingError``, bad files ``IoError``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from navlab.geometry import wrap_angle
from navlab.io import IoError, check_regular_file, read_table
from navlab.mapping import MappingError

CARMEN_SOURCES = ("flaser", "odom", "laser")


def align_se2(est_xy: np.ndarray, truth_xy: np.ndarray) -> tuple[float, float, float]:
    """The rigid transform (x, y, yaw) ``truth_T_est`` minimising sum |truth - T(est)|^2 (no scale)."""
    a = np.asarray(est_xy, dtype=np.float64)
    b = np.asarray(truth_xy, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 2 or a.shape[1] != 2 or len(a) == 0:
        raise MappingError(f"align_se2: expected two (N, 2) arrays of equal shape, got {a.shape} and {b.shape}")
    ma, mb = a.mean(axis=0), b.mean(axis=0)
    da, db = a - ma, b - mb
    # 2-D Umeyama/Horn: the optimal angle comes in closed form from the cross-covariance
    sxx = float(np.sum(da[:, 0] * db[:, 0] + da[:, 1] * db[:, 1]))
    sxy = float(np.sum(da[:, 0] * db[:, 1] - da[:, 1] * db[:, 0]))
    th = math.atan2(sxy, sxx) if len(a) > 1 else 0.0
    c, s = math.cos(th), math.sin(th)
    tx = mb[0] - (c * ma[0] - s * ma[1])
    ty = mb[1] - (s * ma[0] + c * ma[1])
    return float(tx), float(ty), th


def apply_se2(t: tuple[float, float, float], poses: np.ndarray) -> np.ndarray:
    """Poses (N, 3) moved by the rigid transform ``t`` (x, y, yaw)."""
    p = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    c, s = math.cos(t[2]), math.sin(t[2])
    out = np.empty_like(p)
    out[:, 0] = t[0] + c * p[:, 0] - s * p[:, 1]
    out[:, 1] = t[1] + s * p[:, 0] + c * p[:, 1]
    out[:, 2] = wrap_angle(p[:, 2] + t[2])
    return out


def ate(est: np.ndarray, truth: np.ndarray, *, align: bool = True, far: float = 0.5) -> dict[str, float | int]:
    """ATE of matched poses ``est`` and ``truth`` (N, 3) after rigid alignment (``align=False``: as given).

    Returns ``poses``, ``rmse_m``, ``mean_m``, ``median_m``, ``max_m``, ``share_over_far`` (fraction of
    poses whose position error exceeds ``far`` m), ``far_m``, ``yaw_mean_deg`` and the alignment
    (``align_x``, ``align_y``, ``align_yaw``: the truth frame's pose of the estimate's frame)."""
    e = np.asarray(est, dtype=np.float64).reshape(-1, 3)
    g = np.asarray(truth, dtype=np.float64).reshape(-1, 3)
    if len(e) != len(g):
        raise MappingError(f"ate: {len(e)} estimated poses but {len(g)} true poses")
    ok = np.isfinite(e).all(axis=1) & np.isfinite(g).all(axis=1)
    e, g = e[ok], g[ok]
    if len(e) == 0:
        raise MappingError("ate: no pair of finite poses to compare")
    t = align_se2(e[:, :2], g[:, :2]) if align else (0.0, 0.0, 0.0)
    a = apply_se2(t, e)
    d = np.hypot(a[:, 0] - g[:, 0], a[:, 1] - g[:, 1])
    yaw = np.degrees(np.abs(wrap_angle(a[:, 2] - g[:, 2])))
    return {
        "poses": len(d),
        "rmse_m": float(np.sqrt(np.mean(d**2))),
        "mean_m": float(d.mean()),
        "median_m": float(np.median(d)),
        "max_m": float(d.max()),
        "share_over_far": float(np.mean(d > far)),
        "far_m": far,
        "yaw_mean_deg": float(yaw.mean()),
        "align_x": t[0],
        "align_y": t[1],
        "align_yaw": t[2],
    }


def associate(t_est: np.ndarray, t_truth: np.ndarray, *, tolerance: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i into ``t_est``, j into ``t_truth``) of the nearest true timestamp to each estimated
    one within ``tolerance`` s, each true pose used at most once (the closest claim wins)."""
    te = np.asarray(t_est, dtype=np.float64)
    tt = np.asarray(t_truth, dtype=np.float64)
    if len(te) == 0 or len(tt) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    order = np.argsort(tt, kind="stable")
    st = tt[order]
    k = np.clip(np.searchsorted(st, te), 1, max(len(st) - 1, 1)) if len(st) > 1 else np.zeros(len(te), int)
    if len(st) > 1:
        left, right = st[k - 1], st[k]
        k = np.where(np.abs(te - left) <= np.abs(te - right), k - 1, k)
    gap = np.abs(st[k] - te)
    cand = np.flatnonzero(gap <= tolerance)
    # one estimate per true pose: keep the closest
    cand = cand[np.argsort(gap[cand], kind="stable")]
    _, first = np.unique(k[cand], return_index=True)
    keep = np.sort(cand[first])
    return keep, order[k[keep]]


def _is_carmen(path: Path) -> bool:
    try:
        check_regular_file(path, what="trajectory")
        with path.open("r", errors="replace") as fh:
            for line in fh:
                tok = line.split()
                if tok and not tok[0].startswith("#"):
                    return tok[0][0].isalpha()
    except OSError as exc:
        raise IoError(f"cannot read trajectory file {path}: {exc.strerror or exc}") from None
    return False


def read_trajectory(
    path: str | os.PathLike[str], *, carmen: str = "flaser", columns: str = "estimate"
) -> tuple[np.ndarray, np.ndarray]:
    """(timestamps (N,) s, poses (N, 3)) from a trajectory file; the format is recognised by its content.

    - CARMEN log: ``carmen="flaser"`` the robot's odometry pose of each scan (the poses relations refer
      to), ``"laser"`` the laser's, ``"odom"`` the ``ODOM`` lines.
    - ``t x y theta`` (navlab poses, TUM 2-D), ``t x y z qx qy qz qw`` (TUM; yaw from the quaternion,
      ROS order x, y, z, w), and ``navlab map``'s ``t x y theta true_x true_y true_theta``
      (``columns="truth"`` picks the true pose columns).
    Raises ``IoError`` naming the file for unreadable or malformed input.
    """
    p = Path(path)
    if _is_carmen(p):
        from navlab.io import read_carmen

        if carmen not in CARMEN_SOURCES:
            raise IoError(f"CARMEN pose source must be one of {', '.join(CARMEN_SOURCES)}, got {carmen!r}")
        log = read_carmen(p)
        if carmen == "odom":
            if not log.odometry:
                raise IoError(f"{p}: no ODOM lines (use the scans' poses: --carmen flaser)")
            return np.array([o.timestamp for o in log.odometry]), np.array([o.pose for o in log.odometry])
        attr = "odom_pose" if carmen == "flaser" else "laser_pose"
        return np.array([s.timestamp for s in log.scans]), np.array([getattr(s, attr) for s in log.scans])
    table = read_table(p, 4, "trajectory")
    width = _columns(p)
    if width >= 8:
        full = read_table(p, 8, "TUM trajectory")
        qx, qy, qz, qw = full[:, 4], full[:, 5], full[:, 6], full[:, 7]
        yaw = np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy**2 + qz**2))
        return full[:, 0], np.stack([full[:, 1], full[:, 2], yaw], axis=1)
    if width == 7 and columns == "truth":
        full = read_table(p, 7, "trajectory")
        return full[:, 0], full[:, 4:7]
    if columns == "truth":
        raise IoError(f"{p}: {width} columns; true poses need 't x y theta true_x true_y true_theta' lines")
    return table[:, 0], table[:, 1:4]


def _columns(path: Path) -> int:
    """Columns of the first data line (after ``read_table`` has validated the file)."""
    for line in path.read_text().splitlines():
        s = line.split("#", 1)[0].split()
        if s:
            return len(s)
    return 0


def trajectory_ate(
    est: tuple[np.ndarray, np.ndarray],
    truth: tuple[np.ndarray, np.ndarray],
    *,
    tolerance: float = 0.02,
    align: bool = True,
    far: float = 0.5,
) -> dict[str, float | int]:
    """``ate`` of two timestamped trajectories ((t, poses) each) associated by timestamp; adds
    ``n_estimated``/``n_truth``. Raises ``MappingError`` when no timestamps pair up."""
    i, j = associate(est[0], truth[0], tolerance=tolerance)
    if len(i) == 0:
        te, tt = np.asarray(est[0]), np.asarray(truth[0])
        raise MappingError(
            f"no estimated pose's timestamp is within {tolerance} s of a true one (estimate spans "
            f"{te.min():.3f}..{te.max():.3f} s, truth {tt.min():.3f}..{tt.max():.3f} s)"
        )
    out = ate(np.asarray(est[1])[i], np.asarray(truth[1])[j], align=align, far=far)
    return {"n_estimated": len(est[0]), "n_truth": len(truth[0]), **out}
