"""Convex decomposition of concave collision meshes (CoACD), cached on disk by content.

MuJoCo collides a mesh as its convex hull, so a concave world mesh (an L-shaped counter, a U-shaped
shelf) would fill its own notches. The simulator collides such meshes as the convex parts computed
here, while lidar rays still hit the original triangles.

A furnished world has dozens of concave meshes, and CoACD at its default effort takes minutes per
shelf, so the first load of such a world was a long wait. Here:

- the effort is bounded (``EFFORTS["bounded"]``: a coarser voxel pre-pass and a shallower tree
  search than CoACD's defaults; about 5x less CPU per mesh, the notches stay free;
  ``NAVLAB_DECOMPOSE_EFFORT=full`` restores CoACD's defaults);
- :func:`decompose_world` decomposes every uncached concave mesh of a world before the scene is
  built, in parallel worker processes, with a progress bar and its time estimate (tqdm's, on a
  terminal);
- results are cached under the navlab cache directory keyed by the mesh file's bytes, the scale
  and the options (not the path or time stamps), so later loads, and copies of the same mesh, cost
  nothing.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from navlab.io.files import atomic_path
from navlab.sim.errors import SimError
from navlab.world.model import WorldModel

#: CoACD's concavity threshold (smaller: more, tighter parts)
THRESHOLD = 0.05
#: CoACD options per effort level: "full" is CoACD's defaults (navlab before issue 13), "bounded" the default
EFFORTS: dict[str, dict[str, Any]] = {
    "full": {},
    "bounded": {"preprocess_resolution": 30, "resolution": 500, "mcts_nodes": 6, "mcts_iterations": 20,
                "mcts_max_depth": 2},
}
DEFAULT_EFFORT = "bounded"  # unless $NAVLAB_DECOMPOSE_EFFORT names another of EFFORTS
_VERSION = "1"  # bump when the way parts are computed changes (invalidates the cache)

Parts = list[tuple[np.ndarray, np.ndarray]]
MeshKey = tuple[Path, tuple[float, float, float]]


def _cache_dir() -> Path:
    from navlab.description.meshes import cache_dir

    return cache_dir().parent / "convex"


def weld(verts: np.ndarray, faces: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Merge duplicate vertices (STL stores each triangle's own) so the mesh is connected."""
    key = np.round(verts / tol).astype(np.int64) if tol > 0 else verts
    uniq, index, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    del uniq
    return verts[index], inverse.reshape(-1)[faces]


def default_effort() -> str:
    """``$NAVLAB_DECOMPOSE_EFFORT`` (``bounded`` or ``full``), else :data:`DEFAULT_EFFORT`."""
    return os.environ.get("NAVLAB_DECOMPOSE_EFFORT", "").strip() or DEFAULT_EFFORT


def _options(effort: str, threshold: float) -> dict[str, Any]:
    if effort not in EFFORTS:
        raise SimError(f"convex decomposition effort {effort!r}: expected one of {', '.join(EFFORTS)}")
    return {"threshold": threshold, **EFFORTS[effort]}


def cache_file(path: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *, threshold: float = THRESHOLD,
               seed: int = 0, effort: str | None = None) -> Path:
    """Where the parts of this mesh (by content), scale and options are cached (``effort`` None:
    :func:`default_effort`)."""
    effort = effort or default_effort()
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise SimError(f"mesh {path}: cannot read it for convex decomposition ({exc})") from None
    opts = sorted(_options(effort, threshold).items())
    key = repr((tuple(float(s) for s in scale), opts, seed, _VERSION))
    # the "full" effort keeps the key of navlab's first cache (threshold, seed) so its entries stay valid
    if effort == "full":
        key = repr((tuple(scale), threshold, seed, _VERSION))
    digest = hashlib.sha256(data + key.encode()).hexdigest()[:32]
    return _cache_dir() / f"{digest}.npz"


def _load(cached: Path) -> Parts:
    with np.load(cached) as z:
        return [(z[f"v{i}"], z[f"f{i}"]) for i in range(int(z["n"]))]


def _compute(path: Path, scale: tuple[float, float, float], threshold: float, seed: int, effort: str) -> Parts:
    from navlab.description.meshes import read_mesh

    verts, faces = read_mesh(Path(path))
    verts, faces = weld(verts * np.asarray(scale, dtype=float), faces)
    try:
        import coacd
    except ImportError:
        raise SimError(f"mesh {path} is concave and decomposing it needs the coacd package") from None
    coacd.set_log_level("error")
    result = coacd.run_coacd(coacd.Mesh(verts, faces), seed=seed, **_options(effort, threshold))
    parts = [(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int32)) for v, f in result]
    if not parts:
        raise SimError(f"mesh {path}: convex decomposition produced no parts")
    return parts


