"""The true occupancy grid puts the walls and obstacles where the SDF says, at lidar height."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from navlab import resources
from navlab.world import WorldError, load_world, occupancy

FIX = Path(__file__).parents[1] / "fixtures" / "worlds"
RES = 0.05
BOUNDS = (-5.5, -4.5, 5.5, 4.5)


def _cell(x: float, y: float, bounds=BOUNDS, res=RES) -> tuple[int, int]:
    return int((y - bounds[1]) // res), int((x - bounds[0]) // res)


def _centres(grid, bounds=BOUNDS, res=RES):
    ny, nx = grid.shape
    xs = bounds[0] + (np.arange(nx) + 0.5) * res
    ys = bounds[1] + (np.arange(ny) + 0.5) * res
    return np.meshgrid(xs, ys)


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))


@pytest.fixture(scope="module")
def room_grid():
    return occupancy(load_world(resources.world("room")), RES, BOUNDS)


def test_grid_layout(room_grid):
    assert room_grid.shape == (180, 220) and room_grid.dtype == bool


def test_every_wall_box_from_the_file_is_occupied_and_nothing_else(room_grid):
    """Rasterise the SDF's boxes independently (point-in-rotated-rectangle) and compare."""
    root = ET.parse(resources.world("room")).getroot()
    xs, ys = _centres(room_grid)
    expected = np.zeros_like(room_grid)
    for link in root.iter("link"):
        x, y, _, _, _, yaw = (float(v) for v in link.findtext("pose").split())
        sx, sy, _ = (float(v) for v in link.find("collision/geometry/box/size").text.split())
        c, s = math.cos(yaw), math.sin(yaw)
        u = (xs - x) * c + (ys - y) * s
        v = -(xs - x) * s + (ys - y) * c
        inside = (np.abs(u) < sx / 2) & (np.abs(v) < sy / 2)
        assert room_grid[inside].all(), f"{link.get('name')}: cells inside the box are free"
        expected |= inside
    # cells the loader marks but no box centre covers: only the partial-cover rim, ≤ 1 cell wide
    extra = room_grid & ~expected
    grown = expected.copy()
    grown[1:, :] |= expected[:-1, :]
    grown[:-1, :] |= expected[1:, :]
    grown[:, 1:] |= expected[:, :-1]
    grown[:, :-1] |= expected[:, 1:]
    grown[1:, 1:] |= expected[:-1, :-1]
    grown[:-1, :-1] |= expected[1:, 1:]
    grown[1:, :-1] |= expected[:-1, 1:]
    grown[:-1, 1:] |= expected[1:, :-1]
    assert not (extra & ~grown).any()


def test_walls_at_known_places(room_grid):
    for y in np.arange(-3.8, 3.85, 0.1):
        assert room_grid[_cell(4.95, y)] and room_grid[_cell(-4.95, y)]
        assert not room_grid[_cell(4.85, y)] or abs(y + 2.4) < 1.0  # the slanted wall is near (3.2, -2.4)
    for x in np.arange(-4.8, 4.85, 0.1):
        assert room_grid[_cell(x, 3.95)] and room_grid[_cell(x, -3.95)]
    assert not room_grid[_cell(0, 3.85)] and not room_grid[_cell(5.2, 0)]


def test_origin_spawn_area_is_free():
    for name in ("room", "room_obstacles"):
        grid = occupancy(load_world(resources.world(name)), RES, BOUNDS)
        xs, ys = _centres(grid)
        assert not grid[np.hypot(xs, ys) < 1.0 + RES].any(), name


def test_obstacles_are_occupied_at_their_poses():
    world = load_world(resources.world("room_obstacles"))
    grid = occupancy(world, RES, BOUNDS)
    for model in world.models[1:]:
        x, y = model.pose[:2]
        assert grid[_cell(x, y)], model.name
    cyl = next(m for m in world.models if m.name == "unit_cylinder_0")
    r = cyl.links[0].collisions[0].geometry.size[0]
    x, y = cyl.pose[:2]
    assert grid[_cell(x + r - 0.03, y)] and not grid[_cell(x + r + 0.06, y)]


