"""A laser scan's beams and points in the laser frame, worked out once per message and shared by the costmaps.

move_base's global and local costmaps both read the newest ``LaserScan``. The beams' cosines and sines are
kept while the scan's geometry (beam count, ``angle_min``, ``angle_increment``) stays the same; the obstacle
layers take them with the ranges and do the rest in one compiled call (``ObstacleLayer.add_ranges``). Other
scan layers get the ray endpoints (m, laser frame: x along the beam at ``angle_min``), worked out once per
message: the ranges' validity, the clearing distance of rays without a return and the points.
"""

from __future__ import annotations

from typing import Any

import numpy as np


class ScanPoints:
    """Laser-frame endpoints of the last scan asked about (see the module docstring)."""

    def __init__(self) -> None:
        self._last: tuple[Any, float, tuple[np.ndarray, np.ndarray]] | None = None
        self._trig: tuple[tuple[int, float, float], np.ndarray, np.ndarray] | None = None

    def beams(self, msg: Any) -> tuple[np.ndarray, np.ndarray]:
        """(cosines, sines) of ``msg``'s beam angles (``angle_min`` + k ``angle_increment``), kept while the scan's
        geometry stays the same."""
        geometry = (len(msg.ranges), float(msg.angle_min), float(msg.angle_increment))
        if self._trig is None or self._trig[0] != geometry:
            a = geometry[1] + geometry[2] * np.arange(geometry[0])
            self._trig = (geometry, np.cos(a), np.sin(a))
        return self._trig[1], self._trig[2]

    def points(self, msg: Any, clear_to: float) -> tuple[np.ndarray, np.ndarray]:
        """(endpoints (N, 2) m in the laser frame, valid (N,)) of ``msg``'s rays that have an end: real returns
        (``valid``: finite, in [range_min, range_max)) at their range, rays without one (inf, or at/over
        range_max) at ``clear_to`` m (they only clear); NaN readings are left out."""
        last = self._last
        if last is not None and last[0] is msg and last[1] == clear_to:
            return last[2]
        r = np.asarray(msg.ranges, dtype=np.float64)
        cos, sin = self.beams(msg)
        valid = np.isfinite(r) & (r >= float(msg.range_min)) & (r < float(msg.range_max))
        dist = np.where(valid, r, np.where(np.isnan(r), np.nan, clear_to))
        keep = np.isfinite(dist)
        d = dist[keep]
        out = (np.stack([d * cos[keep], d * sin[keep]], axis=1), valid[keep])
        self._last = (msg, clear_to, out)
        return out
