"""Issue 13 item 11: a world's concave meshes are decomposed once, in parallel, into a cache keyed by
their content (fixture: navlab.sim.decompose_bench.furnished_world)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from navlab.sim import decompose
from navlab.sim.decompose_bench import furnished_world
from navlab.world import load_world


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))


def _inside_any(parts, point: np.ndarray) -> bool:
    from scipy.spatial import ConvexHull

    for verts, _ in parts:
        eq = ConvexHull(verts).equations
        if (eq[:, :3] @ point + eq[:, 3] <= 1e-6).all():
            return True
    return False


def test_world_meshes_decomposed_in_parallel_once_and_cached_by_content(tmp_path):
    world_file = furnished_world(tmp_path / "w", n=2, seed=1, kinds=("counter",))  # two L-shaped counters
    world = load_world(world_file)
    meshes = decompose.concave_meshes(world)
    assert len(meshes) == 2
    assert decompose.decompose_world(world, workers=2, progress=False) == 2
    assert decompose.decompose_world(world, workers=2, progress=False) == 0  # all cached now
    # the cache is keyed by content: the same mesh under another name and folder is not decomposed again
    copy = tmp_path / "elsewhere" / "renamed.stl"
    copy.parent.mkdir()
    shutil.copy(meshes[0][0], copy)
    assert decompose.decompose_meshes([(copy, meshes[0][1])], workers=1, progress=False) == 0
    # bounded effort still leaves the L's notch free: its inner corner region is in no convex part
    counter = decompose.convex_parts(*meshes[0])
    verts = np.vstack([v for v, _ in counter])
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    notch = np.array([hi[0] - 0.05, hi[1] - 0.05, 0.3])  # far corner of the L's bounding box, at 0.3 m
    assert not _inside_any(counter, notch)
    assert len(counter) >= 2 and lo[2] == pytest.approx(0.0, abs=0.05)
