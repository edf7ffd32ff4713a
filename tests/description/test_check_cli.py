"""``navlab check robot|world``: summaries in text and JSON, errors as one line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from navlab.cli import main

FIX = Path(__file__).parents[1] / "fixtures"


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_check_robot_json(capsys):
    s = _json(capsys, ["check", "robot", "mybot", "--json"])
    assert s["name"] == "mybot" and s["root_link"] == "chassis"
    assert s["total_mass"] == pytest.approx(15.0, abs=1e-3)
    assert s["links"]["chassis"]["mass"] == 10
    assert {j["name"]: j["type"] for j in s["joints"]}["left_wheel_hinge"] == "continuous"
    assert s["diff_drive"]["wheel_separation"] == 0.4 and s["diff_drive"]["max_torque"] == 5.0  # wheelTorque default
    assert s["lidars"][0]["topic"] == "/mybot/laser/scan" and s["lidars"][0]["samples"] == 720
    assert s["warnings"] == []


def test_check_robot_text_lists_links_joints_plugins(capsys):
    assert main(["check", "robot", str(FIX / "turtlebot3_description/urdf/turtlebot3_burger.urdf.xacro")]) == 0
    out = capsys.readouterr().out
    for word in (
        "turtlebot3_burger",
        "base_footprint",
        "wheel_left_joint",
        "continuous",
        "diff drive",
        "lds_lfcd_sensor",
        "imu_plugin",
        "OK",
    ):
        assert word in out


def test_check_robot_xacro_arg_and_strict(tmp_path, capsys):
    f = tmp_path / "r.xacro"
    f.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:arg name="m" default="1"/>'
        '<link name="a"><inertial><mass value="$(arg m)"/></inertial></link></robot>'
    )
    s = _json(capsys, ["check", "robot", str(f), "--arg", "m:=3", "--json"])
    assert s["links"]["a"]["mass"] == 3
    assert main(["check", "robot", str(f), "--strict"]) == 1  # no diff drive: a warning
    capsys.readouterr()


def test_check_world_json(capsys):
    s = _json(capsys, ["check", "world", "room_obstacles", "--json"])
    assert s["name"] == "room_obstacles" and s["ground_plane"] is True
    assert len(s["models"]) == 9 and s["models"][0]["name"] == "room_walls"
    assert s["extents"] == {"x": [-5.1, 5.1], "y": [-4.1, 4.1]}


def test_check_world_model_path_reports_concave_mesh(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path))
    argv = ["check", "world", str(FIX / "worlds/mesh_world.world"), "--model-path", str(FIX / "worlds/models")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "concave collision mesh" in out and "l_wall.stl" in out
    s = _json(capsys, [*argv, "--json"])
    wall = next(m for m in s["models"] if m["name"] == "l_wall")
    assert wall["non_convex_meshes"] and wall["kinds"] == ["mesh"]


def test_check_world_error(tmp_path, capsys):
    f = tmp_path / "w.world"
    f.write_text('<sdf version="1.6"><world name="w"><include><uri>model://nope</uri></include></world></sdf>')
    assert main(["check", "world", str(f)]) == 2
    err = capsys.readouterr().err
    assert "w.world" in err and "model://nope" in err


def test_check_robot_by_package_uri(capsys):
    argv = [
        "check",
        "robot",
        "package://turtlebot3_description/urdf/turtlebot3_burger.urdf.xacro",
        "--package-path",
        str(FIX),
        "--json",
    ]
    assert _json(capsys, argv)["name"] == "turtlebot3_burger"
