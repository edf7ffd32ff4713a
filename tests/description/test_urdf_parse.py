"""URDF details: every joint type, limits, dynamics, origins, materials, and the fixed links kept."""

from __future__ import annotations

import math

import pytest

from navlab.description import load_robot

INERTIA = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'


def test_joint_types_limits_dynamics(tmp_path):
    links = "".join(f'<link name="{n}">{INERTIA}</link>' for n in ("base", "a", "b", "c", "d", "e"))
    f = tmp_path / "arm.urdf"
    f.write_text(f"""<robot name="arm"><material name="steel"><color rgba="0.5 0.5 0.6 1"/></material>{links}
      <link name="tool"><visual><origin xyz="0 0 0.1" rpy="0 {math.pi / 2} 0"/><geometry><box size="0.1 0.2 0.3"/>
        </geometry><material name="steel"/></visual></link>
      <joint name="j_rev" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.5" rpy="0 0 1"/>
        <axis xyz="0 0 2"/><limit lower="-1.5" upper="1.5" effort="30" velocity="2"/>
        <dynamics damping="0.7" friction="0.1"/></joint>
      <joint name="j_pri" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
        <limit lower="0" upper="0.3" effort="100" velocity="0.5"/></joint>
      <joint name="j_cont" type="continuous"><parent link="b"/><child link="c"/><limit effort="5" velocity="9"/></joint>
      <joint name="j_float" type="floating"><parent link="c"/><child link="d"/></joint>
      <joint name="j_plan" type="planar"><parent link="d"/><child link="e"/><axis xyz="0 0 1"/></joint>
      <joint name="j_fix" type="fixed"><parent link="e"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>
    </robot>""")
    robot = load_robot(f)
    j = {joint.name: joint for joint in robot.joints}
    assert [joint.name for joint in robot.joints] == ["j_rev", "j_pri", "j_cont", "j_float", "j_plan", "j_fix"]
    rev = j["j_rev"]
    assert rev.type == "revolute" and rev.axis == (0.0, 0.0, 1.0)  # normalised
    assert (rev.lower, rev.upper, rev.effort, rev.velocity) == (-1.5, 1.5, 30, 2)
    assert (rev.damping, rev.friction) == (0.7, 0.1) and rev.origin.rpy == (0.0, 0.0, 1.0)
    assert j["j_pri"].type == "prismatic" and j["j_pri"].upper == 0.3
    assert j["j_cont"].lower is None and j["j_cont"].effort == 5  # continuous: no position limits
    assert j["j_float"].type == "floating" and j["j_plan"].type == "planar"
    assert j["j_fix"].type == "fixed" and "tool" in robot.links  # fixed links are kept, not merged
    (vis,) = robot.links["tool"].visuals
    assert vis.rgba == (0.5, 0.5, 0.6, 1.0) and vis.geometry.size == (0.1, 0.2, 0.3)
    assert vis.origin.xyz == (0.0, 0.0, 0.1) and vis.origin.rpy[1] == pytest.approx(math.pi / 2)
    assert robot.root_link == "base"
