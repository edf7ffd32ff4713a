"""A final, globally consistent refinement of SLAM poses: dense verified scan-to-scan constraints, optimised.

Given laser poses that are already globally consistent to a few decimetres (what a SLAM mode's loop
closures give), every scan is matched by point-to-line ICP against the scans of its nearest neighbours
in space (up to ``neighbours`` nodes within ``radius`` m, heading within ``max_heading`` rad, at least
``min_travel`` m back along the path), starting
from their current relative pose. A match enters the pose graph only if it is verified: enough of the
scan overlaps (``min_inliers``), the residual is small (``max_rms``) and the correction it implies is
small (``max_correction`` m / ``max_correction_ang`` rad: these are not loop *searches*, so a large
jump is a wrong match, never accepted). Consecutive scans are always linked (by their match, or by the
current relative pose, weakly, when it cannot be verified). All non-consecutive edges carry a Cauchy
kernel, and an edge the optimised graph still disagrees with by more than ``reject`` (Mahalanobis) is
dropped before a last optimisation (switching off inconsistent constraints).

Pure: numpy in, poses out; no topics, no clock. Poses (x, y, theta) m, rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from navlab.geometry import between2, wrap_angle
from navlab.mapping.posegraph import PoseGraph
from navlab.mapping.scanmatch import ScanPoints, icp_point_to_line


@dataclass
class RefineParams:
    """Parameters of :func:`refine_poses` (m, rad)."""

    radius: float = 4.0
    neighbours: int = 4
    min_travel: float = 1.5  # only nodes this far back along the path (nearer ones: the front end's job)
    max_heading: float = math.radians(100.0)
    min_inliers: float = 0.5
    max_rms: float = 0.03
    max_correction: float = 0.5
    max_correction_ang: float = math.radians(6.0)
    icp_max_dist: float = 0.4
    icp_min_dist: float = 0.06
    icp_iterations: int = 14
    sigma_xy: float = 0.02
    sigma_theta: float = math.radians(0.4)
    weak_sigma_xy: float = 0.2
    weak_sigma_theta: float = math.radians(3.0)
    kernel: float = 2.0
    reject: float = 5.0
    rounds: int = 3
    # a pair matched in an earlier round whose relative pose has since moved less than this (m, rad) from
    # where that match started keeps its match (on CSAIL, ICP from starts 7 mm / 0.14 deg apart lands within
    # 0.1 mm in 9 pairs of 10, the rest within ~1 cm); 0: every round matches every pair again
    rematch_xy: float = 0.0
    rematch_theta: float = 0.0
    # a verified match's information is ``sigma_xy``/``sigma_theta``'s shaped by its ICP Hessian: weaker along
    # directions the scans do not pin down (a corridor's axis), never stronger. ``shape_xy`` is the Hessian's
    # xy eigenvalue per matched point of a match that pins both directions (normals spread evenly: 1/2); 0:
    # every verified match gets the plain sigma_xy / sigma_theta
    shape_xy: float = 0.0
    # the pose graph's Gauss-Newton stops once no pose moves more than this in a step (m, rad)
    tol: float = 1e-6


def _strong(p: RefineParams) -> np.ndarray:
    """The information matrix of a verified match that pins every direction (the plain sigmas')."""
    return np.diag([p.sigma_xy**-2, p.sigma_xy**-2, p.sigma_theta**-2])


def _information(hessian: np.ndarray, theta: float, points: float, p: RefineParams) -> np.ndarray:
    """A verified match's information (in the pose graph's edge-error frame) from its ICP Hessian (over
    the pose (x, y, theta) of the scan in the other's frame, summed over ``points`` matched points): the
    Hessian per point, normalised (xy by ``shape_xy``, theta by its own diagonal), its eigenvalues capped
    at 1, scales ``_strong``. A match whose normals spread evenly keeps the plain sigmas; one along a
    corridor is weak along the corridor's axis, where the start pose, not the scans, placed it."""
    if p.shape_xy <= 0:
        return _strong(p)
    return _shaped(hessian, theta, max(points, 1.0), p.shape_xy, p.sigma_xy, p.sigma_theta)


@numba.njit(cache=True)
def _shaped(
    hessian: np.ndarray, theta: float, points: float, shape_xy: float, sigma_xy: float, sigma_theta: float
) -> np.ndarray:
    """``_information``'s arithmetic (numba: it runs for each of ~10,000 verified matches a round)."""
    c, s = math.cos(theta), math.sin(theta)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # edge error (scan j's frame) -> scan i's frame
    per_point = rot.T @ hessian @ rot / points
    ref = np.array([1.0 / math.sqrt(shape_xy), 1.0 / math.sqrt(shape_xy), math.sqrt(max(per_point[2, 2], 1e-12))])
    w, v = np.linalg.eigh(per_point / np.outer(ref, ref))
    scale = np.array([1.0 / sigma_xy, 1.0 / sigma_xy, 1.0 / sigma_theta])
    return (v * np.minimum(w, 1.0)) @ v.T * np.outer(scale, scale)


def _match(a: ScanPoints, b: ScanPoints, rel: np.ndarray, p: RefineParams) -> tuple[np.ndarray, bool, np.ndarray]:
    """Pose of scan ``b`` in scan ``a``'s frame, refined by ICP from ``rel``, whether it is verified, and its
    information (``_information``)."""
    if len(a.xy) < 20 or len(b.xy) < 20:
        return rel, False, _strong(p)
    res = icp_point_to_line(
        a.xy, a.normals, b.xy, rel, max_dist=p.icp_max_dist, min_dist=p.icp_min_dist, iterations=p.icp_iterations
    )
    corr = res.pose - rel
    ok = (
        res.inlier_fraction >= p.min_inliers
        and res.rms <= p.max_rms
        and math.hypot(corr[0], corr[1]) <= p.max_correction
        and abs(wrap_angle(corr[2])) <= p.max_correction_ang
    )
    if not ok:
        return res.pose, False, _strong(p)
    return res.pose, True, _information(res.hessian, float(res.pose[2]), res.inlier_fraction * len(b.xy), p)


class _Matches:
    """Verified matches by pair (j, k), each with the relative pose it started from (reused in later rounds
    while the pair's relative pose stays within ``rematch_xy`` / ``rematch_theta`` of that start)."""

    def __init__(self, scans: list[ScanPoints], p: RefineParams) -> None:
        self.scans, self.p = scans, p
        self.done: dict[tuple[int, int], tuple[np.ndarray, tuple[np.ndarray, bool, np.ndarray]]] = {}

    def get(self, j: int, k: int, rel: np.ndarray) -> tuple[np.ndarray, bool, np.ndarray]:
        """``_match`` of scan k against scan j from ``rel``, or the earlier one from a start as near."""
        old = self.done.get((j, k))
        if old is not None:
            d = rel - old[0]
            if math.hypot(d[0], d[1]) < self.p.rematch_xy and abs(wrap_angle(d[2])) < self.p.rematch_theta:
                return old[1]
        got = _match(self.scans[j], self.scans[k], rel, self.p)
        self.done[(j, k)] = (rel, got)
        return got


def refine_poses(
    poses: np.ndarray, scans: list[ScanPoints], params: RefineParams | None = None
) -> tuple[np.ndarray, dict[str, int]]:
    """Refined laser poses (N, 3) for ``scans`` (laser-frame points with normals) taken at ``poses``, and
    counters (``refine_edges``: verified constraints kept, ``refine_rejected``: matches that failed
    verification or were switched off by the optimiser)."""
    p = params or RefineParams()
    cur = np.array(poses, dtype=np.float64).reshape(-1, 3)
    n = len(cur)
    stats = {"refine_edges": 0, "refine_rejected": 0}
    if n < 3:
        return cur, stats
    weak = np.diag([p.weak_sigma_xy**-2, p.weak_sigma_xy**-2, p.weak_sigma_theta**-2])
    matches = _Matches(scans, p)
    for _ in range(p.rounds):
        steps = np.hypot(np.diff(cur[:, 0]), np.diff(cur[:, 1]))
        travel = np.concatenate([[0.0], np.cumsum(steps)])
        g = PoseGraph(poses=cur.copy())
        kept = rejected = 0
        for k in range(1, n):
            rel = between2(cur[k - 1], cur[k])
            z, ok, info = matches.get(k - 1, k, rel)
            g.add_edge(k - 1, k, z if ok else rel, info if ok else weak)
            # nearest earlier nodes in space, not the previous one
            d = np.hypot(cur[: k - 1, 0] - cur[k, 0], cur[: k - 1, 1] - cur[k, 1])
            dth = np.abs(wrap_angle(cur[: k - 1, 2] - cur[k, 2]))
            back = travel[k] - travel[: k - 1]
            cand = np.flatnonzero((d < p.radius) & (dth < p.max_heading) & (back >= p.min_travel))
            for j in cand[np.argsort(d[cand])][: p.neighbours]:
                z, ok, info = matches.get(int(j), k, between2(cur[j], cur[k]))
                if ok:
                    g.add_edge(int(j), k, z, info, robust=True)
                    kept += 1
                else:
                    rejected += 1
        g.optimize(iterations=15, kernel=p.kernel, tol=p.tol)
        # switch off the constraints the optimised graph still disagrees with, then optimise again
        bad = np.flatnonzero((g.edge_distances() > p.reject) & np.asarray(g.edges_robust, dtype=bool))
        for e in bad[::-1]:
            g.remove_edge(int(e))
        if len(bad):
            g.optimize(iterations=10, kernel=p.kernel, tol=p.tol)
        cur = g.poses.copy()
        stats = {"refine_edges": kept - len(bad), "refine_rejected": rejected + len(bad)}
    return cur, stats
