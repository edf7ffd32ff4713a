"""slam_gmapping's ``mode`` plugins: the SLAM algorithms behind the ``SlamBackend`` seam (``navlab.plugins``).

Each backend is built as ``cls.from_params(params, context=PluginContext(rng=...))`` from slam_gmapping's
parameter names (a mode's own parameters under its name: ``graph.voxel``), and is what both the
``slam_gmapping`` node and ``navlab slam`` (``run_offline``) drive. Adding a mode is one such class and one
``navlab.slam_backends`` entry point (in navlab's pyproject.toml or a package of one's own: docs/plugins.md).

- ``gmapping``: the Rao-Blackwellized particle filter (:class:`~navlab.mapping.gmapping.GMapping`),
  which applies odometry to every scan and updates the map after ``linearUpdate``/``angularUpdate``/
  ``temporalUpdate``.
- ``graph``: scan matching, loop closure and pose-graph optimisation
  (:class:`~navlab.mapping.graph_slam.GraphSlam`) on the scans a node finds :meth:`~GraphBackend.due`
  by the same gating; its map is built from the scans at the graph's poses (``delta`` m cells,
  beams cut at ``maxUrange``).

Pure: numpy in, poses and grids out; no topics, no clock. Ranges in metres, poses (x, y, yaw).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Self

import numpy as np

from navlab.core import dataclass_parameters, read_params
from navlab.geometry import between2
from navlab.grid import GridMap
from navlab.mapping.errors import MappingError
from navlab.mapping.gmapping import GMapping, GMappingParams
from navlab.mapping.gmapping_match import warmup as gmapping_warmup
from navlab.mapping.graph_slam import GraphSlam, GraphSlamParams
from navlab.mapping.occupancy import build_map
from navlab.mapping.refine import RefineParams, refine_poses
from navlab.mapping.scanmatch import ScanPoints, scan_points
from navlab.plugins import PluginContext


def _int_stats(obj: object) -> dict[str, int]:
    """An algorithm object's public integer counters (updates, resamples, loop_edges, ...)."""
    return {
        k: v for k, v in vars(obj).items() if isinstance(v, int) and not isinstance(v, bool) and not k.startswith("_")
    }


def _no_return_as(ranges: np.ndarray, value: float) -> np.ndarray:
    """``ranges`` (m) with every non-finite reading (no return) replaced by ``value``."""
    r = np.asarray(ranges, dtype=np.float64)
    return np.where(np.isfinite(r), r, value)


class SeededBackend:
    """What both modes share: built from slam_gmapping's parameters and the node's seeded RNG."""

    def __init__(self, params: dict[str, Any] | None = None, *, rng: np.random.Generator) -> None:
        raise NotImplementedError

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """``params``: slam_gmapping's names (a mode's own under its name); ``context.rng`` (required)."""
        if context.rng is None:
            raise MappingError(f"SLAM mode {context.name or cls.__name__}: needs a seeded rng in its context")
        return cls(dict(params or {}), rng=context.rng)


class GMappingBackend(SeededBackend):
    """``mode: gmapping``: slam_gmapping's RBPF. ``params``: GMapping's names (``particles``, ``delta``, ...)."""

    def __init__(self, params: dict[str, Any] | None = None, *, rng: np.random.Generator) -> None:
        self.params = read_params(GMappingParams, params)
        self.slam = GMapping(self.params, rng=rng)
        gmapping_warmup()  # the kernels' one-time load at start-up, not at the first map update
        self._points: list[ScanPoints] = []  # every scan's points, for the final refinement
        # kept only when set (run_offline does): a live node never finishes and would only pile them up
        self.keep_scans = False
        self.refine_edges = 0
        self.refine_rejected = 0

    @classmethod
    def parameters(cls) -> dict[str, Any]:
        """GMapping's parameter names with slam_gmapping's defaults."""
        return dataclass_parameters(GMappingParams)

    def due(self, odom_laser: np.ndarray, stamp_ns: int) -> bool:
        """Always: GMapping moves its particles on every scan and gates its map updates itself."""
        return True

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_laser: np.ndarray,
        *,
        range_max: float | None = None,
        stamp_ns: int | None = None,
    ) -> np.ndarray | None:
        """Move the particles by the odometry step; after enough motion, scan-match, weigh, resample and
        integrate the scan. Returns the best particle's laser pose if the map was updated (always for the
        first scan), else None. With ``range_max``, no-return readings count as ``range_max`` and a
        ``maxRange`` of 0 becomes ``range_max - 0.01``, as slam_gmapping does."""
        if range_max is not None:
            p = self.params
            if p.maxRange <= 0:
                p.maxRange = range_max - 0.01
                p.maxUrange = min(p.maxUrange, p.maxRange)
        self.slam.keep_scans = self.keep_scans
        if self.params.refine and self.keep_scans:
            r = ranges if range_max is None else _no_return_as(ranges, range_max)
            self._points.append(
                scan_points(r, angle_min, angle_increment, range_max=min(self.params.maxUrange, 30.0), voxel=0.04)
            )
        first = not self.slam.particles
        before = self.slam.updates
        stamp = None if stamp_ns is None else stamp_ns * 1e-9
        # the ranges are converted only when the scan updates the map (1 scan in ~40 live)
        pose = self.slam.add_scan(ranges, angle_min, angle_increment, odom_laser, stamp=stamp, no_return=range_max)
        if not first and self.slam.updates == before:
            return None
        return pose

    def trajectory(self) -> np.ndarray:
        """The best particle's laser pose at every updated scan (M, 3)."""
        traj = self.slam.trajectory()
        return np.array([traj[k] for k in sorted(traj)]).reshape(-1, 3)

    def current_map(self, *, frame_id: str = "map") -> GridMap | None:
        """The best particle's map."""
        return self.slam.map(frame_id=frame_id) if self.slam.particles else None

    def finish(self) -> np.ndarray:
        """Laser poses (N, 3) of every scan added (see ``GMapping.finish``), refined with dense verified
        scan-to-scan constraints (``refine``, :func:`~navlab.mapping.refine.refine_poses`)."""
        poses = self.slam.finish()
        if self.params.refine and len(self._points) == len(poses) > 2:
            # no front end has linked neighbouring scans here: match against the nearest ones too. ICP runs 8
            # iterations, not 14 (its search radius shrinks over 4, then at most 4 at the finest: the same figures
            # on CSAIL at 60 % of the cost); a match's information follows its ICP Hessian (a corridor's axis is
            # left to the other edges); the filter's poses, each matched against the finished map, need one round,
            # not three (CSAIL seeds 0/1/2 refined 0.0270/0.0279/0.0285 m with one, 0.0270/0.0276/0.0286 m with
            # two, for a third less of the refinement's CPU); the graph's Gauss-Newton stops at steps under 0.1 mm
            # / 1e-4 rad (a quarter fewer solves, the same poses to 0.1 mm)
            params = RefineParams(min_travel=0.0, neighbours=6, icp_iterations=8, tol=1e-4, shape_xy=2.0, rounds=1)
            poses, stats = refine_poses(poses, self._points, params)
            self.refine_edges, self.refine_rejected = stats["refine_edges"], stats["refine_rejected"]
        return poses

    def stats(self) -> dict[str, int]:
        """GMapping's counters (updates, resamples) and the refinement's."""
        return {**_int_stats(self.slam), **_int_stats(self)}


