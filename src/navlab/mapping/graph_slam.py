"""Graph SLAM: scan-to-local-map matching, loop closure and sparse pose-graph optimisation.

Every scan becomes a node. The front end predicts the scan's pose from odometry, finds it with a
coarse-to-fine correlative search on smoothed hit grids of the recent scans (a window grown with the
odometry step: sparse logs move up to 1 m and 30 degrees between scans), and refines it by point-to-line
ICP.
Every ``loop_every`` nodes, the back end looks for old nodes (far along the path, near in space),
matches the scan against their scans with a coarse-to-fine correlative search and ICP, and, if the
match is good, adds a robust edge and re-optimises the whole graph; an edge the optimised graph
still disagrees with is dropped. Pure: numpy arrays in, poses out; no topics, no clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from navlab.core import ParamSpec
from navlab.geometry import between2, compose2, inverse2, rotate_vectors2, transform_points2
from navlab.mapping.errors import MappingError
from navlab.mapping.posegraph import PoseGraph
from navlab.mapping.refine import refine_poses
from navlab.mapping.scanmatch import (
    LookupField,
    ScanPoints,
    correlative_search,
    icp_point_to_line,
    scan_points,
)


@dataclass
class GraphSlamParams:
    """Parameters of the graph mode (lengths m, angles rad)."""

    maxUrange: float = 30.0
    voxel: float = 0.04  # one point per voxel of this size (m)
    local_window: int = 15  # recent nodes in the local map
    search_lin: float = 0.3  # correlative search half-window around the odometry prediction (m)
    search_ang: float = math.radians(15.0)
    search_ang_step: float = math.radians(0.5)
    # the window grows with the odometry step's uncertainty: half-widths of at least these fractions of
    # the step (m per m travelled, m per rad turned; rad per rad turned, rad per m travelled)
    search_lin_per_m: float = 0.25
    search_lin_per_rad: float = 0.25
    search_ang_per_rad: float = 0.3
    search_ang_per_m: float = math.radians(5.0)
    field_resolution: float = 0.05
    field_sigma: float = 0.05
    icp_max_dist: float = 0.3
    icp_min_dist: float = 0.08
    icp_iterations: int = 12
    odom_jump_lin: float = 0.1  # odometry step this far from the last estimated step -> try other priors
    odom_jump_ang: float = math.radians(8.0)
    odom_still_lin: float = 0.5  # standing still is tried only for odometry steps under these (m, rad)
    odom_still_ang: float = 0.5
    odom_jump_margin: float = 0.0  # ... and a non-odometry prior wins only with this much more ICP overlap
    min_inliers: float = 0.3  # below this the front end trusts odometry instead of the match
    seq_sigma_xy: float = 0.02  # std. dev. of a sequential edge (m)
    seq_sigma_theta: float = math.radians(0.5)
    loop_every: int = 5  # attempt a loop closure every N nodes
    loop_min_travel: float = 8.0  # candidates must be this far back along the path (m)
    loop_radius: float = 5.0  # ... and this near in space (m)
    loop_window: int = 10  # candidate's neighbours (± nodes) in the loop map
    loop_search_lin: float = 3.5  # cap of the loop search half-window (m)
    loop_search_ang: float = math.radians(15.0)
    loop_min_inliers: float = 0.65
    loop_max_rms: float = 0.04
    loop_sigma_xy: float = 0.05
    loop_sigma_theta: float = math.radians(1.0)
    loop_drift_lin: float = 0.2  # a closure may correct at most lin + rate * path length (m)
    loop_drift_rate: float = 0.03
    loop_drift_ang: float = math.radians(3.0)  # ... and at most ang + ang_rate * path length (rad)
    loop_drift_ang_rate: float = math.radians(0.1)
    loop_confirm_above: float = 0.3  # corrections larger than this (m) need a confirming second match
    loop_confirm_lin: float = 0.3  # ... agreeing within this (m)
    loop_confirm_ang: float = math.radians(2.0)
    loop_kernel: float = 3.0  # Cauchy kernel width (Mahalanobis)
    loop_reject: float = 6.0  # drop a loop edge whose optimised Mahalanobis error exceeds this
    refine: bool = False  # finish with dense verified scan-to-scan constraints (mapping.refine); off: measured
    # no gain on the CSAIL log (0.0271 -> 0.0266 m) or the office logs, at +70 % CPU

    PARAMS: ClassVar[ParamSpec] = ParamSpec("graph SLAM", MappingError)


class GraphSlam:
    """Incremental graph SLAM over laser scans; ``poses`` are laser poses (x, y, theta) in the map frame."""

    def __init__(self, params: GraphSlamParams | None = None) -> None:
        self.p = params or GraphSlamParams()
        self.graph = PoseGraph()
        self.node_xy: list[np.ndarray] = []
        self.node_normals: list[np.ndarray] = []
        self.odom: list[np.ndarray] = []
        self.path_length: list[float] = []
        self.loop_edges = 0
        self.loop_rejected = 0
        self.frontend_failures = 0
        self.loop_implausible = 0
        self.odom_jumps = 0
        self.refine_edges = 0
        self.refine_rejected = 0
        self.loop_log: list[tuple[int, int, float, float, float, float]] = []
        self._last_loop_node = -(10**9)
        self._travel_at_loop = -math.inf
        self._pending: tuple[int, int, np.ndarray, np.ndarray] | None = None
        self._world_cache: dict[int, tuple[list[float], np.ndarray, np.ndarray]] = {}  # node -> (pose, xy, normals)

    @property
    def poses(self) -> np.ndarray:
        """Current estimate of every node's laser pose (N, 3)."""
        return self.graph.poses

    def _cloud(self, idx: range | list[int]) -> tuple[np.ndarray, np.ndarray]:
        """Map-frame points and normals of nodes ``idx`` at their current poses (cached per node until its
        pose changes: only an optimisation moves old nodes)."""
        xy, nrm = [], []
        for k in idx:
            pose = self.graph.poses[k]
            key = pose.tolist()  # comparing three floats is much cheaper than np.array_equal
            hit = self._world_cache.get(k)
            if hit is None or hit[0] != key:
                world = transform_points2(pose, self.node_xy[k])
                hit = (key, world, rotate_vectors2(pose[2], self.node_normals[k]))
                self._world_cache[k] = hit
            xy.append(hit[1])
            nrm.append(hit[2])
        return np.concatenate(xy), np.concatenate(nrm)

    def _match(
        self,
        cloud: tuple[np.ndarray, np.ndarray],
        pts: np.ndarray,
        prior: np.ndarray,
        lin: float,
        ang: float,
        fields: dict[tuple[float, float], LookupField] | None = None,
    ) -> tuple[np.ndarray, float, float, float]:
        """Correlative search then ICP; returns (pose, correlative score, ICP inlier fraction, ICP rms).
        ``fields``: lookup fields of this ``cloud`` by (resolution, sigma), filled and reused across calls."""
        map_xy, map_n = cloud
        p = self.p
        cache: dict[tuple[float, float], LookupField] = {} if fields is None else fields

        def field(res: float, sigma: float) -> LookupField:
            f = cache.get((res, sigma))
            if f is None:
                f = cache[(res, sigma)] = LookupField(map_xy, resolution=res, sigma=sigma)
            return f

        sub = pts[:: max(1, len(pts) // 120)]
        if lin > 1.0:  # very wide (loop closure) windows start on a 0.2 m grid
            coarse = field(0.2, 0.2)
            prior, _ = correlative_search(
                coarse, sub, prior, lin_window=lin, ang_window=ang, ang_step=math.radians(1.0)
            )
            lin, ang = 0.3, math.radians(2.0)
        if lin > 0.2 or ang > math.radians(4.0):  # coarse-to-fine for wide windows
            coarse = field(0.1, 0.1)
            prior, _ = correlative_search(
                coarse, sub, prior, lin_window=lin, ang_window=ang, ang_step=math.radians(1.0)
            )
            lin, ang = 0.15, math.radians(1.5)
        fine = field(p.field_resolution, p.field_sigma)
        pose, score = correlative_search(fine, pts, prior, lin_window=lin, ang_window=ang, ang_step=p.search_ang_step)
        res = icp_point_to_line(
            map_xy,
            map_n,
            pts,
            pose,
            max_dist=p.icp_max_dist,
            min_dist=p.icp_min_dist,
            iterations=p.icp_iterations,
        )
        return res.pose, score, res.inlier_fraction, res.rms

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_pose: np.ndarray | tuple[float, float, float],
    ) -> np.ndarray:
        """Add a scan taken with the laser at ``odom_pose`` (odometry frame); returns its map-frame pose."""
        p = self.p
        odom = np.asarray(odom_pose, dtype=np.float64)
        sp = scan_points(ranges, angle_min, angle_increment, range_max=p.maxUrange, voxel=p.voxel)
        n = len(self.odom)
        if n == 0:
            pose = odom.copy()
            self.path_length.append(0.0)
        else:
            step = between2(self.odom[-1], odom)
            prior = compose2(self.graph.poses[-1], step)
            pose = prior
            if len(sp.xy) >= 10:
                lo = max(0, n - p.local_window)
                cloud = self._cloud(range(lo, n))
                if len(cloud[0]) >= 10:
                    priors = [prior]
                    if n >= 2:
                        # odometry sometimes freezes and then jumps: when its step disagrees with the last
                        # estimated step, also try constant velocity and standing still
                        last = between2(self.graph.poses[-2], self.graph.poses[-1])
                        jump = step - last
                        if math.hypot(jump[0], jump[1]) > p.odom_jump_lin or abs(jump[2]) > p.odom_jump_ang:
                            priors.append(compose2(self.graph.poses[-1], last))
                            # standing still only competes with a small odometry step: after a real step
                            # it would often fit the recent scans better than the true pose does
                            if math.hypot(step[0], step[1]) < p.odom_still_lin and abs(step[2]) < p.odom_still_ang:
                                priors.append(self.graph.poses[-1].copy())
                            self.odom_jumps += 1
                    best = None
                    fields: dict[tuple[float, float], LookupField] = {}
                    dist, turn = math.hypot(step[0], step[1]), abs(math.remainder(step[2], 2 * math.pi))
                    lin = max(p.search_lin, p.search_lin_per_m * dist + p.search_lin_per_rad * turn)
                    ang = max(p.search_ang, p.search_ang_per_rad * turn + p.search_ang_per_m * dist)
                    for m, pr in enumerate(priors):
                        cand, score, inl, _rms = self._match(cloud, sp.xy, pr, lin, ang, fields)
                        # another prior must fit clearly better than the odometry's: in a corridor, standing
                        # still fits as well as the true step (aliasing along its length)
                        margin = 0.0 if m == 0 else p.odom_jump_margin
                        if best is None or (inl - margin, score) > (best[2], best[1]):
                            best = (cand, score, inl)
                    assert best is not None
                    if best[2] >= p.min_inliers:
                        pose = best[0]
                    else:
                        self.frontend_failures += 1
            self.path_length.append(self.path_length[-1] + float(np.hypot(*step[:2])))
        self.node_xy.append(sp.xy)
        self.node_normals.append(sp.normals)
        self.odom.append(odom)
        k = self.graph.add_node(pose)
        if k > 0:
            info = np.diag([p.seq_sigma_xy**-2, p.seq_sigma_xy**-2, p.seq_sigma_theta**-2])
            self.graph.add_edge(k - 1, k, between2(self.graph.poses[k - 1], pose), info)
            if k - self._last_loop_node >= p.loop_every and len(sp.xy) >= 30:
                self._try_loop(k, sp.xy)
        return self.graph.poses[k].copy()

    def _try_loop(self, k: int, pts: np.ndarray) -> bool:
        p = self.p
        poses = self.graph.poses
        travel = np.asarray(self.path_length)
        far = np.flatnonzero(travel[k] - travel[:k] > p.loop_min_travel)
        if len(far) == 0:
            return False
        d = np.hypot(poses[far, 0] - poses[k, 0], poses[far, 1] - poses[k, 1])
        near = d < p.loop_radius
        if not near.any():
            return False
        self._last_loop_node = k
        c = int(far[near][np.argmin(d[near])])
        lo, hi = max(0, c - p.loop_window), min(k - 1, c + p.loop_window + 1)
        # only nodes that are themselves far back along the path
        idx = [m for m in range(lo, hi) if travel[k] - travel[m] > p.loop_min_travel]
        cloud = self._cloud(idx)
        # search as far as the front end could have drifted along the path since c (capped)
        path = travel[k] - travel[c]
        lin = min(p.loop_search_lin, p.loop_drift_lin + p.loop_drift_rate * path)
        ang = min(p.loop_search_ang, p.loop_drift_ang + p.loop_drift_ang_rate * path)
        pose, _score, inl, rms = self._match(cloud, pts, poses[k].copy(), lin, ang)
        if inl < p.loop_min_inliers or rms > p.loop_max_rms:
            return False
        # the correction must be a drift the front end could have accumulated along the path since c
        corr = pose - poses[k]
        if (
            math.hypot(corr[0], corr[1]) > p.loop_drift_lin + p.loop_drift_rate * path
            or abs(math.remainder(corr[2], 2 * math.pi)) > p.loop_drift_ang + p.loop_drift_ang_rate * path
        ):
            self.loop_implausible += 1
            return False
        # a large correction must be confirmed by a second, nearby match implying the same correction
        # (corridors alias along their length); small corrections are accepted at once
        edges = [(c, k, between2(poses[c], pose))]
        if math.hypot(corr[0], corr[1]) > p.loop_confirm_above:
            pend = self._pending
            correction = compose2(pose, inverse2(poses[k]))  # map-frame correction this match implies
            self._pending = (c, k, between2(poses[c], pose), correction)
            if pend is None or k - pend[1] > 3 * p.loop_every:
                return False
            diff = between2(pend[3], correction)
            if math.hypot(diff[0], diff[1]) > p.loop_confirm_lin or abs(diff[2]) > p.loop_confirm_ang:
                return False
            edges.insert(0, pend[:3])
            self._pending = None
        return self._add_loop_edges(edges, k, pose, inl, rms)

    def _add_loop_edges(self, edges: list, k: int, pose: np.ndarray, inl: float, rms: float) -> bool:
        p = self.p
        info = np.diag([p.loop_sigma_xy**-2, p.loop_sigma_xy**-2, p.loop_sigma_theta**-2])
        backup = self.graph.poses.copy()
        robust = np.asarray(self.graph.edges_robust, dtype=bool)
        before = self.graph.edge_distances()[robust]
        # a verified match may need a large correction: optimise with the new edge at full weight, then
        # keep it only if it is satisfied and no earlier loop edge became unsatisfied because of it
        n_old = len(self.graph.edges_i)
        for a, b, z in edges:
            self.graph.add_edge(a, b, z, info, robust=False)
        self.graph.optimize(iterations=15, kernel=p.loop_kernel)
        after = self.graph.edge_distances()
        broken = (after[:n_old][robust] > p.loop_reject) & (before <= p.loop_reject)
        if after[n_old:].max() > p.loop_reject or broken.any():
            for _ in edges:
                self.graph.remove_edge(len(self.graph.edges_i) - 1)
            self.graph.poses = backup
            self.loop_rejected += 1
            return False
        for e in range(n_old, len(self.graph.edges_i)):
            self.graph.edges_robust[e] = True
        c = edges[-1][0]
        self.loop_edges += len(edges)
        self._travel_at_loop = self.path_length[k]
        self.loop_log.append((c, k, float(np.hypot(*(pose - backup[k])[:2])), float(pose[2] - backup[k][2]), inl, rms))
        return True

    def finish(self, iterations: int = 20) -> np.ndarray:
        """Final optimisation of the whole graph, then (``refine``) the dense verified refinement of
        :func:`~navlab.mapping.refine.refine_poses`; returns the poses (N, 3)."""
        self.graph.optimize(iterations=iterations, kernel=self.p.loop_kernel)
        if self.p.refine and len(self.node_xy) > 2:
            scans = [ScanPoints(xy, nrm) for xy, nrm in zip(self.node_xy, self.node_normals, strict=True)]
            poses, stats = refine_poses(self.graph.poses, scans)
            self.graph.poses = poses
            self.refine_edges, self.refine_rejected = stats["refine_edges"], stats["refine_rejected"]
        return self.graph.poses.copy()
