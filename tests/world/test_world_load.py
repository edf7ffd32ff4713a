"""SDF worlds: the shipped rooms, includes through a model path, meshes, state, errors."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from navlab import resources
from navlab.world import WorldError, load_world

FIX = Path(__file__).parents[1] / "fixtures" / "worlds"


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)


def test_room_loads():
    world = load_world(resources.world("room"))
    assert world.name == "room" and world.ground_plane and world.warnings == []
    assert world.max_step_size == 0.001 and world.gravity == (0.0, 0.0, -9.8)
    (walls,) = world.models  # ground_plane and sun come in through model:// but add no bodies
    assert walls.name == "room_walls" and walls.static
    names = {link.name for link in walls.links}
    assert {"Wall_north", "Wall_south", "Wall_east", "Wall_west"} <= names
    east = next(link for link in walls.links if link.name == "Wall_east")
    assert walls.link_origins["Wall_east"].xyz == (5.0, 0.0, 0.5)
    assert east.collisions[0].geometry.kind == "box" and east.collisions[0].geometry.size == (0.2, 7.8, 1.0)


def test_room_is_about_10_by_8_m():
    world = load_world(resources.world("room"))
    origins = world.models[0].link_origins
    assert origins["Wall_east"].xyz[0] - origins["Wall_west"].xyz[0] == pytest.approx(10.0)
    assert origins["Wall_north"].xyz[1] - origins["Wall_south"].xyz[1] == pytest.approx(8.0)


def test_room_obstacles_is_room_plus_cubes_and_cylinders():
    room = load_world(resources.world("room"))
    obst = load_world(resources.world("room_obstacles"))
    assert obst.models[0].link_origins == room.models[0].link_origins
    extra = obst.models[1:]
    kinds = [m.links[0].collisions[0].geometry.kind for m in extra]
    assert kinds.count("box") >= 3 and kinds.count("cylinder") >= 3
    assert all(m.static for m in extra)
    # the inertial of the unit shapes is read too
    assert extra[0].links[0].inertial.mass == 5.0


def test_include_through_model_path_with_dae_units_and_concave_mesh():
    world = load_world(FIX / "mesh_world.world", model_path=[FIX / "models"])
    assert world.max_step_size == 0.002 and world.gravity == (0.0, 0.0, -9.81)  # SDF 1.4 physics/gravity
    by_name = {m.name: m for m in world.models}
    assert set(by_name) == {"crate", "l_wall"}  # <include><name> renames
    crate = by_name["crate"]
    assert crate.pose == (2.0, 1.0, 0.0, 0.0, 0.0, 0.0) and crate.static
    geom = crate.links[0].collisions[0].geometry
    assert geom.mesh_path.suffix == ".obj" and geom.mesh_source.name == "box.dae"
    assert geom.mesh_scale == pytest.approx((0.0254,) * 3)
    assert geom.convex is True
    wall = by_name["l_wall"].links[0].collisions[0].geometry
    assert wall.mesh_path.name == "l_wall.stl" and wall.convex is False  # needs convex decomposition
    assert by_name["l_wall"].links[0].visuals[0].geometry.convex is None


def test_gazebo_model_path_env(monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(FIX / "models"))
    assert {m.name for m in load_world(FIX / "mesh_world.world").models} == {"crate", "l_wall"}


def _write(tmp_path, body: str, version: str = "1.6", name: str = "w.world") -> Path:
    f = tmp_path / name
    f.write_text(
        f'<?xml version="1.0"?><sdf version="{version}"><world name="w">'
        f"<include><uri>model://ground_plane</uri></include>{body}</world></sdf>"
    )
    return f


def test_nested_models_dynamic_defaults_and_state(tmp_path):
    body = """
    <model name="cart"><pose>1 0 0 0 0 1.5707963</pose>
      <link name="base"><pose>0 0 0.1 0 0 0</pose>
        <collision name="c"><geometry><box><size>1 0.5 0.2</size></box></geometry>
          <surface><friction><ode><mu>0.4</mu><mu2>0.3</mu2></ode></friction></surface></collision></link>
      <model name="top"><pose>0.5 0 0.3 0 0 0</pose>
        <link name="lid"><collision name="c"><geometry><sphere><radius>0.1</radius></sphere></geometry>
        </collision></link></model>
    </model>
    <state world_name="w"><model name="cart"><pose>3 4 0 0 0 0</pose></model></state>"""
    world = load_world(_write(tmp_path, body))
    (cart,) = world.models
    assert not cart.static and cart.pose == (3.0, 4.0, 0.0, 0.0, 0.0, 0.0)  # the saved state wins
    assert [link.name for link in cart.links] == ["base", "top::lid"]
    assert cart.link_origins["top::lid"].xyz == pytest.approx((0.5, 0.0, 0.3))
    base = cart.links[0]
    assert base.inertial.mass == 1.0 and base.inertial.ixx == 1.0  # SDF's default inertial
    assert (base.mu1, base.mu2) == (0.4, 0.3)


def test_unsupported_things_warn(tmp_path):
    body = """<plugin name="ros_state" filename="libgazebo_ros_state.so"/>
      <model name="k"><static>true</static><link name="l"><pose relative_to="other">1 0 0 0 0 0</pose>
        <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision></link></model>
      <model name="m"><static>true</static><link name="l"><collision name="c"><geometry><heightmap/>
      </geometry></collision></link><plugin name="p" filename="libfoo.so"/></model>"""
    world = load_world(_write(tmp_path, body, version="1.9"))
    text = "\n".join(world.warnings)
    assert "ros_state" in text and "heightmap" in text and "libfoo.so" in text and "1.9" in text
    assert "frame 'other'" in text


def test_no_ground_plane_warns(tmp_path):
    f = tmp_path / "w.world"
    f.write_text('<sdf version="1.6"><world name="w"></world></sdf>')
    world = load_world(f)
    assert not world.ground_plane and any("ground plane" in w for w in world.warnings)


@pytest.mark.parametrize(
    "body,pattern",
    [
        ("<include><uri>model://no_such_model</uri></include>", r"w\.world.*model://no_such_model.*not found"),
        (
            '<model name="m"><link name="l"><collision name="c"><geometry><box><size>1 1</size></box></geometry>'
            "</collision></link></model>",
            r'<model name="m">/<link name="l">/<collision name="c">/<geometry>/<box>/<size>',
        ),
        (
            '<model name="m"><link name="l"><collision name="c"><geometry><cylinder><radius>-1</radius>'
            "<length>1</length></cylinder></geometry></collision></link></model>",
            r"sizes must be positive",
        ),
        (
            '<model name="m"><link name="l"><collision name="c"><geometry><mesh><uri>meshes/gone.stl</uri></mesh>'
            "</geometry></collision></link></model>",
            r'<model name="m">.*gone\.stl not found',
        ),
        ('<model name="m"><pose>0 0 x 0 0 0</pose></model>', r'<model name="m">/<pose>'),
        ('<model name="m"><link name="a"/></model><model name="m"><link name="a"/></model>', r"duplicate model"),
        ('<physics type="ode"><max_step_size>-1</max_step_size></physics>', r"<physics>/<max_step_size>"),
    ],
)
def test_bad_worlds_name_file_and_element(tmp_path, body, pattern):
    with pytest.raises(WorldError, match=pattern):
        load_world(_write(tmp_path, body))


def test_malformed_xml_and_wrong_roots(tmp_path):
    bad = tmp_path / "bad.world"
    bad.write_text('<sdf version="1.6"><world name="w">')
    with pytest.raises(WorldError, match=r"bad\.world: malformed XML"):
        load_world(bad)
    bad.write_text('<robot name="r"/>')
    with pytest.raises(WorldError, match=r"bad\.world: top element is <robot>"):
        load_world(bad)
    bad.write_text('<sdf version="1.6"><model name="m"/></sdf>')
    with pytest.raises(WorldError, match=r"bad\.world: <sdf> has no <world>"):
        load_world(bad)
    with pytest.raises(WorldError, match="not found"):
        load_world(tmp_path / "missing.world")


def test_shipped_world_walls_match_their_xml():
    """Independent check of the loader: every wall link's pose equals the file's <pose>."""
    path = resources.world("room")
    root = ET.parse(path).getroot()
    world = load_world(path)
    origins = world.models[0].link_origins
    for link in root.iter("link"):
        x, y, z, _, _, yaw = (float(v) for v in link.findtext("pose").split())
        o = origins[link.get("name")]
        assert o.xyz == pytest.approx((x, y, z)) and math.isclose(o.rpy[2], yaw, abs_tol=1e-12)


def test_load_model_for_spawning(tmp_path):
    from navlab.world import load_model

    models = FIX / "models"
    by_dir = load_model(models / "l_wall")
    by_file = load_model(models / "l_wall" / "model.sdf")
    by_uri = load_model("model://inch_box", model_path=[models])
    assert by_dir.name == by_file.name == "l_wall" and by_dir.static
    assert by_dir.links[0].collisions[0].geometry.convex is False
    assert by_uri.links[0].collisions[0].geometry.mesh_scale == pytest.approx((0.0254,) * 3)
    assert len(by_uri.warnings) == 2 and all("Y_UP" in w and "ignores" in w for w in by_uri.warnings)
    with pytest.raises(WorldError, match="not found"):
        load_model(tmp_path / "nothing")
    (tmp_path / "light.sdf").write_text('<sdf version="1.6"><light name="l" type="point"/></sdf>')
    with pytest.raises(WorldError, match=r"light\.sdf: no <model>"):
        load_model(tmp_path / "light.sdf")


def test_world_saved_by_gazebo_gui():
    """A world as Gazebo 9's "Save World" writes it: inline ground plane, <state> poses, GUI blocks."""
    world = load_world(FIX / "gazebo_saved.world")
    assert world.ground_plane and [m.name for m in world.models] == ["unit_box", "unit_cylinder"]
    box = world.models[0]
    assert not box.static and box.pose == pytest.approx((2, 1, 0.499995, 0, -1e-05, 0.3))  # from <state>
    assert box.links[0].inertial.ixx == pytest.approx(0.166667) and box.links[0].mu1 is None
    assert len(world.warnings) == 1 and "<scale>: 0.5 0.5 1 is not applied" in world.warnings[0]
