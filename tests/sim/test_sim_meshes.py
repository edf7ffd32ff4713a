"""World meshes: concave ones collide as convex parts, lidar rays hit their true triangles."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from sim_helpers import make_mybot

from navlab.description import Geometry, Link, Shape
from navlab.sim import Simulation, primitive_model
from navlab.world import ModelSpec, WorldModel

# a U seen from above: a bar along y=0..0.5 and two arms x=0..0.5 and x=1..1.5 up to y=1.5
U_OUTLINE = [(0, 0), (0.5, 0), (1.0, 0), (1.5, 0), (1.5, 1.5), (1.0, 1.5), (1.0, 0.5), (0.5, 0.5), (0.5, 1.5), (0, 1.5)]
U_TOP = [(0, 1, 7), (0, 7, 8), (0, 8, 9), (1, 2, 6), (1, 6, 7), (3, 4, 5), (3, 5, 6), (3, 6, 2)]


def write_u_obj(path: Path, height: float = 0.5) -> Path:
    """A closed, extruded U-shaped mesh (concave), 1.5 m × 1.5 m, ``height`` m tall, as OBJ."""
    n = len(U_OUTLINE)
    lines = [f"v {x} {y} 0" for x, y in U_OUTLINE] + [f"v {x} {y} {height}" for x, y in U_OUTLINE]
    for a, b, c in U_TOP:
        lines.append(f"f {a + 1} {c + 1} {b + 1}")  # bottom, facing down
        lines.append(f"f {a + n + 1} {b + n + 1} {c + n + 1}")  # top, facing up
    for i in range(n):  # walls
        j = (i + 1) % n
        lines.append(f"f {i + 1} {j + 1} {j + n + 1}")
        lines.append(f"f {i + 1} {j + n + 1} {i + n + 1}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_concave_mesh_collides_as_parts_and_rays_hit_its_notch(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    mesh = write_u_obj(tmp_path / "u.obj")
    shape = Shape(Geometry("mesh", mesh_path=mesh, convex=False))
    u_model = ModelSpec("u_shelf", static=True, links=[Link("link", collisions=[shape])])
    world = WorldModel("u_world", models=[u_model])
    # the robot outside the U's opening, looking down into the notch (laser beam 360 points ahead)
    sim = Simulation(make_mybot(noise=0.0), world, robot_pose=(0.75, 3.0, -math.pi / 2))
    assert sim.true_ranges()[360] == pytest.approx(2.5, abs=1e-3)  # the bar's inner face at y = 0.5
    # a ball dropped into the notch falls to the floor: the notch is not filled by a convex hull
    sim.spawn(primitive_model("sphere", "ball", (0.15,), x=0.75, y=1.0, z=1.0, static=False))
    sim.step(1500)
    assert sim.model_pose("ball").position[2] == pytest.approx(0.15, abs=0.01)
    assert sim.true_ranges()[360] == pytest.approx(3.0 - 1.15, abs=1e-3)  # and the lidar sees it there
    # cached: a second build reuses the parts; removing and re-adding the model works
    sim.remove("ball")
    sim.remove("u_shelf")
    sim.spawn(u_model)
    assert sim.true_ranges()[360] == pytest.approx(2.5, abs=1e-3)
    assert any((tmp_path / "cache").rglob("*.npz"))


def test_convex_or_unknown_mesh_collides_as_its_hull(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    mesh = write_u_obj(tmp_path / "u.obj")
    shape = Shape(Geometry("mesh", mesh_path=mesh, convex=None))  # not checked: hull, like MuJoCo
    world = WorldModel("w", models=[ModelSpec("u_shelf", static=True, links=[Link("link", collisions=[shape])])])
    sim = Simulation(None, world)
    sim.spawn(primitive_model("sphere", "ball", (0.15,), x=0.75, y=1.0, z=1.0, static=False))
    sim.step(1500)
    assert sim.model_pose("ball").position[2] == pytest.approx(0.5 + 0.15, abs=0.01)  # rests on the hull


def test_sdf_world_with_stl_l_wall_and_dae_box(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The world loader's mesh fixture: a concave STL L-wall at (-3, -2) and a COLLADA box in inches."""
    from navlab.world import load_world

    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    world = load_world(Path(__file__).parents[1] / "fixtures" / "worlds" / "mesh_world.world")
    # inside the L (legs x -3..-1 at y -2..-1.8 and x -3..-2.8 at y -1.8..-0.3), facing its inner corner
    sim = Simulation(make_mybot(noise=0.0), world, robot_pose=(-2.3, -1.3, -3 * math.pi / 4))
    parts = [g for g in range(sim.model.ngeom) if sim.model.geom(g).name.startswith("l_wall::link::collision0::")]
    assert len(parts) >= 2  # decomposed: the L is not its convex hull
    ahead = sim.true_ranges()[360]  # towards the inner corner (-2.8, -1.8)
    assert ahead == pytest.approx(math.hypot(0.5, 0.5), abs=0.02)
    sim.spawn(primitive_model("sphere", "ball", (0.1,), x=-2.6, y=-1.6, z=1.3, static=False))
    sim.step(1000)
    assert sim.model_pose("ball").position[2] == pytest.approx(0.1, abs=0.01)  # fell into the notch
    crate = sim.model_pose("crate").position
    assert crate[:2] == pytest.approx((2.0, 1.0), abs=0.3)