class GraphBackend(SeededBackend):
    """``mode: graph``: incremental graph SLAM. Its own parameters are ``graph.*`` (``GraphSlamParams``);
    slam_gmapping's ``linearUpdate``/``angularUpdate``/``temporalUpdate`` gate it (:meth:`due`), and
    ``delta``/``maxUrange`` shape its map."""

    def __init__(self, params: dict[str, Any] | None = None, *, rng: np.random.Generator) -> None:
        top: dict[str, Any] = {}
        own: dict[str, Any] = {}
        gm_names, graph_names = set(dataclass_parameters(GMappingParams)), set(dataclass_parameters(GraphSlamParams))
        for key, value in (params or {}).items():
            if key.startswith("graph."):
                own[key.removeprefix("graph.")] = value
            elif key not in gm_names and key in graph_names:
                raise MappingError(f"graph SLAM parameter '{key}' belongs under 'graph' (graph.{key})")
            else:
                top[key] = value
        self.gm = read_params(GMappingParams, top)  # gating and map parameters
        self.params = read_params(GraphSlamParams, own)
        self.slam = GraphSlam(self.params)
        self._scans: list[tuple[np.ndarray, np.ndarray]] = []  # (ranges, angles) of each processed scan
        self._last: tuple[np.ndarray, int] | None = None  # odom_laser and stamp (ns) of the last processed scan
        self._max_range = 0.0

    @classmethod
    def parameters(cls) -> dict[str, Any]:
        """slam_gmapping's names (gating, map) and ``graph.*`` with their defaults."""
        return {**dataclass_parameters(GMappingParams), **dataclass_parameters(GraphSlamParams, prefix="graph")}

    def due(self, odom_laser: np.ndarray, stamp_ns: int) -> bool:
        """Whether the laser moved ``linearUpdate`` m or turned ``angularUpdate`` rad since the last processed
        scan, or ``temporalUpdate`` s passed (>= 0 to enable); always for the first scan."""
        if self._last is None:
            return True
        gm = self.gm
        moved = between2(self._last[0], odom_laser)
        return (
            math.hypot(moved[0], moved[1]) >= gm.linearUpdate
            or abs(moved[2]) >= gm.angularUpdate
            or (gm.temporalUpdate >= 0 and (stamp_ns - self._last[1]) * 1e-9 > gm.temporalUpdate)
        )

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_laser: np.ndarray,
        *,
        range_max: float | None = None,
        stamp_ns: int | None = None,
    ) -> np.ndarray:
        """Add the scan as a graph node (matched against the recent ones, loop closure tried); returns its
        laser pose in the map frame. With ``range_max``, readings within 1 cm of it count as no return."""
        if range_max is not None:
            r = _no_return_as(ranges, range_max)
            ranges = np.where(r >= range_max - 0.01, np.inf, r)
            self._max_range = range_max
        self._last = (np.asarray(odom_laser, dtype=np.float64), 0 if stamp_ns is None else stamp_ns)
        pose = self.slam.add_scan(ranges, angle_min, angle_increment, odom_laser)
        n = len(ranges)
        self._scans.append((np.asarray(ranges), angle_min + angle_increment * np.arange(n)))
        return pose

    def trajectory(self) -> np.ndarray:
        """The graph's laser poses (M, 3), one per added scan."""
        return self.slam.poses

    def current_map(self, *, frame_id: str = "map") -> GridMap | None:
        """A map built from every added scan at the graph's current poses."""
        if not self._scans:
            return None
        max_range = self._max_range or self.gm.maxUrange
        return build_map(
            self.slam.poses,
            self._scans,
            resolution=self.gm.delta,
            max_urange=min(self.gm.maxUrange, max_range),
            max_range=max_range,
            frame_id=frame_id,
        )

    def finish(self) -> np.ndarray:
        """The optimised laser poses (N, 3) of every scan added."""
        return self.slam.finish()

    def stats(self) -> dict[str, int]:
        """GraphSlam's counters (loop_edges, loop_rejected, frontend_failures, ...)."""
        return _int_stats(self.slam)
