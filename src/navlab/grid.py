"""Grids shared by mapping, localization and the costmaps, with world <-> cell conversion in one place.

``Grid`` holds the geometry (resolution, origin, size) and any 2-D array; ``GridMap`` is the data of a
``nav_msgs/OccupancyGrid`` (int8 occupancy); costmaps use ``Grid`` with uint8 costs (``COST_*``).

Conventions follow ROS: ``data[j, i]`` is the cell in column ``i`` (x) and row ``j`` (y), row 0 is the
lowest y, values are -1 (unknown) or 0..100 (occupancy probability in percent). ``origin`` is the pose
(x, y, yaw) in the map frame of the lower-left corner of cell (0, 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from navlab import msgs
from navlab.errors import NavlabError

UNKNOWN = -1
FREE = 0
OCCUPIED = 100

# costmap_2d's cost values (uint8)
COST_FREE = 0
COST_INSCRIBED = 253
COST_LETHAL = 254
COST_UNKNOWN = 255


class GridError(NavlabError):
    """A grid or grid message is malformed (wrong shape, values, resolution or origin)."""


@dataclass
class Grid:
    """A 2-D array of cells in ``frame_id``: ``data[j, i]`` is column ``i`` (x), row ``j`` (y).

    ``resolution``: m/cell. ``origin``: (x m, y m, yaw rad) of the lower-left corner of cell (0, 0).
    """

    data: np.ndarray
    resolution: float
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frame_id: str = "map"

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.ndim != 2:
            raise GridError(f"{type(self).__name__}.data must be 2-D (height, width), got shape {data.shape}")
        self.data = data
        try:
            self.resolution = float(self.resolution)
        except (TypeError, ValueError):
            self.resolution = math.nan
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            name = type(self).__name__
            raise GridError(f"{name}.resolution must be a positive number of m/cell, got {self.resolution}")
        if len(self.origin) != 3 or not all(math.isfinite(float(v)) for v in self.origin):
            raise GridError(f"{type(self).__name__}.origin must be finite (x, y, yaw), got {self.origin!r}")
        self.origin = (float(self.origin[0]), float(self.origin[1]), float(self.origin[2]))

    # --- shape ----------------------------------------------------------------------------------

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.data.shape[0])

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.data.shape[1])

    # --- conversions ----------------------------------------------------------------------------

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """Cell indices ``(i column, j row)`` (int64, shape (N, 2)) of points ``xy`` (N, 2) in the map frame.

        Indices may fall outside the grid; check with :meth:`in_bounds`.
        """
        pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        ox, oy, oyaw = self.origin
        dx, dy = pts[:, 0] - ox, pts[:, 1] - oy
        if oyaw != 0.0:
            c, s = math.cos(oyaw), math.sin(oyaw)
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        return np.stack([np.floor(dx / self.resolution), np.floor(dy / self.resolution)], axis=1).astype(np.int64)

    def cell_to_world(self, ij: np.ndarray) -> np.ndarray:
        """Map-frame centres (m, shape (N, 2)) of cells ``ij`` (N, 2) given as (column i, row j)."""
        cells = np.asarray(ij, dtype=np.float64).reshape(-1, 2)
        lx = (cells[:, 0] + 0.5) * self.resolution
        ly = (cells[:, 1] + 0.5) * self.resolution
        ox, oy, oyaw = self.origin
        if oyaw != 0.0:
            c, s = math.cos(oyaw), math.sin(oyaw)
            lx, ly = c * lx - s * ly, s * lx + c * ly
        return np.stack([lx + ox, ly + oy], axis=1)

    def in_bounds(self, ij: np.ndarray) -> np.ndarray:
        """Boolean mask (N,) of cells ``ij`` (N, 2) that lie inside the grid."""
        cells = np.asarray(ij).reshape(-1, 2)
        return (cells[:, 0] >= 0) & (cells[:, 0] < self.width) & (cells[:, 1] >= 0) & (cells[:, 1] < self.height)

    def value_at(self, xy: np.ndarray, *, outside: Any = UNKNOWN) -> np.ndarray:
        """Cell values (N,) at map-frame points ``xy`` (N, 2); points outside the grid read ``outside``."""
        ij = self.world_to_cell(xy)
        out = np.full(len(ij), outside, dtype=self.data.dtype)
        ok = self.in_bounds(ij)
        out[ok] = self.data[ij[ok, 1], ij[ok, 0]]
        return out

    def centers(self, mask: np.ndarray) -> np.ndarray:
        """Map-frame centres (N, 2) of the cells where ``mask`` (same shape as ``data``) is true."""
        jj, ii = np.nonzero(mask)
        return self.cell_to_world(np.stack([ii, jj], axis=1))

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in m of the grid's extent in its own (origin-aligned) axes plus origin."""
        ox, oy, _ = self.origin
        return ox, oy, ox + self.width * self.resolution, oy + self.height * self.resolution

    def sub_origin(self, i0: int, j0: int) -> tuple[float, float, float]:
        """The origin of a sub-grid whose cell (0, 0) is this grid's cell (``i0``, ``j0``)."""
        ox, oy, yaw = self.origin
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = i0 * self.resolution, j0 * self.resolution
        return (ox + c * dx - s * dy, oy + s * dx + c * dy, yaw)

    def crop(self, i0: int, j0: int, i1: int, j1: int) -> Self:
        """Cells [i0, i1) x [j0, j1) (clipped to the grid) as a grid of the same type and frame (a copy)."""
        i0, j0 = max(0, i0), max(0, j0)
        i1, j1 = min(self.width, i1), min(self.height, j1)
        return type(self)(self.data[j0:j1, i0:i1].copy(), self.resolution, self.sub_origin(i0, j0), self.frame_id)


