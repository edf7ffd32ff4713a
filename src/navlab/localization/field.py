"""The map as AMCL sees it: free cells, occupied cells and the distance to the nearest obstacle.

A ``MapField`` is built from an occupancy grid in ROS ``nav_msgs/OccupancyGrid`` layout: ``data`` is
int8 ``(height, width)``, row 0 at the lowest y, values -1 (unknown) or 0..100 (occupancy %);
``resolution`` is metres per cell; ``origin`` ``(x, y, yaw)`` is the pose of cell (0, 0)'s lower-left
corner in the map frame. Poses passed in and out are in the map frame; internally they are
converted to the grid frame (the origin's frame), so a rotated origin is handled exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from navlab.geometry import wrap_angle
from navlab.localization.errors import LocalizationError

OCCUPIED_MIN = 65  # ROS map_server occupied_thresh 0.65
FREE_MAX = 19  # ROS map_server free_thresh 0.196


@dataclass(frozen=True)
class MapField:
    """Occupancy grid plus its obstacle distance field (metres, clipped at ``max_dist``)."""

    occupied: np.ndarray  # bool (H, W)
    free: np.ndarray  # bool (H, W)
    distance: np.ndarray  # float32 (H, W), metres to the nearest occupied cell, <= max_dist
    signed: np.ndarray  # float32 (H, W), signed distance (m) from the cell centre to the obstacle surface
    resolution: float
    origin: tuple[float, float, float]
    max_dist: float
    free_index: np.ndarray  # int64 (K,), flat indices of free cells

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width) in cells."""
        h, w = self.occupied.shape
        return h, w

    def to_grid(self, poses: np.ndarray) -> np.ndarray:
        """Poses ``(N, 3)`` in the map frame → poses in the grid frame (origin at cell (0,0)'s corner)."""
        ox, oy, oyaw = self.origin
        c, s = math.cos(oyaw), math.sin(oyaw)
        dx = poses[:, 0] - ox
        dy = poses[:, 1] - oy
        out = np.empty_like(poses, dtype=np.float64)
        out[:, 0] = c * dx + s * dy
        out[:, 1] = -s * dx + c * dy
        out[:, 2] = poses[:, 2] - oyaw
        return out

    def from_grid(self, poses: np.ndarray) -> np.ndarray:
        """Poses ``(N, 3)`` in the grid frame → map frame, yaw wrapped to [-pi, pi)."""
        ox, oy, oyaw = self.origin
        c, s = math.cos(oyaw), math.sin(oyaw)
        out = np.empty_like(poses, dtype=np.float64)
        out[:, 0] = ox + c * poses[:, 0] - s * poses[:, 1]
        out[:, 1] = oy + s * poses[:, 0] + c * poses[:, 1]
        out[:, 2] = wrap_angle(poses[:, 2] + oyaw)
        return out

    def contains(self, x: float, y: float) -> bool:
        """Whether the map-frame point (m) lies within the grid's bounds."""
        g = self.to_grid(np.array([[x, y, 0.0]]))[0]
        h, w = self.shape
        return bool(0 <= g[0] < w * self.resolution and 0 <= g[1] < h * self.resolution)

    def is_free(self, x: float, y: float) -> bool:
        """Whether the map-frame point (m) lies in a free cell of the map."""
        g = self.to_grid(np.array([[x, y, 0.0]]))[0]
        i = math.floor(g[0] / self.resolution)
        j = math.floor(g[1] / self.resolution)
        h, w = self.shape
        return bool(0 <= i < w and 0 <= j < h and self.free[j, i])

    def random_free_poses(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` poses (map frame) uniform over free cells (uniform within the cell) and yaw."""
        _, w = self.shape
        idx = self.free_index[rng.integers(0, self.free_index.size, size=n)]
        g = np.empty((n, 3))
        g[:, 0] = (idx % w + rng.random(n)) * self.resolution
        g[:, 1] = (idx // w + rng.random(n)) * self.resolution
        g[:, 2] = rng.uniform(-math.pi, math.pi, size=n)
        return self.from_grid(g)


def build_field(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    *,
    max_dist: float = 2.0,
    name: str = "map",
) -> MapField:
    """Classify cells and compute the distance field; raise ``LocalizationError`` on a bad grid.

    ``name`` names the map in error messages (a file or topic).
    """
    arr = np.asarray(data)
    if arr.ndim != 2 or arr.size == 0:
        raise LocalizationError(
            f"{name}: occupancy data must be a non-empty 2-D (height, width) array, got shape {arr.shape}"
        )
    if not (math.isfinite(resolution) and resolution > 0):
        raise LocalizationError(f"{name}: resolution must be a positive number of metres, got {resolution!r}")
    if len(origin) != 3 or not all(math.isfinite(float(v)) for v in origin):
        raise LocalizationError(f"{name}: origin must be three finite numbers (x, y, yaw), got {origin!r}")
    if not (max_dist > 0):
        raise LocalizationError(f"laser_likelihood_max_dist must be > 0 m, got {max_dist!r}")
    arr = arr.astype(np.int16)
    occupied = arr >= OCCUPIED_MIN
    free = (arr >= 0) & (arr <= FREE_MAX)
    free_index = np.flatnonzero(free)
    if free_index.size == 0:
        raise LocalizationError(
            f"{name}: the map has no free cells (values 0..{FREE_MAX}); AMCL needs free space to place particles"
        )
    if occupied.any():
        dist = distance_to(occupied) * resolution
        inside = distance_to(~occupied) * resolution if (~occupied).any() else np.zeros(arr.shape)
        # Obstacle surfaces lie on cell boundaries: half a cell from the centres on either side.
        signed = np.where(occupied, 0.5 * resolution - inside, dist - 0.5 * resolution)
    else:
        dist = np.full(arr.shape, max_dist)
        signed = dist
    dist = np.minimum(dist, max_dist).astype(np.float32)
    signed = np.clip(signed, -max_dist, max_dist).astype(np.float32)
    return MapField(
        occupied=occupied,
        free=free,
        distance=dist,
        signed=signed,
        resolution=float(resolution),
        origin=(float(origin[0]), float(origin[1]), float(origin[2])),
        max_dist=float(max_dist),
        free_index=free_index,
    )


def distance_to(features: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells, float64) of every cell of a 2-D grid to its nearest ``features`` cell (True; at
    least one): what ``scipy.ndimage.distance_transform_edt(~features)`` gives, bit for bit (both are exact: the
    square root of the same least sum of squares), by Felzenszwalb and Huttenlocher's two passes, compiled."""
    return _distance_to(np.ascontiguousarray(features, dtype=np.bool_))


@njit(cache=True)
def _distance_to(features: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`distance_to`: squared distances along each column, then per row the lower envelope of the parabolas
    ``g[q] + (x - q)**2`` (columns without a feature left out), in exact integers held as floats."""
    h, w = features.shape
    none = -1.0  # a column without a feature: no parabola
    g = np.empty((h, w))
    for x in range(w):
        d = -1
        for y in range(h):  # distance to the nearest feature above (or on) the cell
            if features[y, x]:
                d = 0
            elif d >= 0:
                d += 1
            g[y, x] = d
        d = -1
        for y in range(h - 1, -1, -1):  # ... or below it
            if features[y, x]:
                d = 0
            elif d >= 0:
                d += 1
            if d >= 0 and (g[y, x] < 0 or d < g[y, x]):
                g[y, x] = d
        for y in range(h):
            g[y, x] = g[y, x] * g[y, x] if g[y, x] >= 0 else none
    out = np.empty((h, w))
    v = np.empty(w, dtype=np.int64)  # the envelope's parabolas (their columns), left to right
    z = np.empty(w + 1)  # where each takes over
    for y in range(h):
        f = g[y]
        k = -1
        for q in range(w):
            if f[q] == none:
                continue
            fq = f[q] + q * q
            while k >= 0:
                s = (fq - (f[v[k]] + v[k] * v[k])) / (2.0 * (q - v[k]))
                if s <= z[k]:
                    k -= 1
                else:
                    break
            k += 1
            v[k] = q
            z[k] = -np.inf if k == 0 else (fq - (f[v[k - 1]] + v[k - 1] * v[k - 1])) / (2.0 * (q - v[k - 1]))
            z[k + 1] = np.inf
        j = 0
        for x in range(w):
            while z[j + 1] < x:
                j += 1
            dx = x - v[j]
            out[y, x] = math.sqrt(f[v[j]] + dx * dx)
    return out


def field_from_map(grid: Any, *, max_dist: float = 2.0, name: str = "map") -> MapField:
    """``MapField`` from anything with ``data``, ``resolution`` and ``origin`` (e.g. ``GridMap``)."""
    for attr in ("data", "resolution", "origin"):
        if not hasattr(grid, attr):
            raise LocalizationError(f"{name}: expected a grid map with .data, .resolution and .origin; missing .{attr}")
    o = [float(v) for v in grid.origin]
    if len(o) == 2:
        o.append(0.0)
    return build_field(grid.data, float(grid.resolution), (o[0], o[1], o[2]), max_dist=max_dist, name=name)
