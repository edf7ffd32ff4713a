"""Robot footprints as costmap_2d reads them: ``robot_radius`` (m) or a polygon ``footprint`` in the base frame.

A polygon is a float array (N, 2) of vertices (m, base frame: x forward, y left). ROS accepts it as a
YAML list ``[[x, y], ...]`` or as the same text in a string (``"[[0.2, 0.2], [0.2, -0.2], ...]"``).
``footprint_padding`` (m) moves each vertex away from the centre along each axis (costmap_2d's
``padFootprint``); a circular robot's radius grows by the padding.
"""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from navlab.core import check_ceiling
from navlab.grid import Grid
from navlab.navigation.costmap.kernels import circle_cells, fill_circle
from navlab.navigation.errors import NavigationError


@dataclass(frozen=True)
class Footprint:
    """A padded footprint: a circle (``radius`` m, ``polygon`` None) or a polygon (N, 2) in the base frame (m)."""

    radius: float | None
    polygon: np.ndarray | None

    @property
    def inscribed_radius(self) -> float:
        """Largest circle around the base origin inside the footprint (m): the nearest edge's distance."""
        if self.polygon is None:
            return float(self.radius or 0.0)
        pts = self.polygon
        return float(
            min(_point_segment_distance(np.zeros(2), pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts)))
        )

    @property
    def circumscribed_radius(self) -> float:
        """Smallest circle around the base origin that holds the footprint (m): the farthest vertex."""
        if self.polygon is None:
            return float(self.radius or 0.0)
        return float(np.hypot(self.polygon[:, 0], self.polygon[:, 1]).max())

    def oriented(self, pose: tuple[float, float, float]) -> np.ndarray | None:
        """The polygon's vertices (N, 2) placed at ``pose`` (x, y, yaw) in the costmap frame; None for a circle."""
        if self.polygon is None:
            return None
        x, y, yaw = pose
        c, s = math.cos(yaw), math.sin(yaw)
        p = self.polygon
        return np.stack([x + c * p[:, 0] - s * p[:, 1], y + s * p[:, 0] + c * p[:, 1]], axis=1)

    def fill(self, grid: Grid, pose: tuple[float, float, float], value: int) -> None:
        """Set the :meth:`cells` under the footprint at ``pose`` to ``value`` (a round robot's in one compiled call)."""
        if self.polygon is not None or grid.origin[2] != 0.0:
            ij = self.cells(grid, pose)
            grid.data[ij[:, 1], ij[:, 0]] = value
            return
        x, y, _ = pose
        fill_circle(grid.data, float(x), float(y), float(self.radius or 0.0), *grid.origin[:2], grid.resolution, value)

    def cells(self, grid: Grid, pose: tuple[float, float, float]) -> np.ndarray:
        """Cells (i column, j row) (M, 2) of ``grid`` whose centres lie under the footprint at ``pose``.

        The cell holding the pose is always included (a footprint smaller than a cell still covers one).
        """
        if grid.origin[2] != 0.0:
            raise NavigationError(f"footprint cells need a costmap with origin yaw 0, got {grid.origin[2]}")
        x, y, _ = pose
        reach = self.circumscribed_radius
        if self.polygon is None:  # a round robot: one compiled pass
            return circle_cells(
                float(x), float(y), reach, grid.origin[0], grid.origin[1], grid.resolution, grid.width, grid.height
            )
        lo = grid.world_to_cell(np.array([[x - reach, y - reach]]))[0]
        hi = grid.world_to_cell(np.array([[x + reach, y + reach]]))[0]
        ii, jj = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1))
        ij = np.stack([ii.ravel(), jj.ravel()], axis=1)
        centres = grid.cell_to_world(ij)
        poly = self.oriented(pose)
        if poly is None:
            inside = np.hypot(centres[:, 0] - x, centres[:, 1] - y) <= reach
        else:
            inside = points_in_polygon(centres, poly)
        ci, cj = grid.world_to_cell(np.array([[x, y]]))[0]  # the cell under the pose: inside the box, always kept
        inside[(cj - lo[1]) * (hi[0] - lo[0] + 1) + (ci - lo[0])] = True
        out = ij[inside]
        return out[grid.in_bounds(out)]


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance (m) from point ``p`` to segment ``a``-``b``."""
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom == 0.0 else min(1.0, max(0.0, float((p - a) @ ab) / denom))
    return float(np.linalg.norm(a + t * ab - p))


def points_in_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Boolean mask (N,) of ``points`` (N, 2) inside ``polygon`` (M, 2) (even-odd rule, vectorised)."""
    px, py = points[:, 0][:, None], points[:, 1][:, None]
    ax, ay = polygon[:, 0][None, :], polygon[:, 1][None, :]
    bx, by = np.roll(polygon[:, 0], -1)[None, :], np.roll(polygon[:, 1], -1)[None, :]
    crosses = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_at = ax + (py - ay) * (bx - ax) / (by - ay)
    return np.count_nonzero(crosses & (px < x_at), axis=1) % 2 == 1


