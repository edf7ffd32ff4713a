"""Issue 13: ROS robot and world files load as in Gazebo classic, through one resolver for
``package://`` and ``model://`` (fixtures: tests/fixtures/tutorial_bot_description, a Y_UP inch wall)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from navlab.cli import main
from navlab.description import DescriptionError, PackageIndex, load_robot
from navlab.description.errors import NotFoundError
from navlab.world import WorldError, load_world

FIX = Path(__file__).parents[1] / "fixtures"
PKG = FIX / "tutorial_bot_description"
URI = "package://tutorial_bot_description/urdf/tutorial_bot.urdf.xacro"
sys.path.insert(0, str(FIX))
from make_meshes import write_dae_box  # noqa: E402


@pytest.fixture(autouse=True)
def _env(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(FIX))
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)


def _world(path: Path, includes: str) -> Path:
    path.write_text(
        f'<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>{includes}</world></sdf>'
    )
    return path


def _model(root: Path, name: str, size: float) -> None:
    d = root / name
    d.mkdir(parents=True)
    (d / "model.config").write_text(f"<model><name>{name}</name><sdf version='1.6'>model.sdf</sdf></model>")
    (d / "model.sdf").write_text(
        f'<sdf version="1.6"><model name="{name}"><static>true</static><link name="l"><collision name="c">'
        f"<geometry><box><size>{size} {size} 1</size></box></geometry></collision></link></model></sdf>"
    )


def test_y_up_inch_dae_wall_stands_as_in_gazebo_and_check_warns(tmp_path, capsys):
    models = tmp_path / "models"
    write_dae_box(models / "wall" / "meshes" / "wall.dae", (80.0, 6.0, 40.0))  # Y_UP declared, Z-up vertices
    (models / "wall" / "model.config").write_text("<model><name>wall</name><sdf>model.sdf</sdf></model>")
    (models / "wall" / "model.sdf").write_text(
        '<sdf version="1.6"><model name="wall"><static>true</static><link name="l"><collision name="c">'
        "<geometry><mesh><uri>model://wall/meshes/wall.dae</uri></mesh></geometry></collision></link></model></sdf>"
    )
    world = load_world(_world(tmp_path / "w.world", "<include><uri>model://wall</uri></include>"), model_path=[models])
    geom = world.models[0].links[0].collisions[0].geometry
    from navlab.description.meshes import read_mesh

    verts = read_mesh(geom.mesh_path)[0] * np.asarray(geom.mesh_scale)
    extent = verts.max(axis=0) - verts.min(axis=0)
    assert extent == pytest.approx([80 * 0.0254, 6 * 0.0254, 40 * 0.0254])  # upright, 1.016 m tall, not lying
    assert verts.min(axis=0)[2] == pytest.approx(0.0)
    assert main(["check", "world", str(tmp_path / "w.world"), "--model-path", str(models), "--json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    assert any("<up_axis>Y_UP</up_axis>" in w and "ignores it" in w for w in warnings)


def test_package_uri_robot_loads_through_ros_package_path():
    robot = load_robot(URI)
    assert robot.name == "tutorial_bot" and robot.source == PKG / "urdf" / "tutorial_bot.urdf.xacro"
    assert robot.diff_drive is not None and robot.diff_drive.robot_base_frame == "base_link"


def test_swapped_joint_and_legacy_mode_messages_say_what_happens(capsys):
    assert main(["check", "robot", URI, "--arg", "legacy:=true", "--json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    (note,) = [w for w in warnings if "is the wheel on the right" in w]
    assert "turns the opposite way" in note and "as it does in Gazebo" in note
    (ignored,) = [w for w in warnings if "<legacyMode>" in w]  # Noetic does not read the tag: named, not used
    assert "removed" in ignored and "PR #707" in ignored
    for legacy in ("unset", "false"):  # no <legacyMode>, or false (what Noetic does anyway): only the joint note
        robot = load_robot(URI, args={"legacy": legacy})
        assert not any("legacyMode" in w for w in robot.warnings)


def test_missing_visual_mesh_warns_and_skips_but_missing_collision_mesh_is_an_error(tmp_path, capsys):
    robot = load_robot(URI, args={"visual_mesh": "gone.dae"})
    assert robot.links["base_link"].visuals == [] and robot.links["base_link"].collisions
    assert any("gone.dae not found; visual skipped" in w for w in robot.warnings)
    assert main(["check", "robot", URI, "--arg", "visual_mesh:=gone.dae"]) == 0
    assert "visual skipped" in capsys.readouterr().out
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        '<robot name="r"><link name="a"><inertial><mass value="1"/></inertial><collision><geometry>'
        '<mesh filename="gone.stl"/></geometry></collision></link></robot>'
    )
    with pytest.raises(NotFoundError, match=r"<collision>\[0\]/<geometry>/<mesh>: mesh file .*gone\.stl not found"):
        load_robot(urdf)


def test_model_uri_searches_every_folder_and_three_slashes(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    _model(first, "crate", 0.5)
    _model(second, "barrel", 0.7)
    world = load_world(
        _world(
            tmp_path / "w.world",
            "<include><uri>model://crate</uri></include><include><uri>model:///barrel</uri></include>",
        ),
        model_path=[first, second],
    )
    assert {m.name for m in world.models} == {"crate", "barrel"}
    index = PackageIndex(use_env=False)
    (second / "barrel" / "meshes").mkdir()
    (second / "barrel" / "meshes" / "m.stl").write_text("solid m\nendsolid m\n")
    # a file is looked for in every folder holding a model of that name, in order
    (first / "twin").mkdir()
    (second / "twin" / "meshes").mkdir(parents=True)
    (second / "twin" / "meshes" / "t.stl").write_text("solid t\nendsolid t\n")
    found = index.resolve_uri("model:///twin/meshes/t.stl", base_dir=tmp_path, model_paths=[first, second])
    assert found == second / "twin" / "meshes" / "t.stl"


def test_gazebo_model_path_export_and_missing_model_names_folders(tmp_path, monkeypatch):
    world = load_world(_world(tmp_path / "w.world", "<include><uri>model://pillar</uri></include>"))
    assert [m.name for m in world.models] == ["pillar"]  # found through package.xml's export
    with pytest.raises(WorldError) as err:
        load_world(
            _world(tmp_path / "x.world", "<include><uri>model://no_such_model</uri></include>"),
            model_path=[tmp_path / "a", tmp_path / "b"],
        )
    msg = str(err.value)
    assert "'no_such_model'" in msg and str(tmp_path / "a") in msg and str(tmp_path / "b") in msg
    assert str(PKG / "models") in msg


@pytest.mark.parametrize(
    "uri",
    [
        "package://tutorial_bot_description/../../../etc/passwd",
        "package://tutorial_bot_description/urdf/../../..",
        "model://../../etc/passwd",
        "model://pillar/../../../package.xml",
    ],
)
def test_uris_cannot_leave_their_package_or_model(tmp_path, uri):
    index = PackageIndex()
    with pytest.raises(DescriptionError, match=r"leaves its root|model name"):
        index.resolve_uri(uri, base_dir=tmp_path, model_paths=[PKG / "models"])
