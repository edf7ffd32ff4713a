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
- only where the robot can reach (``reach``, m above the floor: the robot's height plus a margin,
  see :func:`robot_reach`): a static, upright mesh is clipped at that height (its z clamped, which
  keeps the solid below exactly), only the part below is decomposed; above it a connected piece
  collides as one convex hull where that is nearly its shape (a table top, a shelf board) and not
  at all otherwise (the top of a wall). Rays still hit the true triangles.
  ``NAVLAB_DECOMPOSE_REACH=off`` (or metres) overrides the robot's reach;
- the worker processes never re-run the user's script: a script that loads such a world needs no
  ``if __name__ == "__main__":`` guard;
- results are cached under the navlab cache directory keyed by the mesh file's bytes, the scale
  and the options, including the clipping height in the mesh's frame (not the path or time stamps),
  so later loads, and copies of the same mesh, cost nothing.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import sys
from collections.abc import Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from navlab.description import Origin
from navlab.io import MAX_TEXT_BYTES, IoError, atomic_path, read_bytes_checked
from navlab.sim.errors import SimError
from navlab.world import WorldModel

#: CoACD's concavity threshold (smaller: more, tighter parts)
THRESHOLD = 0.05
#: CoACD options per effort level: "full" is CoACD's defaults (navlab before bounded effort), "bounded" the default
EFFORTS: dict[str, dict[str, Any]] = {
    "full": {},
    "bounded": {
        "preprocess_resolution": 30,
        "resolution": 500,
        "mcts_nodes": 6,
        "mcts_iterations": 20,
        "mcts_max_depth": 2,
    },
}
DEFAULT_EFFORT = "bounded"  # unless $NAVLAB_DECOMPOSE_EFFORT names another of EFFORTS
_VERSION = "1"  # bump when the way parts are computed changes (invalidates the cache)
_REACH_VERSION = "2"  # the same for the clipping at the reach height

#: clearance (m) added to the robot's height for the reach of :func:`robot_reach`
REACH_MARGIN = 0.1
#: above the reach, a piece crossing it collides as its hull if it fills this share of the hull
NEARLY_CONVEX = 0.9

Parts = list[tuple[np.ndarray, np.ndarray]]
#: (mesh file, scale, clipping height in the mesh's frame in m or None for the whole mesh)
MeshKey = tuple[Path, tuple[float, float, float], float | None]


def _cache_dir() -> Path:
    from navlab.description import cache_dir

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


def default_reach() -> float | None:
    """``$NAVLAB_DECOMPOSE_REACH``: m above the floor up to which meshes are decomposed when no robot
    decides it (``off``/unset: None, whole meshes)."""
    env = os.environ.get("NAVLAB_DECOMPOSE_REACH", "").strip().lower()
    if env in ("", "off", "none"):
        return None
    try:
        return float(env)
    except ValueError:
        raise SimError(f"NAVLAB_DECOMPOSE_REACH={env!r}: expected metres above the floor, or 'off'") from None


def robot_reach(robot: Any) -> float | None:
    """How high (m above the floor) ``robot`` can touch the world: its collision height plus
    :data:`REACH_MARGIN`; ``$NAVLAB_DECOMPOSE_REACH`` overrides it (``off``: whole meshes)."""
    env = os.environ.get("NAVLAB_DECOMPOSE_REACH", "").strip()
    if env or robot is None:
        return default_reach()
    from navlab.sim.spawn import robot_outline

    _xy, z_lo, z_hi = robot_outline(robot)
    return round(float(z_hi - z_lo) + REACH_MARGIN, 3)


def local_cut(origin: Origin | None, reach: float | None) -> float | None:
    """The clipping height in a mesh's own frame (m, mm-rounded) for a mesh placed at ``origin`` in
    the world (None: a moving model), or None (whole mesh) when there is no reach or the mesh is
    tilted out of upright."""
    if reach is None or origin is None:
        return None
    m = origin.matrix()
    if abs(m[2, 2] - 1.0) > 1e-9:
        return None
    return round(float(reach) - float(m[2, 3]), 3)