def _store(cached: Path, parts: Parts) -> None:
    arrays: dict[str, np.ndarray] = {"n": np.array(len(parts))}
    for i, (v, f) in enumerate(parts):
        arrays[f"v{i}"], arrays[f"f{i}"] = v, f
    with atomic_path(cached, suffix=".npz") as tmp, tmp.open("wb") as fh:
        np.savez(fh, allow_pickle=False, **arrays)  # numeric arrays only


def convex_parts(
    path: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *, threshold: float = THRESHOLD,
    seed: int = 0, effort: str | None = None,
) -> Parts:
    """Convex parts (vertices (n, 3) in m, triangles (m, 3)) of the mesh file scaled by ``scale``.

    Results are cached under the navlab cache directory, keyed by the file's bytes and the options.
    """
    effort = effort or default_effort()
    cached = cache_file(path, scale, threshold=threshold, seed=seed, effort=effort)
    if cached.is_file():
        return _load(cached)
    parts = _compute(Path(path), scale, threshold, seed, effort)
    _store(cached, parts)
    return parts


def _worker(path: str, scale: tuple[float, float, float], threshold: float, seed: int, effort: str) -> int:
    """Decompose one mesh into the cache (in a worker process); returns the number of parts."""
    return len(convex_parts(Path(path), scale, threshold=threshold, seed=seed, effort=effort))


def concave_meshes(world: WorldModel) -> list[MeshKey]:
    """(mesh file, scale) of every collision mesh of ``world`` that needs decomposing, each once."""
    out: list[MeshKey] = []
    for model in world.models:
        for link in model.links:
            for shape in link.collisions:
                g = shape.geometry
                if g.kind == "mesh" and g.convex is False and g.mesh_path is not None:
                    key = (g.mesh_path, (float(g.mesh_scale[0]), float(g.mesh_scale[1]), float(g.mesh_scale[2])))
                    if key not in out:
                        out.append(key)
    return out


def default_workers() -> int:
    """Worker processes for decomposition: ``$NAVLAB_DECOMPOSE_WORKERS``, else the CPUs this process may use."""
    env = os.environ.get("NAVLAB_DECOMPOSE_WORKERS", "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            raise SimError(f"NAVLAB_DECOMPOSE_WORKERS={env!r}: expected a whole number >= 1") from None
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def decompose_meshes(meshes: Sequence[MeshKey] | Iterable[MeshKey], *, workers: int | None = None,
                     progress: bool | None = None, threshold: float = THRESHOLD, seed: int = 0,
                     effort: str | None = None) -> int:
    """Fill the cache for every (mesh, scale) not in it yet, ``workers`` processes at a time (default:
    :func:`default_workers`), with a progress bar and time estimate (``progress`` None: on a terminal).
    Returns how many meshes were decomposed."""
    effort = effort or default_effort()
    todo = [(p, s) for p, s in meshes
            if not cache_file(p, s, threshold=threshold, seed=seed, effort=effort).is_file()]
    if not todo:
        return 0
    from tqdm import tqdm

    n_workers = min(workers or default_workers(), len(todo))
    bar = tqdm(total=len(todo), desc=f"decomposing {len(todo)} concave meshes (once; cached)", unit="mesh",
               disable=None if progress is None else not progress, leave=False)
    try:
        if n_workers <= 1:
            for path, scale in todo:
                convex_parts(path, scale, threshold=threshold, seed=seed, effort=effort)
                bar.update()
            return len(todo)
        import multiprocessing

        ctx = multiprocessing.get_context("spawn")  # no fork of a process that may hold threads
        with ProcessPoolExecutor(max_workers=n_workers, mp_context=ctx) as pool:
            # the biggest meshes first, so no long one starts last
            order = sorted(todo, key=lambda item: -Path(item[0]).stat().st_size)
            futures = [pool.submit(_worker, str(p), s, threshold, seed, effort) for p, s in order]
            for fut in as_completed(futures):
                fut.result()
                bar.update()
    finally:
        bar.close()
    return len(todo)


def decompose_world(world: WorldModel, *, workers: int | None = None, progress: bool | None = None) -> int:
    """Decompose the world's uncached concave collision meshes before its scene is built (see
    :func:`decompose_meshes`); returns how many were decomposed."""
    return decompose_meshes(concave_meshes(world), workers=workers, progress=progress)
