"""Bad robot descriptions raise DescriptionError naming the file and the element."""

from __future__ import annotations

import pytest

from navlab.description import DescriptionError, load_robot

INERTIA = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'


def _write(tmp_path, text: str, name: str = "bad.urdf.xacro"):
    f = tmp_path / name
    f.write_text(text)
    return f


def _robot(body: str) -> str:
    return f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}</robot>'


@pytest.mark.parametrize(
    "body,pattern",
    [
        # malformed XML
        ('<link name="a">' + INERTIA, r"bad\.urdf\.xacro.*malformed XML"),
        # an undefined xacro property
        ('<link name="a"><inertial><mass value="${wheel_mass}"/></inertial></link>', r"bad\.urdf\.xacro.*wheel_mass"),
        # an unknown ROS package
        ('<xacro:include filename="$(find no_such_pkg)/x.xacro"/>', r"bad\.urdf\.xacro.*no_such_pkg"),
        # a missing include
        ('<xacro:include filename="parts/missing.xacro"/>', r"missing\.xacro"),
        # moving link without inertial
        (
            f'<link name="base">{INERTIA}</link><link name="wheel"/>'
            '<joint name="j" type="continuous"><parent link="base"/><child link="wheel"/></joint>',
            r'bad\.urdf\.xacro.*<link name="wheel">.*no <inertial>',
        ),
        # the floating root without mass
        ('<link name="base"/>', r'<link name="base">.*root link'),
        # joint type
        (
            f'<link name="a">{INERTIA}</link><link name="b">{INERTIA}</link>'
            '<joint name="j" type="hinge"><parent link="a"/><child link="b"/></joint>',
            r'<joint name="j">: type \'hinge\'',
        ),
        # joint naming a missing link
        (
            f'<link name="a">{INERTIA}</link>'
            '<joint name="j" type="fixed"><parent link="a"/><child link="ghost"/></joint>',
            r'<joint name="j">/<child>: link \'ghost\' is not defined',
        ),
        # a bad number
        (
            f'<link name="a">{INERTIA}<collision><origin xyz="0 0 zero"/><geometry><box size="1 1 1"/>'
            "</geometry></collision></link>",
            r'<link name="a">/<collision>\[0\]/<origin>: attribute xyz',
        ),
        # a box with two sizes
        (
            f'<link name="a">{INERTIA}<collision><geometry><box size="1 1"/></geometry></collision></link>',
            r'<link name="a">/<collision>\[0\]/<geometry>/<box>: attribute size: expected 3 numbers',
        ),
        # negative radius
        (
            f'<link name="a">{INERTIA}<visual><geometry><sphere radius="-1"/></geometry></visual></link>',
            r"<sphere>: sizes must be positive",
        ),
        # revolute joint without limit
        (
            f'<link name="a">{INERTIA}</link><link name="b">{INERTIA}</link>'
            '<joint name="arm" type="revolute"><parent link="a"/><child link="b"/></joint>',
            r'<joint name="arm">: a revolute joint needs <limit',
        ),
        # two roots
        (f'<link name="a">{INERTIA}</link><link name="b">{INERTIA}</link>', r"one root; roots found: \['a', 'b'\]"),
        # negative mass
        ('<link name="a"><inertial><mass value="-2"/></inertial></link>', r"<inertial>/<mass>: mass must be >= 0"),
        # a missing collision mesh (a missing visual mesh only warns, as in Gazebo: tests/description/test_ros_files.py)
        (
            f'<link name="a">{INERTIA}<collision><geometry><mesh filename="meshes/gone.stl"/></geometry></collision>'
            "</link>",
            r'<link name="a">/<collision>\[0\]/<geometry>/<mesh>: mesh file .*gone\.stl not found',
        ),
    ],
)
def test_bad_input_names_file_and_element(tmp_path, body, pattern):
    with pytest.raises(DescriptionError, match=pattern):
        load_robot(_write(tmp_path, _robot(body)))


def test_missing_package_mesh_names_package(tmp_path):
    body = (
        f'<link name="a">{INERTIA}<collision><geometry><mesh filename="package://ghost_pkg/m.stl"/></geometry>'
        "</collision></link>"
    )
    with pytest.raises(DescriptionError, match="ghost_pkg"):
        load_robot(_write(tmp_path, _robot(body)))


def test_error_in_included_file_names_that_file(tmp_path):
    (tmp_path / "part.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="x"><inertial><mass value="${oops}"/></inertial></link></robot>'
    )
    with pytest.raises(DescriptionError, match=r"part\.xacro"):
        load_robot(_write(tmp_path, _robot('<xacro:include filename="part.xacro"/>')))


def test_missing_file():
    with pytest.raises(DescriptionError, match=r"nowhere\.xacro: robot description file not found"):
        load_robot("/nowhere.xacro")


def test_cli_prints_one_line_error(tmp_path, capsys):
    from navlab.cli import main

    f = _write(tmp_path, _robot('<link name="a">'))
    assert main(["check", "robot", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("navlab: error:") and "bad.urdf.xacro" in err and "\n" not in err
