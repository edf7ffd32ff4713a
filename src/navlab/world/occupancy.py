"""The true 2-D occupancy of a world at lidar height, for map evaluation and tests.

A grid cell is occupied when a collision shape overlaps the cell's square anywhere between
``z_min`` and ``z_max`` (default 0.05–0.5 m above the floor). Grids follow map_server's layout:
``grid[i, j]`` is the cell whose centre is ``(x_min + (j + 0.5) res, y_min + (i + 0.5) res)``, so
row 0 is the lowest y.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from navlab.description import Shape, read_mesh
from navlab.geometry import matrix_from_pose6
from navlab.world.errors import WorldError
from navlab.world.model import WorldModel

_PRISM_SIDES = 32
_EPS = 1e-6  # m: overlaps thinner than this (rounding at cell borders) do not count


@dataclass(frozen=True)
class Footprint:
    """A shape's cover of the floor plane within the height band (world frame, metres).

    ``kind``: "polygon" (convex, ``points`` (k, 2)), "disc" (``points`` = [[cx, cy]], ``radius``) or
    "mesh" (``triangles`` (m, 3, 3) world-frame vertices, filled by surface and by even-odd inside test).
    """

    kind: str
    name: str
    points: np.ndarray
    radius: float = 0.0
    triangles: np.ndarray | None = None

    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of the footprint (m, world frame)."""
        if self.kind == "disc":
            (cx, cy), r = self.points[0], self.radius
            return (cx - r, cy - r, cx + r, cy + r)
        pts = self.triangles.reshape(-1, 3)[:, :2] if self.triangles is not None else self.points
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def _slab_points(verts: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """xy of (convex hull of ``verts``) ∩ {z0 <= z <= z1}: vertices inside plus segment crossings."""
    z = verts[:, 2]
    pts = [verts[(z >= z0) & (z <= z1), :2]]
    i, j = np.triu_indices(len(verts), 1)
    a, b = verts[i], verts[j]
    for plane in (z0, z1):
        da, db = a[:, 2] - plane, b[:, 2] - plane
        cross = da * db < 0
        if cross.any():
            t = (da[cross] / (da[cross] - db[cross]))[:, None]
            pts.append((a[cross] + t * (b[cross] - a[cross]))[:, :2])
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def _monotone_chain(pts: np.ndarray) -> list[int]:
    """Indices of the convex hull's corners of 2-D points sorted by x then y, counter-clockwise from the
    lowest-x point (Andrew's monotone chain; points on an edge left out). The few corners of a shape's slab
    need no Qhull (scipy.spatial alone costs 0.25 s to import at every start)."""
    xy = pts.tolist()

    def half(order: range) -> list[int]:
        out: list[int] = []
        for k in order:
            while len(out) >= 2:
                (ax, ay), (bx, by), (cx, cy) = xy[out[-2]], xy[out[-1]], xy[k]
                if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0:
                    break
                out.pop()
            out.append(k)
        return out

    lower, upper = half(range(len(xy))), half(range(len(xy) - 1, -1, -1))
    return lower[:-1] + upper[:-1]


def _hull2d(pts: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise; degenerate sets → their extreme segment/point."""
    if len(pts) == 0:
        return pts
    pts = np.unique(np.round(pts, 12), axis=0)  # sorted by x, then y
    if len(pts) >= 3:
        hull = _monotone_chain(pts)
        if len(hull) >= 3:
            return pts[hull]
    if len(pts) == 1:
        return pts
    d = pts - pts.mean(axis=0)
    axis = np.linalg.svd(d, full_matrices=False)[2][0]
    s = d @ axis
    return pts[[int(np.argmin(s)), int(np.argmax(s))]]


def _prism(radius: float, length: float) -> np.ndarray:
    """Vertices of a prism circumscribing a z-axis cylinder."""
    r = radius / math.cos(math.pi / _PRISM_SIDES)
    ang = np.arange(_PRISM_SIDES) * 2 * math.pi / _PRISM_SIDES
    ring = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    return np.concatenate(
        [np.c_[ring, np.full(_PRISM_SIDES, -length / 2)], np.c_[ring, np.full(_PRISM_SIDES, length / 2)]]
    )


def _footprint(shape: Shape, world_T_shape: np.ndarray, name: str, z0: float, z1: float) -> Footprint | None:
    g = shape.geometry
    rot, pos = world_T_shape[:3, :3], world_T_shape[:3, 3]
    if g.kind == "sphere":
        r = g.size[0]
        d = max(z0 - pos[2], pos[2] - z1, 0.0)
        return Footprint("disc", name, pos[None, :2].copy(), math.sqrt(r * r - d * d)) if d < r else None
    if g.kind == "cylinder" and abs(abs(rot[2, 2]) - 1.0) < 1e-9:  # upright: exact disc
        r, half = g.size[0], g.size[1] / 2
        if pos[2] + half < z0 or pos[2] - half > z1:
            return None
        return Footprint("disc", name, pos[None, :2].copy(), r)
    if g.kind in ("box", "cylinder"):
        if g.kind == "box":
            sx, sy, sz = (v / 2 for v in g.size)
            local = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)])
        else:
            local = _prism(g.size[0], g.size[1])
        pts = _hull2d(_slab_points(local @ rot.T + pos, z0, z1))
        return Footprint("polygon", name, pts) if len(pts) else None
    if g.kind == "mesh":
        if g.mesh_path is None:
            return None
        verts, faces = read_mesh(g.mesh_path)
        verts = (verts * np.asarray(g.mesh_scale)) @ rot.T + pos
        tris = verts[faces]
        keep = (tris[:, :, 2].max(axis=1) >= z0) & (tris[:, :, 2].min(axis=1) <= z1)
        return Footprint("mesh", name, np.zeros((0, 2)), triangles=tris[keep]) if keep.any() else None
    raise WorldError(f"{name}: unknown geometry kind {g.kind!r}")


def shape_footprints(
    world: WorldModel, *, z_min: float = 0.05, z_max: float = 0.5, static_only: bool = False
) -> list[Footprint]:
    """Footprints of every collision shape (models at their initial poses) in the height band."""
    out = []
    for model in world.models:
        if static_only and not model.static:
            continue
        world_T_model = matrix_from_pose6(model.pose)
        for link in model.links:
            model_T_link = model.link_origins[link.name].matrix() if link.name in model.link_origins else np.eye(4)
            for k, shape in enumerate(link.collisions):
                m = world_T_model @ model_T_link @ shape.origin.matrix()
                fp = _footprint(shape, m, f"{model.name}::{link.name}::{shape.name or k}", z_min, z_max)
                if fp is not None:
                    out.append(fp)
    return out


def extents(
    world: WorldModel, *, z_min: float = 0.05, z_max: float = 0.5, static_only: bool = False
) -> tuple[float, float, float, float] | None:
    """(x_min, y_min, x_max, y_max) of every collision shape in the height band; None if there is none.

    Pass ``z_min=-math.inf, z_max=math.inf`` for the full extents regardless of height.
    """
    boxes = [fp.bounds() for fp in shape_footprints(world, z_min=z_min, z_max=z_max, static_only=static_only)]
    if not boxes:
        return None
    arr = np.array(boxes)
    return (float(arr[:, 0].min()), float(arr[:, 1].min()), float(arr[:, 2].max()), float(arr[:, 3].max()))


class _Grid:
    def __init__(self, resolution: float, bounds: tuple[float, float, float, float]) -> None:
        self.res = resolution
        self.x0, self.y0, x1, y1 = bounds
        self.nx = round((x1 - self.x0) / resolution)
        self.ny = round((y1 - self.y0) / resolution)
        self.cells = np.zeros((self.ny, self.nx), dtype=bool)

    def window(self, lo: np.ndarray, hi: np.ndarray) -> tuple[slice, slice, np.ndarray, np.ndarray] | None:
        """Cell index ranges touching the box [lo, hi] and their centre coordinates."""
        j0 = max(math.floor((lo[0] - self.x0) / self.res) - 1, 0)
        j1 = min(math.ceil((hi[0] - self.x0) / self.res) + 1, self.nx)
        i0 = max(math.floor((lo[1] - self.y0) / self.res) - 1, 0)
        i1 = min(math.ceil((hi[1] - self.y0) / self.res) + 1, self.ny)
        if j0 >= j1 or i0 >= i1:
            return None
        cx = self.x0 + (np.arange(j0, j1) + 0.5) * self.res
        cy = self.y0 + (np.arange(i0, i1) + 0.5) * self.res
        return slice(i0, i1), slice(j0, j1), cx[None, :], cy[:, None]

    def polygon(self, pts: np.ndarray, strict: bool = True) -> None:
        """Mark cells whose square overlaps the convex polygon (separating-axis test)."""
        win = self.window(pts.min(axis=0), pts.max(axis=0))
        if win is None:
            return
        si, sj, cx, cy = win
        h, eps = self.res / 2, (_EPS if strict else -_EPS)
        ok = (
            (cx + h > pts[:, 0].min() + eps)
            & (cx - h < pts[:, 0].max() - eps)
            & (cy + h > pts[:, 1].min() + eps)
            & (cy - h < pts[:, 1].max() - eps)
        )
        edges = np.roll(pts, -1, axis=0) - pts
        for e in edges[np.linalg.norm(edges, axis=1) > 1e-12]:
            n = np.array([-e[1], e[0]]) / np.linalg.norm(e)
            proj = pts @ n
            c = cx * n[0] + cy * n[1]
            r = h * (abs(n[0]) + abs(n[1]))
            ok &= (c + r > proj.min() + eps) & (c - r < proj.max() - eps)
        self.cells[si, sj] |= ok

    def disc(self, centre: np.ndarray, radius: float) -> None:
        """Mark cells whose square overlaps the disc."""
        win = self.window(centre - radius, centre + radius)
        if win is None:
            return
        si, sj, cx, cy = win
        h = self.res / 2
        dx = np.maximum(np.abs(cx - centre[0]) - h, 0.0)
        dy = np.maximum(np.abs(cy - centre[1]) - h, 0.0)
        self.cells[si, sj] |= dx * dx + dy * dy < radius * radius - _EPS

    def surface(self, tris: np.ndarray, z0: float, z1: float, chunk: int = 200_000) -> None:
        """Mark cells touched by any triangle's part inside the band (vectorised separating-axis test).

        Each triangle ∩ slab is the hull of up to 9 candidate points (3 vertices, 6 edge/plane
        crossings); its separating axes are among x, y and the normals of candidate-point pairs.
        """
        z = tris[:, :, 2]
        cand = [tris[:, :, :2]]
        valid = [(z >= z0) & (z <= z1)]
        for a, b in ((0, 1), (1, 2), (2, 0)):
            for plane in (z0, z1):
                da, db = z[:, a] - plane, z[:, b] - plane
                cross = da * db < 0
                t = np.where(cross, da / np.where(cross, da - db, 1.0), 0.0)[:, None]
                cand.append((tris[:, a, :2] + t * (tris[:, b, :2] - tris[:, a, :2]))[:, None, :])
                valid.append(cross[:, None])
        pts = np.concatenate(cand, axis=1)  # (T, 9, 2)
        ok = np.concatenate(valid, axis=1)  # (T, 9)
        keep = ok.any(axis=1)
        pts, ok = pts[keep], ok[keep]
        if not len(pts):
            return
        big = np.where(ok[..., None], pts, np.nan)
        lo, hi = np.nanmin(big, axis=1), np.nanmax(big, axis=1)
        j0 = np.clip(np.floor((lo[:, 0] - self.x0) / self.res).astype(int), 0, self.nx)
        j1 = np.clip(np.floor((hi[:, 0] - self.x0) / self.res).astype(int) + 1, 0, self.nx)
        i0 = np.clip(np.floor((lo[:, 1] - self.y0) / self.res).astype(int), 0, self.ny)
        i1 = np.clip(np.floor((hi[:, 1] - self.y0) / self.res).astype(int) + 1, 0, self.ny)
        width = np.maximum(j1 - j0, 0)
        counts = width * np.maximum(i1 - i0, 0)
        # axes: normals of every candidate-point pair of a triangle (invalid pairs get a zero axis)
        ia, ib = np.triu_indices(9, 1)
        d = pts[:, ib] - pts[:, ia]
        axes = np.stack([-d[..., 1], d[..., 0]], axis=-1)
        length = np.linalg.norm(axes, axis=-1)
        good = ok[:, ia] & ok[:, ib] & (length > 1e-12)
        axes = np.where(good[..., None], axes / np.where(length > 1e-12, length, 1.0)[..., None], 0.0)
        proj = np.einsum("tak,tpk->tap", axes, pts)  # (T, A, 9)
        pmin = np.where(ok[:, None, :], proj, np.inf).min(axis=2)
        pmax = np.where(ok[:, None, :], proj, -np.inf).max(axis=2)
        h, eps = self.res / 2, _EPS
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        total = int(counts.sum())
        for s0 in range(0, total, chunk):
            k = np.arange(s0, min(s0 + chunk, total))
            t = np.searchsorted(starts, k, side="right") - 1
            local = k - starts[t]
            i = i0[t] + local // np.maximum(width[t], 1)
            j = j0[t] + local % np.maximum(width[t], 1)
            cx = self.x0 + (j + 0.5) * self.res
            cy = self.y0 + (i + 0.5) * self.res
            hit = (
                (cx + h >= lo[t, 0] - eps)
                & (cx - h <= hi[t, 0] + eps)
                & (cy + h >= lo[t, 1] - eps)
                & (cy - h <= hi[t, 1] + eps)
            )
            ax = axes[t]  # (P, A, 2)
            c = ax[..., 0] * cx[:, None] + ax[..., 1] * cy[:, None]
            r = h * (np.abs(ax[..., 0]) + np.abs(ax[..., 1]))
            sep = (c + r < pmin[t] - eps) | (c - r > pmax[t] + eps)
            hit &= ~(sep & good[t]).any(axis=1)
            self.cells[i[hit], j[hit]] = True

    def mesh(self, tris: np.ndarray, z0: float, z1: float) -> None:
        """Mark cells touched by the mesh surface in the band, and cells inside its closed slices."""
        self.surface(tris, z0, z1)
        lo, hi = tris.reshape(-1, 3).min(axis=0), tris.reshape(-1, 3).max(axis=0)
        win = self.window(lo[:2], hi[:2])
        if win is None:
            return
        si, sj, cx, cy = win
        levels = np.linspace(max(z0, lo[2]), min(z1, hi[2]), max(2, math.ceil((z1 - z0) / self.res) + 1))
        for zl in levels:
            segs = _slice(tris, zl)
            if len(segs) == 0:
                continue
            inside = np.zeros((cy.shape[0], cx.shape[1]), dtype=bool)
            for chunk in np.array_split(segs, max(1, len(segs) // 256)):
                (ax, ay), (bx, by) = chunk[:, 0].T, chunk[:, 1].T
                spans = (ay[None, None, :] <= cy[..., None]) != (by[None, None, :] <= cy[..., None])
                with np.errstate(divide="ignore", invalid="ignore"):
                    xc = ax + (cy[..., None] - ay) * (bx - ax) / (by - ay)
                inside ^= (np.count_nonzero(spans & (xc > cx[..., None]), axis=-1) % 2).astype(bool)
            self.cells[si, sj] |= inside


def _slice(tris: np.ndarray, z: float) -> np.ndarray:
    """Segments (s, 2, 2) where the plane at height z cuts the triangles."""
    d = tris[:, :, 2] - z
    out = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        cross = (d[:, a] * d[:, b]) < 0
        t = np.where(cross, d[:, a] / np.where(cross, d[:, a] - d[:, b], 1.0), 0.0)
        out.append((cross, tris[:, a, :2] + t[:, None] * (tris[:, b, :2] - tris[:, a, :2])))
    mask = np.stack([c for c, _ in out], axis=1)
    pts = np.stack([p for _, p in out], axis=1)
    two = mask.sum(axis=1) == 2
    segs = [pts[k][mask[k]] for k in np.nonzero(two)[0]]
    return np.array(segs).reshape(-1, 2, 2)


def occupancy(
    world: WorldModel,
    resolution: float,
    bounds: tuple[float, float, float, float],
    *,
    z_min: float = 0.05,
    z_max: float = 0.5,
    static_only: bool = False,
) -> np.ndarray:
    """Boolean grid (ny, nx) of the world's true occupancy between ``z_min`` and ``z_max`` (m).

    ``bounds`` = (x_min, y_min, x_max, y_max) in the world frame (m); ``resolution`` in m/cell. Models
    are taken at their initial poses; ``static_only`` skips dynamic models.
    """
    if not resolution > 0:
        raise WorldError(f"occupancy: resolution must be > 0 m, got {resolution}")
    x0, y0, x1, y1 = bounds
    if not (x1 > x0 and y1 > y0):
        raise WorldError(f"occupancy: bounds must be (x_min, y_min, x_max, y_max) with max > min, got {bounds}")
    if not z_max > z_min:
        raise WorldError(f"occupancy: z_max must exceed z_min, got {z_min}..{z_max}")
    grid = _Grid(resolution, bounds)
    for fp in shape_footprints(world, z_min=z_min, z_max=z_max, static_only=static_only):
        if fp.kind == "disc":
            grid.disc(fp.points[0], fp.radius)
        elif fp.kind == "polygon":
            grid.polygon(fp.points if len(fp.points) > 1 else np.repeat(fp.points, 2, axis=0))
        elif fp.triangles is not None:
            grid.mesh(fp.triangles, z_min, z_max)
    return grid.cells
