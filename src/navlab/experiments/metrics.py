"""Accuracy metrics, in one place: SLAM relations, maps and trajectories against the truth, settling times.

The relations metric is that of Kümmerle et al. 2009 ("On measuring the accuracy of SLAM").

For each ground-truth relation (t1, t2, relative pose of the scan at t2 in the frame of the scan at
t1), the error is ``relation ⊖ (pose(t1)^-1 ∘ pose(t2))``; the report gives mean ± sample standard
deviation of the absolute translational error (m) and rotational error (deg), and the means of
their squares. Pose files (``timestamp x y theta`` per line) are read and written by
``navlab.io.poses``; ``read_poses``/``write_poses`` are re-exported here.
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np
from scipy import ndimage

from navlab.experiments.trajectory import ate
from navlab.geometry import inverse_transform_points2, transform_points2, wrap_angle
from navlab.grid import Grid, GridMap
from navlab.io import read_poses, read_table, write_poses
from navlab.mapping import MappingError
from navlab.world import visible_surface

__all__ = [
    "ate",
    "distance_to_path",
    "free_coverage",
    "read_poses",
    "read_relations",
    "relations_error",
    "score_map",
    "settled_after",
    "trajectory_error",
    "write_poses",
]  # pose files live in navlab.io.poses


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
        rot_max_deg=float(rot.max()),
        rot_over_5deg=int(np.count_nonzero(rot > 5.0)),
    )
    return out


def relations_closure(relations: np.ndarray, *, time_tolerance: float = 1e-3) -> dict[str, float | int]:
    """How well a relations file agrees with itself: every triangle of relations (a→b, b→c, a→c) should close,
    a→b ∘ b→c = a→c. Returns ``n_triangles``, the translational closure's median and mean (m) and
    ``noise_floor_m``: if the relations' errors were independent, isotropic and Gaussian, the mean translational
    error of one relation against the truth (mean closure / √3): the score an estimator without error would get.
    ``noise_floor_m`` is NaN without triangles."""
    rel = np.asarray(relations, dtype=np.float64)
    key = np.round(np.concatenate([rel[:, 0], rel[:, 1]]) / time_tolerance).astype(np.int64)
    a, b = key[: len(rel)], key[len(rel) :]
    index = {(int(i), int(j)): k for k, (i, j) in enumerate(zip(a, b, strict=True))}
    after: dict[int, list[int]] = {}
    for k, i in enumerate(a):
        after.setdefault(int(i), []).append(k)
    closure = []
    for ab, (i, j) in enumerate(zip(a, b, strict=True)):
        for bc in after.get(int(j), []):
            ac = index.get((int(i), int(b[bc])))
            if ac is None:
                continue
            x, y, yaw = rel[ab, 2:5]
            c, s = np.cos(yaw), np.sin(yaw)
            end = (x + c * rel[bc, 2] - s * rel[bc, 3], y + s * rel[bc, 2] + c * rel[bc, 3])
            closure.append(np.hypot(end[0] - rel[ac, 2], end[1] - rel[ac, 3]))
    err = np.asarray(closure)
    if not len(err):
        return {
            "n_triangles": 0,
            "closure_median_m": float("nan"),
            "closure_mean_m": float("nan"),
            "noise_floor_m": float("nan"),
        }
    # the closure is the sum of three relations' errors: per axis sigma * sqrt(3), so its mean 2D norm is
    # sqrt(3) times one relation's
    return {
        "n_triangles": len(err),
        "closure_median_m": float(np.median(err)),
        "closure_mean_m": float(err.mean()),
        "noise_floor_m": float(err.mean() / np.sqrt(3.0)),
    }


# --- maps and trajectories against a simulated world's truth ------------------------------------


def score_map(
    grid: GridMap,
    truth: Grid,
    *,
    world_T_map: tuple[float, float, float] = (0.0, 0.0, 0.0),
    tolerance_cells: int = 1,
    occupied_threshold: int = 65,
    start_xy: tuple[float, float] | None = None,
) -> dict[str, float | int]:
    """Occupied-cell precision and recall of ``grid`` against ``truth`` (a boolean ``Grid``, world frame).

    Precision: map-occupied cells with a true occupied cell within the tolerance. Recall: true visible
    wall cells (see ``truth.visible_surface``, seen from ``start_xy``: the robot's start in the world,
    default ``world_T_map``'s position) with a map-occupied cell within the tolerance. Also the
    mean distance (m) from each map-occupied cell to the nearest true occupied cell.
    """
    jj, ii = np.nonzero(grid.data >= occupied_threshold)
    if len(ii) == 0:
        return {"occupied_cells": 0, "precision": 0.0, "recall": 0.0, "mean_wall_error_m": math.inf}
    pts = transform_points2(world_T_map, grid.cell_to_world(np.stack([ii, jj], axis=1)))
    tol_m = tolerance_cells * max(grid.resolution, truth.resolution)
    dist_to_truth = ndimage.distance_transform_edt(~truth.data) * truth.resolution
    cells = truth.world_to_cell(pts)
    inside = truth.in_bounds(cells)
    d = np.full(len(pts), np.inf)
    d[inside] = dist_to_truth[cells[inside, 1], cells[inside, 0]]
    # distance from a map cell centre to the nearest true cell *edge* is at most half a truth cell less.
    precision = float(np.mean(d <= tol_m + 0.5 * truth.resolution))

    seen_from = (world_T_map[0], world_T_map[1]) if start_xy is None else start_xy
    spts = truth.centers(visible_surface(truth, seen_from))
    in_map = grid.world_to_cell(inverse_transform_points2(world_T_map, spts))
    map_occ = grid.data >= occupied_threshold
    dist_to_map = ndimage.distance_transform_edt(~map_occ) * grid.resolution
    ok = grid.in_bounds(in_map)
    ds = np.full(len(spts), np.inf)
    ds[ok] = dist_to_map[in_map[ok, 1], in_map[ok, 0]]
    recall = float(np.mean(ds <= tol_m + 0.5 * grid.resolution)) if len(ds) else 0.0
    finite = d[np.isfinite(d)]
    return {
        "occupied_cells": len(pts),
        "precision": round(precision, 4),
        "recall": round(recall, 4),
        "mean_wall_error_m": round(float(finite.mean()), 4) if len(finite) else math.inf,
    }


def free_coverage(
    grid: GridMap,
    truth: Grid,
    *,
    world_T_map: tuple[float, float, float] = (0.0, 0.0, 0.0),
    robot_radius: float = 0.2,
    start_xy: tuple[float, float] | None = None,
) -> float:
    """Fraction of the true free space reachable by a robot of ``robot_radius`` from the start
    (``start_xy`` in the world, default ``world_T_map``'s position) that the map marks known."""
    start_xy = (world_T_map[0], world_T_map[1]) if start_xy is None else start_xy
    free = ~truth.data
    clearance = ndimage.distance_transform_edt(free) * truth.resolution
    labels, _ = ndimage.label(clearance > robot_radius)
    i, j = truth.world_to_cell(np.array([start_xy]))[0]
    reach = labels == labels[j, i]
    # The reachable region grown by the robot radius is the space the robot's sensor footprint can reach.
    reach = reach | (ndimage.binary_dilation(reach, iterations=max(1, round(robot_radius / truth.resolution))) & free)
    pts = truth.centers(reach)
    cells = grid.world_to_cell(inverse_transform_points2(world_T_map, pts))
    ok = grid.in_bounds(cells)
    known = np.zeros(len(pts), bool)
    known[ok] = grid.data[cells[ok, 1], cells[ok, 0]] >= 0
    return float(known.mean()) if len(known) else 0.0


def trajectory_error(est: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """Absolute errors between matched poses (N, 3) (x, y, yaw), rows with a NaN skipped: mean/max position
    (m) and mean yaw (deg)."""
    ok = np.isfinite(est).all(axis=1) & np.isfinite(truth).all(axis=1)
    est, truth = est[ok], truth[ok]
    if len(est) == 0:
        return {
            "poses": 0,
            "position_error_mean_m": math.nan,
            "position_error_max_m": math.nan,
            "yaw_error_mean_deg": math.nan,
        }
    dpos = np.hypot(est[:, 0] - truth[:, 0], est[:, 1] - truth[:, 1])
    dyaw = np.abs(wrap_angle(est[:, 2] - truth[:, 2]))
    return {
        "poses": len(est),
        "position_error_mean_m": round(float(dpos.mean()), 4),
        "position_error_max_m": round(float(dpos.max()), 4),
        "yaw_error_mean_deg": round(float(np.degrees(dyaw).mean()), 3),
    }


def settled_after(t: np.ndarray, err: np.ndarray, t0: float, threshold: float) -> float | None:
    """First time >= ``t0`` from which ``err`` stays <= ``threshold`` to the end (None if never)."""
    sel = t >= t0
    tt, ee = t[sel], err[sel]
    bad = np.flatnonzero(~(ee <= threshold))
    if bad.size == 0:
        return float(tt[0]) if tt.size else None
    k = bad[-1] + 1
    return float(tt[k]) if k < tt.size else None


def distance_to_path(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Distance (m) from each point (N, 2) to the polyline ``path`` (M, >=2; x y in the same frame): the
    path tracking error of a driven path against the global plan."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    poly = np.asarray(path, dtype=np.float64)[:, :2]
    if len(poly) == 0:
        return np.full(len(pts), np.nan)
    if len(poly) == 1:
        return np.hypot(pts[:, 0] - poly[0, 0], pts[:, 1] - poly[0, 1])
    return _distance_to_polyline(np.ascontiguousarray(pts), np.ascontiguousarray(poly))


@numba.njit(cache=True)
def _distance_to_polyline(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """Each point's distance (m) to the nearest of the segments ``poly[k]``-``poly[k + 1]`` (M >= 2)."""
    out = np.empty(pts.shape[0])
    for n in range(pts.shape[0]):
        px, py = pts[n, 0], pts[n, 1]
        best = math.inf
        for k in range(poly.shape[0] - 1):
            ax, ay = poly[k, 0], poly[k, 1]
            abx, aby = poly[k + 1, 0] - ax, poly[k + 1, 1] - ay
            length2 = max(abx * abx + aby * aby, 1e-18)
            t = min(max(((px - ax) * abx + (py - ay) * aby) / length2, 0.0), 1.0)
            dx, dy = px - (ax + t * abx), py - (ay + t * aby)
            best = min(best, math.sqrt(dx * dx + dy * dy))
        out[n] = best
    return out
