"""Issue 13 item 11: a world's concave meshes are decomposed once, in parallel, into a cache keyed by
their content (fixture: navlab.bench.decompose.furnished_world)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

from navlab.bench.decompose import furnished_world
from navlab.sim import decompose
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
    assert decompose.decompose_meshes([(copy, *meshes[0][1:])], workers=1, progress=False) == 0
    # bounded effort still leaves the L's notch free: its inner corner region is in no convex part
    counter = decompose.convex_parts(meshes[0][0], meshes[0][1], cut=meshes[0][2])
    verts = np.vstack([v for v, _ in counter])
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    notch = np.array([hi[0] - 0.05, hi[1] - 0.05, 0.3])  # far corner of the L's bounding box, at 0.3 m
    assert not _inside_any(counter, notch)
    assert len(counter) >= 2 and lo[2] == pytest.approx(0.0, abs=0.05)


def test_decomposed_only_up_to_the_robots_reach_and_the_robot_still_cannot_drive_through(tmp_path):
    """Above the robot's reach nothing is decomposed: an L counter's top is left out of physics, a
    table top is one hull; below it the L keeps its notch, and the robot drives into the counter and
    stops at it."""
    from sim_helpers import make_mybot

    from navlab.description.meshes import read_mesh
    from navlab.sim import Simulation, primitive_model

    robot = make_mybot(noise=0.0)
    reach = decompose.robot_reach(robot)
    assert 0.15 < reach < 0.5  # mybot's height + margin
    world = load_world(furnished_world(tmp_path / "w", n=2, seed=2, kinds=("counter", "table")))
    (counter_mesh, scale, cut), (table_mesh, tscale, tcut) = decompose.concave_meshes(world, reach)
    assert cut == tcut == pytest.approx(reach)  # pieces stand on the floor: the cut in their frame is the reach
    assert decompose.cache_file(counter_mesh, scale, cut=cut) != decompose.cache_file(counter_mesh, scale)
    counter = decompose.convex_parts(counter_mesh, scale, cut=cut)
    verts = np.vstack([v for v, _ in counter])
    assert verts[:, 2].max() < reach + 0.03  # nothing above the reach (but CoACD's voxel slack)
    hi = read_mesh(counter_mesh)[0].max(axis=0) * np.asarray(scale)
    assert not _inside_any(counter, np.array([hi[0] - 0.05, hi[1] - 0.05, 0.1]))  # the notch stays free
    assert _inside_any(counter, np.array([0.05, 0.05, 0.1]))  # the solid stays solid
    table = decompose.convex_parts(table_mesh, tscale, cut=tcut)
    assert any(v[:, 2].min() > reach for v, _ in table)  # the top above the reach: its own hull

    # the counter's long side faces -y at y = 0; the robot drives straight at it from 0.6 m away
    sim = Simulation(robot, world, robot_pose=(0.5, -0.6, math.pi / 2), visuals=False)
    sim.set_wheel_velocity_targets(8.0, 8.0)
    sim.step(2000)  # 4 s: far enough to pass through the 0.5 m deep counter were it not solid
    y = sim.base_pose2d()[1]
    assert y < -0.05  # stopped by the counter (the robot's centre stays outside it)
    assert sim.base_pose2d()[1] > -0.45  # and it did drive up to it
    # an object dropped on the table top rests on it (the top collides as its hull)
    top = max(v[:, 2].max() for v, _ in table)
    sim.spawn(primitive_model("sphere", "ball", (0.05,), x=3.0 + 0.3, y=0.3, z=top + 0.3, static=False))
    sim.step(600)
    assert sim.model_pose("ball").position[2] == pytest.approx(top + 0.05, abs=0.02)


def test_a_script_without_a_main_guard_loads_a_world_with_concave_meshes(tmp_path):
    """Issue 23 item 5: the decomposition workers never re-import the user's script (spawn would run it
    again in each worker, which then tries to start workers of its own and crashes)."""
    import os
    import subprocess
    import sys

    world_file = furnished_world(tmp_path / "w", n=2, seed=3, kinds=("sofa",))
    script = tmp_path / "user_script.py"
    script.write_text(
        "from navlab.sim import decompose\n"
        "from navlab.world import load_world\n"
        f"world = load_world({str(world_file)!r})\n"
        "print('decomposed', decompose.decompose_world(world, workers=2, progress=False), flush=True)\n"
    )
    env = {**os.environ, "NAVLAB_CACHE": str(tmp_path / "cache")}
    done = subprocess.run(
        [sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=600, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.splitlines() == ["decomposed 2"]  # the script ran once: no worker re-ran it