def cache_file(
    path: Path,
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
    *,
    threshold: float = THRESHOLD,
    seed: int = 0,
    effort: str | None = None,
    cut: float | None = None,
) -> Path:
    """Where the parts of this mesh (by content), scale, options and clipping height ``cut`` (m in
    the mesh's frame, None: whole) are cached (``effort`` None: :func:`default_effort`)."""
    effort = effort or default_effort()
    try:
        data = read_bytes_checked(path, what="mesh", max_bytes=MAX_TEXT_BYTES * 4)
    except IoError as exc:
        raise SimError(f"mesh {path}: cannot read it for convex decomposition ({exc})") from None
    opts = sorted(_options(effort, threshold).items())
    key = repr((tuple(float(s) for s in scale), opts, seed, _VERSION))
    # the "full" effort keeps the key of navlab's first cache (threshold, seed) so its entries stay valid
    if effort == "full":
        key = repr((tuple(scale), threshold, seed, _VERSION))
    if cut is not None:
        key += repr(("cut", round(float(cut), 3), _REACH_VERSION))
    digest = hashlib.sha256(data + key.encode()).hexdigest()[:32]
    return _cache_dir() / f"{digest}.npz"


def _load(cached: Path) -> Parts:
    with np.load(cached) as z:
        return [(z[f"v{i}"], z[f"f{i}"]) for i in range(int(z["n"]))]


def _coacd(path: Path, verts: np.ndarray, faces: np.ndarray, threshold: float, seed: int, effort: str) -> Parts:
    try:
        import coacd
    except ImportError:
        raise SimError(f"mesh {path} is concave and decomposing it needs the coacd package") from None
    coacd.set_log_level("error")
    result = coacd.run_coacd(coacd.Mesh(verts, faces), seed=seed, **_options(effort, threshold))
    return [(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int32)) for v, f in result]


def _compute(
    path: Path, scale: tuple[float, float, float], threshold: float, seed: int, effort: str, cut: float | None = None
) -> Parts:
    from navlab.description import read_mesh

    verts, faces = read_mesh(Path(path))
    verts, faces = weld(verts * np.asarray(scale, dtype=float), faces)
    if cut is not None and len(verts) and float(verts[:, 2].max()) > cut + 1e-6:
        below, above = split_at(verts, faces, cut)
        parts = above + (_coacd(path, *below, threshold, seed, effort) if below is not None else [])
    else:
        parts = _coacd(path, verts, faces, threshold, seed, effort)
    if not parts and cut is None:  # (with a cut: nothing within reach, nothing to collide)
        raise SimError(f"mesh {path}: convex decomposition produced no parts")
    return parts


def _store(cached: Path, parts: Parts) -> None:
    arrays: dict[str, np.ndarray] = {"n": np.array(len(parts))}
    for i, (v, f) in enumerate(parts):
        arrays[f"v{i}"], arrays[f"f{i}"] = v, f
    with atomic_path(cached, suffix=".npz") as tmp, tmp.open("wb") as fh:
        np.savez(fh, allow_pickle=False, **arrays)  # numeric arrays only


def convex_parts(
    path: Path,
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
    *,
    threshold: float = THRESHOLD,
    seed: int = 0,
    effort: str | None = None,
    cut: float | None = None,
) -> Parts:
    """Convex parts (vertices (n, 3) in m, triangles (m, 3)) of the mesh file scaled by ``scale``;
    with ``cut`` (m, mesh frame) only the part below it is decomposed (see the module docstring).

    Results are cached under the navlab cache directory, keyed by the file's bytes and the options.
    """
    effort = effort or default_effort()
    cached = cache_file(path, scale, threshold=threshold, seed=seed, effort=effort, cut=cut)
    if cached.is_file():
        return _load(cached)
    parts = _compute(Path(path), scale, threshold, seed, effort, cut)
    _store(cached, parts)
    return parts


