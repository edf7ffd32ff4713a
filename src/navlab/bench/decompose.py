"""``navlab bench decompose``: the first load of a furnished world (many concave meshes) with CoACD's
defaults and with navlab's bounded, parallel decomposition, on a generated world, each with a cold cache.

- ``before``: CoACD at its default effort, one mesh after another in this process (navlab before
  bounded effort);
- ``after_whole``: bounded effort (``decompose.EFFORTS["bounded"]``) in parallel worker processes,
  whole meshes;
- ``after``: the same, decomposed only up to the reach of mybot (``decompose.robot_reach``): parts
  above it are one hull each;
- ``warm``: the same load again, everything from the content-keyed cache.

Each load runs in a fresh process. Figures are wall seconds of ``Simulation(None, world)`` (load +
decomposition + build), the CPU seconds of the decomposition (all processes), the parts per mesh,
and peak memory: ``ru_maxrss`` (MB) of the loading process and of its largest worker. The world is
:func:`furnished_world`: L-shaped counters, U-shaped sofas, open shelves and T-shaped tables of
seeded random sizes (every mesh different, so the cache cannot share them).
"""

from __future__ import annotations

import argparse
import os
import resource
import struct
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

MESHES = 8  # concave meshes in the generated world
ROBOT = "mybot"  # whose reach bounds the decomposition in ``after``


