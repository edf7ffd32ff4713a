"""Occupancy grids: ``GridMap`` (the data of a ``nav_msgs/OccupancyGrid``) and cell <-> world conversions.

Conventions follow ROS: ``data[j, i]`` is the cell in column ``i`` (x) and row ``j`` (y), row 0 is the
lowest y, values are -1 (unknown) or 0..100 (occupancy probability in percent). ``origin`` is the pose
(x, y, yaw) in the map frame of the lower-left corner of cell (0, 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from navlab import msgs
from navlab.mapping.errors import MappingError

UNKNOWN = -1
FREE = 0
OCCUPIED = 100


@dataclass
class GridMap:
    """A 2D occupancy grid in ``frame_id``.

    ``data``: int8, shape (height, width), row 0 = lowest y, -1 unknown, 0..100 occupancy (%).
    ``resolution``: m/cell. ``origin``: (x m, y m, yaw rad) of the lower-left corner of cell (0, 0).
    """

    data: np.ndarray
    resolution: float
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frame_id: str = "map"

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.ndim != 2:
            raise MappingError(f"GridMap.data must be 2-D (height, width), got shape {data.shape}")
        if data.dtype != np.int8:
            if data.size and (data.min() < -1 or data.max() > 100):
                raise MappingError("GridMap.data values must be -1 (unknown) or 0..100")
            data = data.astype(np.int8)
        self.data = data
        if not (self.resolution > 0 and math.isfinite(self.resolution)):
            raise MappingError(f"GridMap.resolution must be a positive number of m/cell, got {self.resolution}")
        if len(self.origin) != 3:
            raise MappingError(f"GridMap.origin must be (x, y, yaw), got {self.origin!r}")
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

    def value_at(self, xy: np.ndarray) -> np.ndarray:
        """Cell values (int8, N) at map-frame points ``xy`` (N, 2); points outside the grid read -1."""
        ij = self.world_to_cell(xy)
        out = np.full(len(ij), UNKNOWN, dtype=np.int8)
        ok = self.in_bounds(ij)
        out[ok] = self.data[ij[ok, 1], ij[ok, 0]]
        return out

    def occupied_mask(self, threshold: int = 65) -> np.ndarray:
        """Cells whose occupancy is at least ``threshold`` percent (map_saver's default 65)."""
        return self.data >= threshold

    def free_mask(self, threshold: int = 25) -> np.ndarray:
        """Known cells whose occupancy is at most ``threshold`` percent (map_saver's default 25)."""
        return (self.data >= 0) & (self.data <= threshold)

    def unknown_mask(self) -> np.ndarray:
        """Cells never observed (-1)."""
        return self.data < 0

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in m of the grid's extent in its own (origin-aligned) axes plus origin."""
        ox, oy, _ = self.origin
        return ox, oy, ox + self.width * self.resolution, oy + self.height * self.resolution

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
            raise MappingError(f"OccupancyGrid has {data.size} cells but info says width {w} x height {h} = {w * h}")
        return cls(
            data.reshape(h, w).copy(),
            float(msg.info.resolution),
            msgs.pose2d(msg.info.origin),
            str(msg.header.frame_id) or "map",
        )
