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
    from navlab.navigation import Footprint


@dataclass
class Track:
    """A path to draw: (N, 2+) points in the map's frame, a legend label and a matplotlib style."""

    xy: np.ndarray
    label: str
    style: str = "-"
    color: str | None = None
    width: float = 1.2


@dataclass
class Marks:
    """Points to draw over a map: (N, 2) in the map's frame, a legend label, a colour, a marker and its size."""

    xy: np.ndarray
    label: str
    color: str
    marker: str = "s"
    size: float = 2.0


@dataclass
class ErrorPanel:
    """An error-over-time panel: ``t`` (s), ``values`` (m), drawn in cm on a log scale."""

    t: np.ndarray
    values: np.ndarray
    ylabel: str = "position error (cm, log scale)"
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
    t: float  # simulated time of the snapshot (s)
    costmap_in_map: Pose2 | None  # where the costmap's (and plans') frame sits in the picture's (None: same)
    new_obstacles: np.ndarray | None  # (N, 2) points of obstacles the map does not have (added after mapping)
    dropped: list[tuple[float, float, float, str]]  # models dropped in while driving: (x m, y m, t s, name)
    near_misses: np.ndarray  # (N, 2) where the true clearance fell under 5 cm without contact
    collision_xy: np.ndarray  # (N, 2) where contact episodes began


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
    marks: Sequence[Marks] = (),
) -> Path:
    """Save the map with ``tracks`` (and ``error`` beside it) as a PNG at ``path``; returns the path.

    ``crop`` limits the view to the part of the map that is known (plus 0.5 m); ``marks``: points such as
    obstacles the map does not have, a start or goals."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io import save_figure_atomic

    if error is None:
        fig, ax = plt.subplots(figsize=(8, 7))
        ax2 = None
    else:
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1.3, 1]})
    x0, y0, x1, y1 = grid.bounds()
    ax.imshow(
        map_image(grid), cmap="gray", vmin=0, vmax=1, origin="lower", extent=(x0, x1, y0, y1), interpolation="nearest"
    )
    for m in marks:
        ax.scatter(m.xy[:, 0], m.xy[:, 1], s=m.size, marker=m.marker, c=m.color, label=m.label, zorder=3)
    for tr in tracks:
        xy = np.asarray(tr.xy, dtype=np.float64)
        if len(xy):
            style: dict[str, Any] = {"color": tr.color} if tr.color else {}  # None would override tr.style's colour
            ax.plot(xy[:, 0], xy[:, 1], tr.style, lw=tr.width, label=tr.label or None, **style)
    known = grid.known_bounds() if crop else None
    if known is not None:
        ax.set_xlim(known[0], known[2])
        ax.set_ylim(known[1], known[3])
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [m] ({grid.frame_id} frame)")
    ax.set_ylabel("y [m]")
    from matplotlib.patches import Patch

    key = [Patch(facecolor="black", label="map: occupied"), Patch(facecolor="0.8", label="map: unknown")]
    lines, _labels = ax.get_legend_handles_labels()
    ax.legend(handles=key + lines, loc="upper right", fontsize=8, framealpha=0.85)
    if title:
        ax.set_title(title)
    if ax2 is not None and error is not None:
        ax2.plot(error.t, np.asarray(error.values) * 100, color="tab:red")
        if error.threshold is not None:
            ax2.axhline(
                error.threshold * 100, color="gray", ls=":", lw=1, label=f"converged below {error.threshold * 100:g} cm"
            )
        for label, t in error.events.items():
            ax2.axvline(t, color="black", ls="--", lw=1, label=label)
        if error.events or error.threshold is not None:
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


def navigation_figure(grid: GridMap, shot: NavSnapshot, *, title: str = "", goal: Sequence[float] | None = None) -> Any:
    """A picture in the style of the paper's Figs. 9–12, with a legend: the map, the global costmap's inflation
    as a blue shadow, obstacles the map lacks (added after mapping) in purple, dropped-in models marked, the
    driven path, the global plan (blue), the local plan (green), the robot's footprint (orange) with a heading
    arrow, the last laser scan (red points), near misses and collisions, and the goal with its heading.
    ``shot`` is from ``navigate_run``; returns the matplotlib figure (the caller closes it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    from navlab.geometry import compose2, transform_points2

    fig, ax = plt.subplots(figsize=(9, 7))
    x0, y0, x1, y1 = grid.bounds()
    ax.imshow(
        map_image(grid), cmap="gray", vmin=0, vmax=1, origin="lower", extent=(x0, x1, y0, y1), interpolation="nearest"
    )
    handles: list[Any] = [Patch(facecolor="black", label="map: wall"), Patch(facecolor="0.8", label="map: unknown")]
    cm, in_map = shot.get("costmap"), shot.get("costmap_in_map")
    if cm is not None and (in_map is None or abs(in_map[2]) < 1e-6):  # a rotated odom costmap is not drawn
        c = cm.data.astype(float)
        shade = np.where((c > 0) & (c < 253), 0.15 + 0.45 * c / 252.0, 0.0)
        shade = np.where((c == 253) | (c == 254), 0.75, shade)
        rgba = np.zeros((*c.shape, 4))
        rgba[..., 2] = 0.35
        rgba[..., 3] = shade
        dx, dy = (in_map[0], in_map[1]) if in_map is not None else (0.0, 0.0)
        cx0, cy0, cx1, cy1 = cm.bounds()
        ax.imshow(rgba, origin="lower", extent=(cx0 + dx, cx1 + dx, cy0 + dy, cy1 + dy), interpolation="nearest")
        handles.append(Patch(facecolor=(0, 0, 0.35, 0.6), label="global costmap (inflation)"))
    new = shot.get("new_obstacles")
    if new is not None and len(new):
        ax.scatter(new[:, 0], new[:, 1], s=2, marker="s", c="tab:purple", label="obstacle not in the map")
    for k, (dx_, dy_, t, name) in enumerate(shot.get("dropped") or []):
        ax.scatter(
            [dx_],
            [dy_],
            s=260,
            facecolors="none",
            edgecolors="magenta",
            linewidths=2,
            label="dropped in while driving" if k == 0 else None,
        )
        ax.annotate(
            f"{name}\n(t={t:.0f} s)", (dx_, dy_), xytext=(8, 8), textcoords="offset points", fontsize=7, color="magenta"
        )
    trail = np.asarray(shot.get("path"))
    if trail.ndim == 2 and len(trail):
        ax.plot(trail[:, 0], trail[:, 1], "-", color="0.35", lw=1.0, label="driven path (truth)")
    plan = shot.get("plan")
    if plan is not None and len(plan):
        plan = np.asarray(plan)[:, :2]
        if in_map is not None:
            plan = transform_points2(in_map, plan)
        ax.plot(plan[:, 0], plan[:, 1], "-", color="tab:blue", lw=2.0, label="global plan")
    local, odom_to_map = shot.get("local_plan"), shot.get("odom_to_map")
    if local is not None and odom_to_map is not None and len(local):
        lp = transform_points2(odom_to_map, np.asarray(local)[:, :2])
        ax.plot(lp[:, 0], lp[:, 1], "-", color="tab:green", lw=2.5, label="local plan")
    scan_xy = shot.get("scan_xy")
    if scan_xy is not None and len(scan_xy):
        ax.scatter(scan_xy[:, 0], scan_xy[:, 1], s=1.5, c="tab:red", label="laser (last scan)")
    near = shot.get("near_misses")
    if near is not None and len(near):
        ax.scatter(
            near[:, 0],
            near[:, 1],
            s=60,
            marker="o",
            facecolors="none",
            edgecolors="gold",
            linewidths=1.8,
            label="near miss (< 5 cm)",
        )
    hits = shot.get("collision_xy")
    if hits is not None and len(hits):
        ax.scatter(hits[:, 0], hits[:, 1], s=90, marker="X", c="red", edgecolors="black", label="collision")
    robot = shot.get("robot")
    if robot is not None:
        sx, sy, syaw = robot
        footprint = shot.get("footprint")
        poly = footprint.oriented((sx, sy, syaw)) if footprint is not None else None
        if poly is None:
            r = footprint.circumscribed_radius if footprint is not None else 0.2
            ang = np.linspace(0, 2 * np.pi, 33)
            poly = np.stack([sx + r * np.cos(ang), sy + r * np.sin(ang)], axis=1)
        ax.fill(poly[:, 0], poly[:, 1], color="tab:orange", alpha=0.9, label="robot (truth)")
        _arrow(ax, sx, sy, syaw, "black")
    seen = [trail.reshape(-1, 2)] if trail.ndim == 2 else []
    if goal is not None:
        gx, gy, gyaw = compose2(in_map, tuple(goal)) if in_map is not None else tuple(goal)
        ax.plot(gx, gy, "*", color="tab:purple", ms=14, label="goal")
        _arrow(ax, gx, gy, gyaw, "tab:purple")
        seen.append(np.array([[gx, gy]]))
    known = grid.known_bounds()
    if known is not None:  # the known map, widened to show the whole drive and the goal
        pts = np.vstack([np.array([[known[0], known[1]], [known[2], known[3]]]), *seen])
        lo, hi = pts.min(0), pts.max(0)
        pad = np.where(pts.min(0) < known[:2], 0.5, 0.0), np.where(pts.max(0) > known[2:], 0.5, 0.0)
        ax.set_xlim(lo[0] - pad[0][0], hi[0] + pad[1][0])
        ax.set_ylim(lo[1] - pad[0][1], hi[1] + pad[1][1])
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [m] ({'world' if in_map is not None else 'map'} frame)")
    ax.set_ylabel("y [m]")
    lines, _labels = ax.get_legend_handles_labels()
    ax.legend(
        handles=handles + lines,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=7,
        title="legend",
        title_fontsize=8,
    )
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def plot_navigation(
    grid: GridMap, shot: NavSnapshot, path: str | Path, *, title: str = "", goal: Sequence[float] | None = None
) -> Path:
    """Save :func:`navigation_figure` as a PNG at ``path`` (atomically); returns the path."""
    import matplotlib.pyplot as plt

    from navlab.io import save_figure_atomic

    fig = navigation_figure(grid, shot, title=title, goal=goal)
    out = Path(path)
    try:
        save_figure_atomic(fig, out, format="png", dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)
    return out


def _arrow(ax: Any, x: float, y: float, yaw: float, color: str, length: float = 0.45) -> None:
    """A heading arrow of ``length`` m from (x, y) along ``yaw`` (rad)."""
    ax.annotate(
        "",
        xy=(x + length * np.cos(yaw), y + length * np.sin(yaw)),
        xytext=(x, y),
        arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.8},
    )