def _worker(
    path: str, scale: tuple[float, float, float], threshold: float, seed: int, effort: str, cut: float | None = None
) -> int:
    """Decompose one mesh into the cache (in a worker process); returns the number of parts."""
    return len(convex_parts(Path(path), scale, threshold=threshold, seed=seed, effort=effort, cut=cut))


def _volume(verts: np.ndarray, faces: np.ndarray) -> float:
    """The volume (m³) a closed triangle mesh encloses (divergence theorem; any consistent winding);
    0 for an open mesh (an edge not shared by exactly two triangles), whose volume means nothing."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _e, counts = np.unique(edges, axis=0, return_counts=True)
    if len(faces) == 0 or (counts != 2).any():
        return 0.0
    v0, v1, v2 = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    return abs(float(np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum()) / 6.0)


def _hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The convex hull of ``points`` (n, 3) as (vertices, outward triangles, volume m³), None if flat."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError):
        return None
    if hull.volume <= 1e-12:
        return None
    used = np.unique(hull.simplices)
    index = np.full(len(points), -1)
    index[used] = np.arange(len(used))
    faces = index[hull.simplices]
    verts = points[used]
    # orient each triangle along its facet's outward normal
    n = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    flip = np.einsum("ij,ij->i", n, hull.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, [0, 2, 1]]
    return verts.astype(float), faces.astype(np.int32), float(hull.volume)


def split_at(verts: np.ndarray, faces: np.ndarray, cut: float) -> tuple[tuple[np.ndarray, np.ndarray] | None, Parts]:
    """Split a closed mesh (m, welded) at height ``cut``: (the solid below it as a mesh to decompose,
    or None; the convex hulls of connected pieces above it).

    Below: the pieces reaching below ``cut`` with every z clamped to it. The clamp only moves surface
    above the plane, so every point below keeps its winding number: the same solid up to ``cut``,
    closed by the flattened surface above. Above: a piece entirely above the cut (a table top, a shelf
    board) collides as its hull; the part above the cut of a piece that crosses it, as its hull if
    that part is nearly convex (a cabinet), else not at all: a hull there would fill the room a
    wall mesh encloses (rays still hit the true triangles)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(verts)
    rows = np.concatenate([faces[:, 0], faces[:, 1]])
    cols = np.concatenate([faces[:, 1], faces[:, 2]])
    _n, label = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)), directed=False)
    z = verts[:, 2]
    lo = np.full(_n, np.inf)
    hi = np.full(_n, -np.inf)
    np.minimum.at(lo, label, z)
    np.maximum.at(hi, label, z)
    above: Parts = []
    raised = verts.copy()
    raised[:, 2] = np.maximum(raised[:, 2], cut)
    face_piece = label[faces[:, 0]]
    for piece in np.nonzero(hi > cut + 1e-6)[0]:
        hull = _hull(raised[label == piece])
        if hull is None:
            continue
        if lo[piece] >= cut - 1e-6 or _volume(raised, faces[face_piece == piece]) >= NEARLY_CONVEX * hull[2]:
            above.append((hull[0], hull[1]))
    keep = (lo < cut - 1e-6)[face_piece]
    if not keep.any():
        return None, above
    low = verts.copy()
    low[:, 2] = np.minimum(low[:, 2], cut)
    f = faces[keep]
    area = np.linalg.norm(np.cross(low[f[:, 1]] - low[f[:, 0]], low[f[:, 2]] - low[f[:, 0]]), axis=1)
    f = f[area > 1e-12]  # faces above the cut seen edge-on collapse to nothing
    used, f = np.unique(f, return_inverse=True)
    return (low[used], f.reshape(-1, 3).astype(np.int32)), above


def _shape_origins(world: WorldModel) -> list[tuple[Any, Origin | None]]:
    """(geometry, its pose in the world or None for a moving model) of every collision shape."""
    out: list[tuple[Any, Origin | None]] = []
    for model in world.models:
        x, y, z, roll, pitch, yaw = model.pose
        model_pose = Origin(xyz=(x, y, z), rpy=(roll, pitch, yaw))
        for link in model.links:
            link_pose = model_pose.then(model.link_origins.get(link.name, Origin()))
            for shape in link.collisions:
                out.append((shape.geometry, link_pose.then(shape.origin) if model.static else None))
    return out


