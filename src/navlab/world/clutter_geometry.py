"""Exact clearances in a clutter world: the distance from points to the nearest cylinder or wall surface, and
whether straight segments keep a disc of a given radius clear of them (the clutter generator's geometry)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

if TYPE_CHECKING:
    from navlab.world.clutter import Box


class Clearance:
    """Exact distance to the nearest obstacle surface: cylinders (centres ``cylinders``, radius ``cylinder_radius``
    m) through a k-d tree, walls as boxes."""

    def __init__(self, cylinders: np.ndarray, walls: Sequence[Box], cylinder_radius: float) -> None:
        self.cylinder_radius = cylinder_radius
        self.tree = cKDTree(cylinders) if len(cylinders) else None
        self.boxes = np.array([[w.x, w.y, w.sx / 2, w.sy / 2] for w in walls]).reshape(-1, 4)

    def __call__(self, pts: np.ndarray) -> np.ndarray:
        d = np.full(len(pts), np.inf)
        if self.tree is not None:
            d = self.tree.query(pts)[0] - self.cylinder_radius
        for cx, cy, hx, hy in self.boxes:
            dx = np.maximum(np.abs(pts[:, 0] - cx) - hx, 0.0)
            dy = np.maximum(np.abs(pts[:, 1] - cy) - hy, 0.0)
            d = np.minimum(d, np.hypot(dx, dy))
        return np.maximum(d, 0.0)

    def segments_clear(self, a: np.ndarray, ends: np.ndarray, radius: float) -> np.ndarray:
        """Exact test, for each segment ``a`` -> ``ends[k]``, that every point has clearance >= ``radius``."""
        ok = np.ones(len(ends), dtype=bool)
        if self.tree is not None:
            ok &= point_segment_distance(self.tree.data, a, ends).min(axis=1) >= radius + self.cylinder_radius
        for cx, cy, hx, hy in self.boxes:  # the box grown by a disc of radius: two rectangles, four discs
            lo, hi = np.array([cx - hx, cy - hy]), np.array([cx + hx, cy + hy])
            for grow in (np.array([radius, 0.0]), np.array([0.0, radius])):
                ok &= ~segment_hits_rect(a, ends, lo - grow, hi + grow)
            corners = np.array([[lo[0], lo[1]], [lo[0], hi[1]], [hi[0], lo[1]], [hi[0], hi[1]]])
            ok &= point_segment_distance(corners, a, ends).min(axis=1) >= radius
        return ok


def point_segment_distance(points: np.ndarray, a: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(n, k) distances from k points to the n segments ``a`` -> ``ends[n]``."""
    ab = ends - a  # (n, 2)
    ap = points - a  # (k, 2)
    denom = np.maximum((ab * ab).sum(axis=1), 1e-18)[:, None]
    t = np.clip((ab @ ap.T) / denom, 0.0, 1.0)  # (n, k)
    dx = ap[None, :, 0] - t * ab[:, None, 0]
    dy = ap[None, :, 1] - t * ab[:, None, 1]
    return np.hypot(dx, dy)


def segment_hits_rect(a: np.ndarray, ends: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether each segment ``a`` -> ``ends[n]`` meets the open rectangle (lo, hi) (Liang-Barsky clip)."""
    d = ends - a
    t0, t1 = np.zeros(len(ends)), np.ones(len(ends))
    hit = np.ones(len(ends), dtype=bool)
    for ax in (0, 1):
        p = d[:, ax]
        flat = np.abs(p) < 1e-15
        hit &= ~(flat & ((a[ax] <= lo[ax]) | (a[ax] >= hi[ax])))
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo[ax] - a[ax]) / p, (hi[ax] - a[ax]) / p
        t0 = np.where(flat, t0, np.maximum(t0, np.minimum(ta, tb)))
        t1 = np.where(flat, t1, np.minimum(t1, np.maximum(ta, tb)))
    return hit & (t0 < t1 - 1e-12)