def test_height_band(tmp_path):
    f = tmp_path / "w.world"
    f.write_text("""<sdf version="1.6"><world name="w">
      <model name="shelf"><static>true</static><pose>1 0 0.8 0 0 0</pose><link name="l"><collision name="c">
        <geometry><box><size>0.5 0.5 0.2</size></box></geometry></collision></link></model>
      <model name="mat"><static>true</static><pose>-1 0 0.01 0 0 0</pose><link name="l"><collision name="c">
        <geometry><box><size>0.5 0.5 0.02</size></box></geometry></collision></link></model>
      <model name="ball"><static>true</static><pose>0 1 0.52 0 0 0</pose><link name="l"><collision name="c">
        <geometry><sphere><radius>0.1</radius></sphere></geometry></collision></link></model>
      <model name="log"><static>true</static><pose>0.02 -1.02 0.1 1.5707963 0 0</pose>
        <link name="l"><collision name="c">
        <geometry><cylinder><radius>0.1</radius><length>1.0</length></cylinder></geometry></collision></link>
      </model>
      <model name="crate"><pose>1 1 0.1 0 0 0</pose><link name="l"><collision name="c">
        <geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision></link></model>
    </world></sdf>""")
    world = load_world(f)
    b = (-2.0, -2.0, 2.0, 2.0)
    grid = occupancy(world, 0.05, b)
    assert not grid[_cell(1, 0, b)]  # above 0.5 m
    assert not grid[_cell(-1, 0, b)]  # below 0.05 m
    assert grid[_cell(0, 1, b)]  # a ball dipping into the band
    xs, ys = _centres(grid, b)
    ball = grid & (np.hypot(xs, ys - 1) < 0.2)
    assert np.hypot(xs[ball], ys[ball] - 1).max() < 0.1 + 0.05 * 0.75  # r_eff = sqrt(0.1² - 0.02²) < 0.1
    # a lying cylinder: 1 m long along y (-1.52..-0.52), 0.2 m wide in x (-0.08..0.12)
    log = grid & (np.abs(xs) < 0.5) & (np.abs(ys + 1) < 0.8)
    assert (ys[log].min(), ys[log].max()) == pytest.approx((-1.525, -0.525))
    assert (xs[log].min(), xs[log].max()) == pytest.approx((-0.075, 0.125))
    assert grid[_cell(1, 1, b)]
    assert not occupancy(world, 0.05, b, static_only=True)[_cell(1, 1, b)]


def test_mesh_occupancy_fills_inside_and_keeps_the_concave_notch_free(tmp_path, monkeypatch):
    world = load_world(FIX / "mesh_world.world", model_path=[FIX / "models"])
    b = (-4.0, -3.0, 4.0, 3.0)
    grid = occupancy(world, 0.05, b)
    # crate: 20 x 10 in = 0.508 x 0.254 m centred at (2, 1)
    assert grid[_cell(2.0, 1.0, b)] and grid[_cell(2.2, 1.1, b)]
    assert not grid[_cell(2.32, 1.0, b)] and not grid[_cell(2.0, 1.17, b)]
    # L wall at (-3, -2): legs x in [0, 2] x y in [0, 0.2] and x in [0, 0.2] x y in [0, 1.5]
    assert grid[_cell(-2.0, -1.9, b)] and grid[_cell(-2.9, -1.0, b)]
    assert not grid[_cell(-2.0, -1.0, b)]  # inside the L's notch


def test_bad_arguments():
    world = load_world(resources.world("room"))
    with pytest.raises(WorldError, match="resolution"):
        occupancy(world, 0.0, BOUNDS)
    with pytest.raises(WorldError, match="bounds"):
        occupancy(world, 0.05, (1, 1, 0, 2))


def test_extents():
    from navlab.world import extents

    world = load_world(resources.world("room_obstacles"))
    assert extents(world) == pytest.approx((-5.1, -4.1, 5.1, 4.1))
    mesh_world = load_world(FIX / "mesh_world.world", model_path=[FIX / "models"])
    x0, y0, x1, y1 = extents(mesh_world)
    assert (x0, y0) == pytest.approx((-3.0, -2.0)) and (x1, y1) == pytest.approx((2.254, 1.127))
    assert extents(world, z_min=2.0, z_max=3.0) is None  # nothing that tall