def concave_meshes(world: WorldModel, reach: float | None = None) -> list[MeshKey]:
    """(mesh file, scale, clipping height) of every collision mesh of ``world`` that needs decomposing,
    each once; ``reach`` (m above the floor, None: whole meshes) sets the clipping heights."""
    out: list[MeshKey] = []
    for g, origin in _shape_origins(world):
        if g.kind == "mesh" and g.convex is False and g.mesh_path is not None:
            scale = (float(g.mesh_scale[0]), float(g.mesh_scale[1]), float(g.mesh_scale[2]))
            key = (g.mesh_path, scale, local_cut(origin, reach))
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


@contextlib.contextmanager
def _main_not_reimported() -> Iterator[None]:
    """While workers start, hide the user's ``__main__`` from multiprocessing's spawn: a spawned worker
    otherwise re-runs the user's script (or ``-m`` module) before it imports the worker function, and a
    script without an ``if __name__ == "__main__":`` guard would then start workers of its own and crash.
    The workers need only navlab's own modules."""
    main = sys.modules.get("__main__")
    saved: dict[str, Any] = {
        k: main.__dict__[k] for k in ("__file__", "__spec__") if main is not None and k in main.__dict__
    }
    try:
        if main is not None:
            main.__dict__.pop("__file__", None)
            main.__spec__ = None
        yield
    finally:
        if main is not None:
            main.__dict__.update(saved)
            if "__spec__" not in saved:
                main.__dict__.pop("__spec__", None)


def decompose_meshes(
    meshes: Sequence[MeshKey] | Iterable[MeshKey],
    *,
    workers: int | None = None,
    progress: bool | None = None,
    threshold: float = THRESHOLD,
    seed: int = 0,
    effort: str | None = None,
) -> int:
    """Fill the cache for every (mesh, scale) not in it yet, ``workers`` processes at a time (default:
    :func:`default_workers`), with a progress bar and time estimate (``progress`` None: on a terminal).
    Returns how many meshes were decomposed."""
    effort = effort or default_effort()
    todo = [
        (p, s, c)
        for p, s, c in meshes
        if not cache_file(p, s, threshold=threshold, seed=seed, effort=effort, cut=c).is_file()
    ]
    if not todo:
        return 0
    from tqdm import tqdm

    n_workers = min(workers or default_workers(), len(todo))
    bar = tqdm(
        total=len(todo),
        desc=f"decomposing {len(todo)} concave meshes (once; cached)",
        unit="mesh",
        disable=None if progress is None else not progress,
        leave=False,
    )
    try:
        if n_workers <= 1:
            for path, scale, cut in todo:
                convex_parts(path, scale, threshold=threshold, seed=seed, effort=effort, cut=cut)
                bar.update()
            return len(todo)
        import multiprocessing

        ctx = multiprocessing.get_context("spawn")  # no fork of a process that may hold threads
        with _main_not_reimported(), ProcessPoolExecutor(max_workers=n_workers, mp_context=ctx) as pool:
            # the biggest meshes first, so no long one starts last
            order = sorted(todo, key=lambda item: -Path(item[0]).stat().st_size)
            futures = [pool.submit(_worker, str(p), s, threshold, seed, effort, c) for p, s, c in order]
            for fut in as_completed(futures):
                fut.result()
                bar.update()
    finally:
        bar.close()
    return len(todo)


def decompose_world(
    world: WorldModel, *, reach: float | None = None, workers: int | None = None, progress: bool | None = None
) -> int:
    """Decompose the world's uncached concave collision meshes (up to ``reach``, see
    :func:`concave_meshes`) before its scene is built (see :func:`decompose_meshes`); returns how
    many were decomposed."""
    return decompose_meshes(concave_meshes(world, reach), workers=workers, progress=progress)
