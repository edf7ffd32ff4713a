"""Seeded randomized property test: occupancy agrees with dense point sampling of random shapes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from navlab.description import Geometry, Link, Origin, Shape
from navlab.geometry import matrix_from_pose6
from navlab.world import ModelSpec, WorldModel, occupancy

RES, BOUNDS, Z0, Z1 = 0.05, (-2.0, -2.0, 2.0, 2.0), 0.05, 0.5


def _random_shape(rng: np.random.Generator, kind: str) -> tuple[Geometry, tuple[float, ...]]:
    size = {
        "box": tuple(rng.uniform(0.1, 0.8, 3)),
        "cylinder": (rng.uniform(0.05, 0.4), rng.uniform(0.1, 0.8)),
        "sphere": (rng.uniform(0.05, 0.4),),
    }[kind]
    rpy = tuple(rng.uniform(-np.pi, np.pi, 3)) if rng.random() < 0.5 else (0.0, 0.0, rng.uniform(-np.pi, np.pi))
    pose = (*rng.uniform(-1.0, 1.0, 2), rng.uniform(0.1, 0.45), *rpy)  # centre inside the band
    return Geometry(kind, size=size), pose


def _inside(geom: Geometry, p: np.ndarray) -> np.ndarray:
    """Points (n, 3) in the shape's own frame → inside mask."""
    if geom.kind == "box":
        return (np.abs(p) <= np.array(geom.size) / 2).all(axis=1)
    if geom.kind == "cylinder":
        r, length = geom.size
        return (np.hypot(p[:, 0], p[:, 1]) <= r) & (np.abs(p[:, 2]) <= length / 2)
    return np.linalg.norm(p, axis=1) <= geom.size[0]


@pytest.mark.parametrize("seed", range(12))
def test_occupancy_matches_point_sampling(seed):
    rng = np.random.default_rng(seed)
    geom, pose = _random_shape(rng, ("box", "cylinder", "sphere")[seed % 3])
    model = ModelSpec(
        name="s", pose=pose, static=True, links=[Link(name="l", collisions=[Shape(geometry=geom, origin=Origin())])]
    )
    grid = occupancy(WorldModel(name="w", models=[model]), RES, BOUNDS, z_min=Z0, z_max=Z1)
    # sample the band densely, keep points inside the shape
    step, reach = 0.01, float(np.linalg.norm(geom.size))  # reach bounds the shape's extent from its centre
    xs = np.arange(pose[0] - reach, pose[0] + reach, step)
    ys = np.arange(pose[1] - reach, pose[1] + reach, step)
    zs = np.linspace(Z0, Z1, 16)
    pts = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    m = matrix_from_pose6(pose)
    local = (pts - m[:3, 3]) @ m[:3, :3]
    hits = pts[_inside(geom, local)]
    cols = ((hits[:, 0] - BOUNDS[0]) // RES).astype(int)
    rows = ((hits[:, 1] - BOUNDS[1]) // RES).astype(int)
    # (a) every cell holding a point of the shape is occupied
    assert grid[rows, cols].all()
    # (b) every occupied cell lies next to the shape (within a cell diagonal plus the sampling step)
    occ = np.argwhere(grid)
    assert len(hits) > 100  # every shape crosses the band
    centres = np.c_[BOUNDS[0] + (occ[:, 1] + 0.5) * RES, BOUNDS[1] + (occ[:, 0] + 0.5) * RES]
    dist, _ = cKDTree(hits[:, :2]).query(centres)
    assert dist.max() <= RES * np.sqrt(2) / 2 + 2 * step
