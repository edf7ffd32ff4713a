"""The one map-and-trajectory plotter: a map (grey unknown, black walls) with paths drawn over it,
optionally beside an error-over-time panel. Written atomically as PNG."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np

from navlab.geometry import Pose2
from navlab.grid import Grid, GridMap

if TYPE_CHECKING:
    from navlab.navigation.costmap.footprint import Footprint


@dataclass
class Track:
    """A path to draw: (N, 2+) points in the map's frame, a legend label and a matplotlib style."""

    xy: np.ndarray
    label: str
    style: str = "-"
    color: str | None = None
    width: float = 1.2


@dataclass
class ErrorPanel:
    """An error-over-time panel: ``t`` (s), ``values`` (m), drawn in cm on a log scale."""

    t: np.ndarray
    values: np.ndarray
    ylabel: str = "position error (cm)"
    title: str = ""
    threshold: float | None = None
    events: dict[str, float] = field(default_factory=dict)  # label -> time (s), drawn as dashed lines


class NavSnapshot(TypedDict, total=False):
    """One moment of a navigation run as :func:`plot_navigation` draws it (map frame unless said; a
    missing or None entry is not drawn)."""

    costmap: Grid  # the global costmap (a copy)
    plan: np.ndarray | None  # the global plan (N, 2+)
    local_plan: np.ndarray | None  # the controller's local plan (N, 2+), odom frame
    odom_to_map: Pose2 | None  # map_T_odom (x m, y m, yaw rad), to draw the local plan
    path: np.ndarray  # the driven path (N, 2)
    scan_xy: np.ndarray | None  # the last scan's returns (N, 2)
    robot: Pose2 | None  # the robot's pose (x m, y m, yaw rad)
    footprint: Footprint | None  # the robot's padded footprint (None: a 0.2 m circle)


def map_image(grid: GridMap, max_pixels: int = 1200) -> np.ndarray:
    """Grey image of the grid (1 free, 0 occupied, 0.8 unknown), block-reduced so one-cell walls survive
    when the grid is larger than ``max_pixels``: a block is occupied if any cell is, else free if any is."""
    f = max(1, int(np.ceil(max(grid.width, grid.height) / max_pixels)))
    occ = grid.occupied_mask()
    free = grid.free_mask()
    if f > 1:
        occ, free = _block_any(occ, f), _block_any(free, f)
    return np.where(occ, 0.0, np.where(free, 1.0, 0.8))