def parse_polygon(value: Any, *, key: str = "footprint") -> np.ndarray | None:
    """A footprint polygon (N, 2) from a YAML list or ROS's string form "[[x, y], ...]"; None when empty."""
    if value is None:
        return None
    raw = value
    if isinstance(value, str):
        text = value.strip()
        if text in ("", "[]"):
            return None
        try:
            if len(text) > 100_000:
                raise ValueError("too long")
            raw = ast.literal_eval(text)
        except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
            raise NavigationError(
                f"costmap parameter {key}: expected a list of [x, y] points such as "
                f"'[[0.2, 0.2], [0.2, -0.2], [-0.2, -0.2], [-0.2, 0.2]]', got {value!r}"
            ) from None
    try:
        pts = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise NavigationError(f"costmap parameter {key}: expected a list of [x, y] points, got {value!r}") from None
    if pts.size == 0:
        return None
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise NavigationError(f"costmap parameter {key}: expected a list of [x, y] points, got {value!r}")
    if len(pts) < 3:
        raise NavigationError(f"costmap parameter {key}: a polygon needs at least 3 points, got {len(pts)}")
    if not np.isfinite(pts).all():
        raise NavigationError(f"costmap parameter {key}: points must be finite numbers, got {value!r}")
    check_ceiling(NavigationError, "costmap", f"{key} (number of points)", len(pts), "polygon_points")
    check_ceiling(
        NavigationError,
        "costmap",
        f"{key} (a point's distance from the centre)",
        float(np.hypot(pts[:, 0], pts[:, 1]).max()),
        "footprint_m",
    )
    return pts


def pad_polygon(polygon: np.ndarray, padding: float) -> np.ndarray:
    """Each vertex moved ``padding`` m away from the centre along x and along y (costmap_2d's ``padFootprint``)."""
    return polygon + np.sign(polygon) * padding


def make_footprint(*, robot_radius: float = 0.46, footprint: Any = None, footprint_padding: float = 0.01) -> Footprint:
    """The padded footprint from costmap_2d's parameters: ``footprint`` if non-empty, else ``robot_radius``."""
    if not math.isfinite(footprint_padding):
        raise NavigationError(f"costmap parameter footprint_padding: expected a finite number, got {footprint_padding}")
    polygon = parse_polygon(footprint)
    if polygon is not None:
        padded = pad_polygon(polygon, footprint_padding)
        if not points_in_polygon(np.zeros((1, 2)), padded)[0]:
            raise NavigationError(
                f"costmap parameter footprint: the robot's centre (0, 0) must lie inside the "
                f"polygon, got {polygon.tolist()}"
            )
        return Footprint(None, padded)
    if not (math.isfinite(robot_radius) and robot_radius > 0):
        raise NavigationError(f"costmap parameter robot_radius: expected a positive number (m), got {robot_radius}")
    radius = robot_radius + footprint_padding
    if radius <= 0:
        raise NavigationError(
            f"costmap parameters robot_radius {robot_radius} + footprint_padding "
            f"{footprint_padding}: expected a positive padded radius"
        )
    return Footprint(radius, None)
