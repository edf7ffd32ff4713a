"""Mesh files: STL/OBJ reading, COLLADA conversion with units and up axis, convexity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from navlab.description import DescriptionError, load_robot
from navlab.description.meshes import dae_to_obj, is_convex, read_dae, read_mesh

FIX = Path(__file__).parents[1] / "fixtures"
DAE = FIX / "worlds" / "models" / "inch_box" / "meshes" / "box.dae"
LWALL = FIX / "worlds" / "models" / "l_wall" / "meshes" / "l_wall.stl"


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))


def test_binary_stl_extents_in_millimetres():
    verts, faces = read_mesh(FIX / "turtlebot3_description" / "meshes" / "bases" / "burger_base.stl")
    assert faces.shape == (12, 3)
    assert np.ptp(verts, axis=0) == pytest.approx([140, 140, 180])


def test_ascii_stl_and_obj(tmp_path):
    stl = tmp_path / "t.stl"
    stl.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 2 0\n"
        "endloop\nendfacet\nendsolid t\n"
    )
    verts, faces = read_mesh(stl)
    assert verts[faces[0]].tolist() == [[0, 0, 0], [1, 0, 0], [0, 2, 0]]
    obj = tmp_path / "q.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n")
    verts, faces = read_mesh(obj)
    assert len(faces) == 2  # the quad fan-triangulated


def test_dae_units_up_axis_and_node_transform():
    verts, faces, unit = read_dae(DAE)
    assert unit == pytest.approx(0.0254)
    assert len(faces) == 12
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    # 20 x 10 x 30 inches; the file declares Y_UP but, as in Gazebo classic, it is not turned: the
    # box stands 30 in tall, lifted by its node <translate> to stand on z = 0
    assert hi - lo == pytest.approx([20, 10, 30])
    assert lo[2] == pytest.approx(0) and (lo[:2] + hi[:2]) == pytest.approx([0, 0])


def test_dae_converted_once_to_cached_obj():
    obj, unit = dae_to_obj(DAE)
    assert obj.suffix == ".obj" and obj.exists() and unit == pytest.approx(0.0254)
    mtime = obj.stat().st_mtime_ns
    again, _ = dae_to_obj(DAE)
    assert again == obj and obj.stat().st_mtime_ns == mtime
    v_obj, _ = read_mesh(obj)
    v_dae, _, _ = read_dae(DAE)
    assert np.allclose(v_obj, v_dae)


def test_urdf_dae_mesh_scale_includes_collada_unit(tmp_path):
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        f'<robot name="r"><link name="a"><inertial><mass value="1"/></inertial>'
        f'<collision><geometry><mesh filename="file://{DAE}" scale="2 2 2"/></geometry></collision>'
        f"</link></robot>"
    )
    geom = load_robot(urdf).links["a"].collisions[0].geometry
    assert geom.mesh_source == DAE and geom.mesh_path.suffix == ".obj"
    assert geom.mesh_scale == pytest.approx((0.0508, 0.0508, 0.0508))


def test_malformed_dae_names_file(tmp_path):
    bad = tmp_path / "bad.dae"
    bad.write_text("<COLLADA><asset>")
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        '<robot name="r"><link name="a"><inertial><mass value="1"/></inertial>'
        '<visual><geometry><mesh filename="bad.dae"/></geometry></visual></link></robot>'
    )
    with pytest.raises(DescriptionError, match=r'<link name="a">.*bad\.dae: malformed COLLADA'):
        load_robot(urdf)


def test_convexity():
    box = read_mesh(FIX / "turtlebot3_description" / "meshes" / "bases" / "burger_base.stl")
    assert is_convex(*box)
    tire = read_mesh(FIX / "turtlebot3_description" / "meshes" / "wheels" / "left_tire.stl")
    assert is_convex(*tire)
    lwall = read_mesh(LWALL)
    assert not is_convex(*lwall)


def test_dae_polylist_matrix_and_instance_node(tmp_path):
    """A quad as <polylist>, placed by a <matrix> node that instantiates a library node, Z up."""
    dae = tmp_path / "quad.dae"
    dae.write_text("""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="q"><mesh>
    <source id="p"><float_array id="pa" count="12">0 0 0 10 0 0 10 20 0 0 20 0</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3"/></technique_common></source>
    <source id="n"><float_array id="na" count="3">0 0 1</float_array></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <polylist count="1"><input semantic="VERTEX" source="#v" offset="0"/>
      <input semantic="NORMAL" source="#n" offset="1"/><vcount>4</vcount><p>0 0 1 0 2 0 3 0</p></polylist>
  </mesh></geometry></library_geometries>
  <library_nodes><node id="part"><instance_geometry url="#q"/></node></library_nodes>
  <library_visual_scenes><visual_scene id="s">
    <node><matrix>1 0 0 100  0 1 0 0  0 0 1 5  0 0 0 1</matrix><instance_node url="#part"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>""")
    verts, faces, unit = read_dae(dae)
    assert unit == 0.001 and faces.shape == (2, 3)
    assert verts.min(axis=0) == pytest.approx([100, 0, 5]) and verts.max(axis=0) == pytest.approx([110, 20, 5])
