"""Convex decomposition of concave collision meshes (CoACD), cached on disk.

MuJoCo collides a mesh as its convex hull, so a concave world mesh (an L-shaped counter, a U-shaped
shelf) would fill its own notches. The simulator collides such meshes as the convex parts computed
here, while lidar rays still hit the original triangles.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from navlab.io.files import atomic_path
from navlab.sim.errors import SimError

#: CoACD's concavity threshold (smaller: more, tighter parts)
THRESHOLD = 0.05
_VERSION = "1"  # bump when the way parts are computed changes (invalidates the cache)


def _cache_dir() -> Path:
    from navlab.description.meshes import cache_dir

    return cache_dir().parent / "convex"


def weld(verts: np.ndarray, faces: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Merge duplicate vertices (STL stores each triangle's own) so the mesh is connected."""
    key = np.round(verts / tol).astype(np.int64) if tol > 0 else verts
    uniq, index, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    del uniq
    return verts[index], inverse.reshape(-1)[faces]


def convex_parts(
    path: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *, threshold: float = THRESHOLD,
    seed: int = 0,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Convex parts (vertices (n, 3) in m, triangles (m, 3)) of the mesh file scaled by ``scale``.

    Results are cached under the navlab cache directory, keyed by the file's bytes and the options.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise SimError(f"mesh {path}: cannot read it for convex decomposition ({exc})") from None
    digest = hashlib.sha256(data + repr((tuple(scale), threshold, seed, _VERSION)).encode()).hexdigest()[:32]
    cached = _cache_dir() / f"{digest}.npz"
    if cached.is_file():
        with np.load(cached) as z:
            return [(z[f"v{i}"], z[f"f{i}"]) for i in range(int(z["n"]))]
    from navlab.description.meshes import read_mesh

    verts, faces = read_mesh(Path(path))
    verts, faces = weld(verts * np.asarray(scale, dtype=float), faces)
    try:
        import coacd
    except ImportError:
        raise SimError(f"mesh {path} is concave and decomposing it needs the coacd package") from None
    coacd.set_log_level("error")
    result = coacd.run_coacd(coacd.Mesh(verts, faces), threshold=threshold, seed=seed)
    parts = [(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int32)) for v, f in result]
    if not parts:
        raise SimError(f"mesh {path}: convex decomposition produced no parts")
    arrays: dict[str, np.ndarray] = {"n": np.array(len(parts))}
    for i, (v, f) in enumerate(parts):
        arrays[f"v{i}"], arrays[f"f{i}"] = v, f
    with atomic_path(cached, suffix=".npz") as tmp, tmp.open("wb") as fh:
        np.savez(fh, allow_pickle=False, **arrays)  # numeric arrays only
    return parts