def _box(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Triangles (12, 3, 3) of an axis-aligned box, outward-facing."""
    c = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return np.array([[c[a], c[b], c[d]] for q in quads for a, b, d in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))])


Box = tuple[Sequence[float], Sequence[float]]


def _piece(kind: str, rng: np.random.Generator) -> list[Box]:
    """Boxes (lo, hi) of one piece of furniture, metres, standing on z = 0."""
    t = float(rng.uniform(0.03, 0.06))
    if kind == "counter":  # L
        a, b, d, h = rng.uniform(1.2, 2.2), rng.uniform(0.8, 1.6), rng.uniform(0.5, 0.7), rng.uniform(0.8, 0.95)
        return [([0, 0, 0], [a, d, h]), ([0, d, 0], [d, b, h])]
    if kind == "sofa":  # U seen from above
        w, d, h = rng.uniform(1.5, 2.4), rng.uniform(0.8, 1.0), rng.uniform(0.7, 0.9)
        return [
            ([0, 0, 0], [w, 0.2, h]),
            ([0, 0.2, 0], [0.2, d, h * 0.7]),
            ([w - 0.2, 0.2, 0], [w, d, h * 0.7]),
            ([0.2, 0.2, 0], [w - 0.2, d, 0.4]),
        ]
    if kind == "shelf":  # open shelf: sides, back and boards
        w, d, h = rng.uniform(0.8, 1.4), rng.uniform(0.3, 0.45), rng.uniform(0.8, 1.8)
        boxes: list[Box] = [([0, 0, 0], [t, d, h]), ([w - t, 0, 0], [w, d, h]), ([0, d - t, 0], [w, d, h])]
        return boxes + [([0, 0, float(z)], [w, d, float(z) + t]) for z in np.linspace(0, h - t, 3)]
    w, d, h = rng.uniform(0.8, 1.6), rng.uniform(0.6, 1.0), rng.uniform(0.7, 0.8)  # table: top on a pedestal
    return [([0, 0, h - t], [w, d, h]), ([w / 2 - 0.1, d / 2 - 0.1, 0], [w / 2 + 0.1, d / 2 + 0.1, h - t])]


def _write_stl(path: Path, tris: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    rec = np.zeros(len(tris), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rec["v"] = tris
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(tris)) + rec.tobytes())


KINDS = ("counter", "sofa", "shelf", "table")


def furnished_world(folder: Path, n: int = MESHES, seed: int = 0, kinds: tuple[str, ...] = KINDS) -> Path:
    """Write a world of ``n`` concave furniture meshes (STL models under ``folder/models``), taking the
    ``kinds`` in turn (counter: L, sofa: U, shelf, table: T); returns the ``.world`` file."""
    rng = np.random.default_rng(seed)
    includes = []
    for i in range(n):
        name = f"piece_{i}"
        boxes = _piece(kinds[i % len(kinds)], rng)
        tris = np.concatenate([_box(np.array(lo, float), np.array(hi, float)) for lo, hi in boxes])
        model = folder / "models" / name
        _write_stl(model / "meshes" / f"{name}.stl", tris)
        (model / "model.config").write_text(f"<model><name>{name}</name><sdf version='1.6'>model.sdf</sdf></model>")
        (model / "model.sdf").write_text(
            f'<sdf version="1.6"><model name="{name}"><static>true</static><link name="link">'
            f'<collision name="c"><geometry><mesh><uri>model://{name}/meshes/{name}.stl</uri></mesh></geometry>'
            f'</collision><visual name="v"><geometry><mesh><uri>model://{name}/meshes/{name}.stl</uri></mesh>'
            "</geometry></visual></link></model></sdf>"
        )
        x, y = 3.0 * (i % 4), 3.0 * (i // 4)
        includes.append(f"<include><uri>model://{name}</uri><pose>{x} {y} 0 0 0 0</pose></include>")
    world = folder / "furnished.world"
    world.write_text(
        '<sdf version="1.6"><world name="furnished"><include><uri>model://ground_plane</uri>'
        f"</include>{''.join(includes)}</world></sdf>"
    )
    return world


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _self_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _load_here(world_file: str, cache: str, effort: str, workers: int, reach: str) -> dict[str, Any]:
    """Load the world and build its simulation with the cache at ``cache`` (in a fresh process)."""
    from navlab.sim import Simulation, concave_meshes, convex_parts, default_reach
    from navlab.world import load_world

    os.environ["NAVLAB_CACHE"] = cache
    os.environ["NAVLAB_DECOMPOSE_WORKERS"] = str(workers)
    os.environ["NAVLAB_DECOMPOSE_EFFORT"] = effort  # what the scene builder's decompose_world uses
    os.environ["NAVLAB_DECOMPOSE_REACH"] = reach  # no robot in the scene: the reach is given
    wall0, cpu0, child0 = time.perf_counter(), _self_cpu(), _children_cpu()
    world = load_world(world_file)
    sim = Simulation(None, world, visuals=False)  # decomposes (in parallel), then builds
    wall = time.perf_counter() - wall0
    cpu = _self_cpu() - cpu0 + _children_cpu() - child0
    meshes = concave_meshes(world, default_reach())
    parts = [len(convex_parts(p, s, cut=c)) for p, s, c in meshes]
    mb = 1024.0 if os.uname().sysname != "Darwin" else 1024.0 * 1024.0  # ru_maxrss: KiB on Linux, bytes on macOS
    return {
        "wall_s": round(wall, 1),
        "cpu_s": round(cpu, 1),
        "meshes": len(meshes),
        "parts_per_mesh": round(float(np.mean(parts)), 1),
        "geoms": int(sim.model.ngeom),
        "workers": workers,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / mb),
        "peak_worker_rss_mb": round(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / mb),
    }


def _first_load(world_file: Path, cache: Path, effort: str, workers: int, reach: str = "off") -> dict[str, Any]:
    """:func:`_load_here` in a fresh process, so its peak memory is its own."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        return pool.submit(_load_here, str(world_file), str(cache), effort, workers, reach).result()


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Measure and return {"before", "after", "warm_s", ...} (see the module docstring)."""
    from navlab.description import load_robot_named
    from navlab.sim import default_reach, default_workers, robot_reach

    seed = int(getattr(args, "seed", 0))
    reach = robot_reach(load_robot_named(ROBOT)) if not os.environ.get("NAVLAB_DECOMPOSE_REACH") else None
    reach_s = str(reach if reach is not None else default_reach() or "off")
    workers = default_workers()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        world = furnished_world(folder / "world", MESHES, seed)
        after = _first_load(world, folder / "cache_after", "bounded", workers, reach_s)
        t0 = time.perf_counter()
        warm = _first_load(world, folder / "cache_after", "bounded", 1, reach_s)
        warm_s = time.perf_counter() - t0
        whole = _first_load(world, folder / "cache_whole", "bounded", workers, "off")
        before = _first_load(world, folder / "cache_before", "full", 1, "off")
    return {
        "before": before,
        "after_whole": whole,
        "after": after,
        "reach_m": reach_s,
        "robot": ROBOT,
        "warm_s": round(warm_s, 2),
        "warm_wall_s": warm["wall_s"],
        "speedup_wall": round(before["wall_s"] / max(after["wall_s"], 1e-9), 1),
        "speedup_cpu": round(before["cpu_s"] / max(after["cpu_s"], 1e-9), 1),
        "reach_speedup_cpu": round(whole["cpu_s"] / max(after["cpu_s"], 1e-9), 2),
        "note": "cold caches, each load in a fresh process; wall time on a shared machine depends on its load",
    }