@dataclass
class GridMap(Grid):
    """A 2-D occupancy grid: the data of a ``nav_msgs/OccupancyGrid``.

    ``data``: int8, shape (height, width), row 0 = lowest y, -1 unknown, 0..100 occupancy (%).
    """

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.dtype != np.int8:
            if data.size and (data.min() < -1 or data.max() > 100):
                raise GridError("GridMap.data values must be -1 (unknown) or 0..100")
            self.data = data.astype(np.int8)
        super().__post_init__()

    @classmethod
    def empty(
        cls,
        width: int,
        height: int,
        resolution: float,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
        *,
        frame_id: str = "map",
        fill: int = UNKNOWN,
    ) -> GridMap:
        """A grid of ``width`` x ``height`` cells all set to ``fill`` (default unknown)."""
        return cls(np.full((height, width), fill, dtype=np.int8), resolution, origin, frame_id)

    def occupied_mask(self, threshold: int = 65) -> np.ndarray:
        """Cells whose occupancy is at least ``threshold`` percent (map_saver's default 65)."""
        return self.data >= threshold

    def free_mask(self, threshold: int = 25) -> np.ndarray:
        """Known cells whose occupancy is at most ``threshold`` percent (map_saver's default 25)."""
        return (self.data >= 0) & (self.data <= threshold)

    def unknown_mask(self) -> np.ndarray:
        """Cells never observed (-1)."""
        return self.data < 0

    def known_bounds(self, margin: float = 0.5) -> tuple[float, float, float, float] | None:
        """(xmin, ymin, xmax, ymax) in m around the known (not -1) cells plus ``margin``; None if none is known.

        SLAM maps are allocated far larger than what they have seen; plots crop to this.
        """
        jj, ii = np.nonzero(self.data >= 0)
        if len(ii) == 0:
            return None
        corners = self.cell_to_world(np.array([[ii.min(), jj.min()], [ii.max(), jj.max()]]))
        lo, hi = corners.min(axis=0) - margin, corners.max(axis=0) + margin
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    def crop_to_known(self, margin_cells: int = 3) -> GridMap:
        """The smallest sub-grid holding every known cell plus ``margin_cells`` of unknown (same frame).

        SLAM maps are allocated larger than what they have seen; planning and saving use this.
        """
        known = self.data >= 0
        jj = np.flatnonzero(known.any(axis=1))  # rows and columns holding a known cell
        if len(jj) == 0:
            return self
        ii = np.flatnonzero(known.any(axis=0))
        m = margin_cells
        return self.crop(int(ii[0]) - m, int(jj[0]) - m, int(ii[-1]) + m + 1, int(jj[-1]) + m + 1)

    def copy(self) -> GridMap:
        """A deep copy."""
        return GridMap(self.data.copy(), self.resolution, self.origin, self.frame_id)

    # --- messages -------------------------------------------------------------------------------

    def to_msg(self, stamp_ns: int = 0, *, map_load_time_ns: int | None = None) -> Any:
        """``nav_msgs/OccupancyGrid`` with this grid (row-major, row 0 first, as ROS stores it)."""
        info = msgs.MapMetaData(
            map_load_time=msgs.time_from_ns(stamp_ns if map_load_time_ns is None else map_load_time_ns),
            resolution=float(self.resolution),
            width=self.width,
            height=self.height,
            origin=msgs.pose_from_2d(*self.origin),
        )
        return msgs.OccupancyGrid(
            header=msgs.header(stamp_ns, self.frame_id),
            info=info,
            data=np.ascontiguousarray(self.data, dtype=np.int8).reshape(-1).copy(),
        )

    @classmethod
    def from_msg(cls, msg: Any) -> GridMap:
        """A ``GridMap`` from a ``nav_msgs/OccupancyGrid``."""
        w, h = int(msg.info.width), int(msg.info.height)
        data = np.asarray(msg.data, dtype=np.int8)
        if data.size != w * h:
            raise GridError(f"OccupancyGrid has {data.size} cells but info says width {w} x height {h} = {w * h}")
        return cls(
            data.reshape(h, w).copy(),
            float(msg.info.resolution),
            msgs.pose2d(msg.info.origin),
            str(msg.header.frame_id) or "map",
        )
