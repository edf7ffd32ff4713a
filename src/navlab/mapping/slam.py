"""Offline SLAM over a laser log: run a SLAM mode scan by scan, then build the map and write results.

``run_offline`` feeds every scan of a ``CarmenLog`` to the chosen mode (``graph``: scan-to-map
matching with loop closure and pose-graph optimisation; ``gmapping``: the paper's Rao-Blackwellized
particle filter), and returns robot poses per scan plus the occupancy grid. ``write_outputs`` writes
``map.yaml``/``map.pgm`` (map_saver format) and ``poses.txt`` (``timestamp x y theta``).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab.core import flatten_params
from navlab.geometry import compose2, inverse2
from navlab.grid import GridMap
from navlab.io import CarmenLog
from navlab.mapping.errors import MappingError
from navlab.mapping.mapfile import save_map
from navlab.mapping.occupancy import build_map
from navlab.plugins import PluginContext, PluginError, SlamBackend, load_plugin


@dataclass
class SlamResult:
    """Per-scan timestamps (s) and robot poses (N, 3) in the map frame, the map, and run statistics."""

    timestamps: np.ndarray
    poses: np.ndarray
    laser_poses: np.ndarray
    grid: GridMap
    stats: dict[str, Any] = field(default_factory=dict)


def make_slam(mode: str, params: dict[str, Any] | None = None, *, seed: int = 0) -> SlamBackend:
    """The ``SlamBackend`` plugin registered as ``mode`` (slam_gmapping's ``mode``: ``gmapping``, ``graph``).

    ``params``: slam_gmapping's parameter names, as in its YAML file (a mode's own under its name:
    ``{"graph": {"loop_every": 1}}`` or ``{"graph.loop_every": 1}``). An unknown mode says "did you mean".
    """
    try:
        cls = load_plugin("slam_backend", mode, param="SLAM mode")
    except PluginError as exc:
        raise MappingError(str(exc)) from None
    context = PluginContext(name=mode, rng=np.random.default_rng(seed))
    backend: SlamBackend = cls.from_params(flatten_params(params or {}), context=context)
    return backend


def run_offline(
    log: CarmenLog,
    *,
    mode: str = "graph",
    params: dict[str, Any] | None = None,
    seed: int = 0,
    resolution: float = 0.05,
    map_max_urange: float = 30.0,
    max_scans: int | None = None,
    progress: bool = False,
) -> SlamResult:
    """Run SLAM over the log's scans (all, or the first ``max_scans``) and build the final map.

    Every scan goes to the mode's ``add_scan`` (a node's ``due`` gating is not applied to a log) with the
    log's sensor range as the scan's ``range_max``, as slam_gmapping takes a LaserScan's: readings at or
    beyond it (CARMEN's 81.9 m "no return") are no hits and no free-space rays, and an unset ``maxRange``
    becomes ``range_max - 0.01``."""
    from tqdm import tqdm

    scans = log.scans[:max_scans] if max_scans else log.scans
    slam = make_slam(mode, params, seed=seed)
    if hasattr(slam, "keep_scans"):  # offline, the mode may refine every scan's pose at the end
        slam.keep_scans = True
    for s in tqdm(scans, desc=f"slam ({mode})", unit="scan", disable=not progress, file=sys.stderr):
        slam.add_scan(s.ranges, s.angle_min, s.angle_increment, s.laser_pose, range_max=s.max_range)
    laser = np.asarray(slam.finish(), dtype=np.float64)
    robot = np.array([compose2(lp, inverse2(s.laser_offset)) for lp, s in zip(laser, scans, strict=True)])
    grid = build_map(
        laser,
        [(s.ranges.astype(np.float64), s.angle_min + s.angle_increment * np.arange(len(s.ranges))) for s in scans],
        resolution=resolution,
        max_urange=map_max_urange,
        max_range=min(s.max_range for s in scans),
    )
    return SlamResult(np.array([s.timestamp for s in scans]), robot, laser, grid, slam.stats())


def write_outputs(result: SlamResult, out_dir: str | Path) -> dict[str, Path]:
    """Write map.yaml, map.pgm and poses.txt into ``out_dir`` (created if needed); a picture of them is
    ``experiments.plots.plot_run``'s job."""
    from navlab.io import write_poses

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MappingError(f"cannot create output directory {out}: {exc.strerror or exc}") from None
    image = save_map(result.grid, out / "map.yaml")
    write_poses(out / "poses.txt", result.timestamps, result.poses)
    return {"yaml": out / "map.yaml", "image": image, "poses": out / "poses.txt"}