def _block_any(mask: np.ndarray, f: int) -> np.ndarray:
    """A bool (H, W) mask reduced over f×f blocks (zero-padded at the far edges): True where any cell is."""
    h, w = mask.shape
    hp, wp = (h + f - 1) // f * f, (w + f - 1) // f * f
    blocks = np.pad(mask, ((0, hp - h), (0, wp - w))).reshape(hp // f, f, wp // f, f)
    return np.asarray(blocks.any(axis=(1, 3)))


def plot_run(
    grid: GridMap,
    tracks: Sequence[Track],
    path: str | Path,
    *,
    title: str = "",
    error: ErrorPanel | None = None,
    crop: bool = True,
    dpi: int = 120,
) -> Path:
    """Save the map with ``tracks`` (and ``error`` beside it) as a PNG at ``path``; returns the path.

    ``crop`` limits the view to the part of the map that is known (plus 0.5 m)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io.files import save_figure_atomic

    if error is None:
        fig, ax = plt.subplots(figsize=(8, 7))
        ax2 = None
    else:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1.3, 1]})
    x0, y0, x1, y1 = grid.bounds()
    ax.imshow(map_image(grid), cmap="gray", vmin=0, vmax=1, origin="lower", extent=(x0, x1, y0, y1),
              interpolation="nearest")  # fmt: skip
    for tr in tracks:
        xy = np.asarray(tr.xy, dtype=np.float64)
        if len(xy):
            style: dict[str, Any] = {"color": tr.color} if tr.color else {}  # None would override tr.style's colour
            ax.plot(xy[:, 0], xy[:, 1], tr.style, lw=tr.width, label=tr.label, **style)
    known = grid.known_bounds() if crop else None
    if known is not None:
        ax.set_xlim(known[0], known[2])
        ax.set_ylim(known[1], known[3])
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [m] ({grid.frame_id} frame)")
    ax.set_ylabel("y [m]")
    if tracks:
        ax.legend(loc="upper right", fontsize=8)
    if title:
        ax.set_title(title)
    if ax2 is not None and error is not None:
        ax2.plot(error.t, np.asarray(error.values) * 100, color="tab:red")
        if error.threshold is not None:
            ax2.axhline(error.threshold * 100, color="gray", ls=":", lw=1)
        for label, t in error.events.items():
            ax2.axvline(t, color="black", ls="--", lw=1, label=label)
        if error.events:
            ax2.legend(fontsize=8)
        ax2.set_yscale("log")
        ax2.set_xlabel("time (s)")
        ax2.set_ylabel(error.ylabel)
        ax2.set_title(error.title)
    fig.tight_layout()
    out = Path(path)
    try:
        save_figure_atomic(fig, out, format="png", dpi=dpi)
    finally:
        plt.close(fig)
    return out


def plot_navigation(grid: GridMap, shot: NavSnapshot, path: str | Path, *, title: str = "",
                    goal: Sequence[float] | None = None) -> Path:  # fmt: skip
    """A picture in the style of the paper's Figs. 9–12: the map, the global costmap's inflation as a dark
    shadow and its obstacles, the driven path, the global plan (blue), the local plan (green), the robot's
    footprint (orange) and the last laser scan (red points). ``shot`` is from ``navigate_run``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.geometry import compose2, transform_points2
    from navlab.io.files import save_figure_atomic

    fig, ax = plt.subplots(figsize=(8, 7))
    x0, y0, x1, y1 = grid.bounds()
    ax.imshow(map_image(grid), cmap="gray", vmin=0, vmax=1, origin="lower", extent=(x0, x1, y0, y1),
              interpolation="nearest")  # fmt: skip
    cm = shot.get("costmap")
    if cm is not None:
        c = cm.data.astype(float)
        shade = np.where((c > 0) & (c < 253), 0.15 + 0.45 * c / 252.0, 0.0)
        shade = np.where((c == 253) | (c == 254), 0.75, shade)
        rgba = np.zeros((*c.shape, 4))
        rgba[..., 2] = 0.35
        rgba[..., 3] = shade
        cx0, cy0, cx1, cy1 = cm.bounds()
        ax.imshow(rgba, origin="lower", extent=(cx0, cx1, cy0, cy1), interpolation="nearest")
    trail = np.asarray(shot.get("path"))
    if trail.ndim == 2 and len(trail):
        ax.plot(trail[:, 0], trail[:, 1], "-", color="0.35", lw=1.0, label="driven path")
    plan = shot.get("plan")
    if plan is not None:
        plan = np.asarray(plan)
        ax.plot(plan[:, 0], plan[:, 1], "-", color="tab:blue", lw=2.0, label="global plan")
    local, odom_to_map = shot.get("local_plan"), shot.get("odom_to_map")
    if local is not None and odom_to_map is not None and len(local):
        lp = transform_points2(odom_to_map, np.asarray(local)[:, :2])
        ax.plot(lp[:, 0], lp[:, 1], "-", color="tab:green", lw=2.5, label="local plan")
    scan_xy = shot.get("scan_xy")
    if scan_xy is not None and len(scan_xy):
        ax.scatter(scan_xy[:, 0], scan_xy[:, 1], s=1.5, c="tab:red", label="laser")
    robot = shot.get("robot")
    if robot is not None:
        sx, sy, syaw = robot
        footprint = shot.get("footprint")
        poly = footprint.oriented((sx, sy, syaw)) if footprint is not None else None
        if poly is None:
            r = footprint.circumscribed_radius if footprint is not None else 0.2
            ang = np.linspace(0, 2 * np.pi, 33)
            poly = np.stack([sx + r * np.cos(ang), sy + r * np.sin(ang)], axis=1)
        ax.fill(poly[:, 0], poly[:, 1], color="tab:orange", alpha=0.9, label="robot")
        tip = compose2((sx, sy, syaw), (0.3, 0.0, 0.0))
        ax.plot([sx, tip[0]], [sy, tip[1]], "-", color="black", lw=1.5)
    if goal is not None:
        ax.plot(goal[0], goal[1], "*", color="tab:purple", ms=14, label="goal")
    known = grid.known_bounds()
    if known is not None:
        ax.set_xlim(known[0], known[2])
        ax.set_ylim(known[1], known[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (map frame)")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right", fontsize=7)
    if title:
        ax.set_title(title)
    out = Path(path)
    try:
        save_figure_atomic(fig, out, format="png", dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)
    return out
