"""Issue 13: a ``package://`` robot through every verb that spawns one, and start poses refused inside
obstacles (fixture: tests/fixtures/tutorial_bot_description, found through ROS_PACKAGE_PATH)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from navlab.cli import main

FIX = Path(__file__).parents[1] / "fixtures"
ROBOT = "package://tutorial_bot_description/urdf/tutorial_bot.urdf.xacro"


@pytest.fixture(autouse=True)
def _env(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVLAB_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(FIX))


def test_package_robot_through_sim_render_launch_map_and_navigate(tmp_path, capsys):
    assert main(["sim", "--robot", ROBOT, "--duration", "0.5", "--cmd-vel", "0.3,0", "--quiet", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["robot"] == "tutorial_bot" and out["messages"]["/tutorial_bot/laser/scan"] >= 9
    assert main(["launch", "sim", f"robot:={ROBOT}", "--duration", "0.3", "--quiet", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["topics"]["/tutorial_bot/laser/scan"] >= 5
    assert main(["map", "--robot", ROBOT, "--duration", "2", "--out", str(tmp_path / "map"), "--quiet", "--json"]) == 0
    assert (tmp_path / "map" / "map.yaml").is_file()
    capsys.readouterr()
    code = main(["navigate", "--robot", ROBOT, "--goal", "0.5", "0", "0", "--timeout", "3", "--json"])
    assert code in (0, 1)  # reached or not in 3 s: the robot loaded and the stack ran
    assert "Traceback" not in capsys.readouterr().err
    code = main(["render", "--robot", ROBOT, "--out", str(tmp_path / "r.png"), "--width", "64", "--height", "48"])
    err = capsys.readouterr().err
    if code == 2 and "cannot render offscreen" in err:
        pytest.skip("no offscreen OpenGL here (every other verb loaded the package:// robot)")
    assert code == 0 and (tmp_path / "r.png").stat().st_size > 100


@pytest.mark.parametrize(
    "argv",
    [
        ["sim", "--x", "4.95", "--duration", "0.2", "--quiet"],
        ["render", "--x", "4.95", "--out", "never.png"],
        ["launch", "sim", "x:=4.95", "--duration", "0.2", "--quiet"],
        ["map", "--x", "4.95", "--duration", "1", "--quiet"],
    ],
)
def test_start_pose_inside_a_wall_is_refused_with_a_message(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "start pose x=4.95" in err and "inside 'room_walls'" in err and "Traceback" not in err
    assert not (tmp_path / "never.png").exists()


def test_package_and_model_path_options(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ROS_PACKAGE_PATH", "")
    monkeypatch.setenv("GAZEBO_MODEL_PATH", "")
    world = tmp_path / "w.world"
    world.write_text(
        '<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>'
        "<include><uri>model:///pillar</uri><pose>2 0 0 0 0 0</pose></include></world></sdf>"
    )
    models = FIX / "tutorial_bot_description" / "models"
    assert main(["sim", "--robot", ROBOT, "--world", str(world), "--duration", "0.2", "--quiet", "--json"]) == 2
    assert "tutorial_bot_description" in capsys.readouterr().err  # the package is named in the error
    assert (
        main(
            [
                "sim",
                "--robot",
                ROBOT,
                "--world",
                str(world),
                "--package-path",
                str(FIX),
                "--model-path",
                str(models),
                "--duration",
                "0.2",
                "--quiet",
                "--json",
            ]
        )
        == 0
    )
    assert "pillar" in json.loads(capsys.readouterr().out)["models"]


def test_map_with_package_and_model_path_options(tmp_path, monkeypatch, capsys):
    """A package:// robot and a model:/// world through ``navlab map`` with --package-path and
    --model-path only (nothing in ROS_PACKAGE_PATH / GAZEBO_MODEL_PATH)."""
    monkeypatch.setenv("ROS_PACKAGE_PATH", "")
    monkeypatch.setenv("GAZEBO_MODEL_PATH", "")
    models = tmp_path / "models"
    (models / "crate").mkdir(parents=True)  # a model no package exports: found through --model-path only
    pillar = FIX / "tutorial_bot_description" / "models" / "pillar"
    (models / "crate" / "model.config").write_text((pillar / "model.config").read_text().replace("pillar", "crate"))
    (models / "crate" / "model.sdf").write_text((pillar / "model.sdf").read_text().replace("pillar", "crate"))
    world = tmp_path / "w.world"
    world.write_text(
        '<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>'
        "<include><uri>model:///crate</uri><pose>1.5 0 0 0 0 0</pose></include></world></sdf>"
    )
    argv = [
        "map",
        "--robot",
        ROBOT,
        "--world",
        str(world),
        "--duration",
        "2",
        "--out",
        str(tmp_path / "m"),
        "--quiet",
        "--json",
    ]
    assert main(argv) == 2
    assert "tutorial_bot_description" in capsys.readouterr().err  # not found without the options
    assert main([*argv, "--package-path", str(FIX), "--model-path", str(models)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["scans_processed"] > 0 and not out["map_empty"]  # the laser saw the crate


@pytest.mark.parametrize(
    "verb",
    [
        ["navigate", "--goal", "1", "0", "0"],
        ["localize"],
        ["launch", "mapping"],
        ["view"],
        ["experiment", "run", "empty_room"],
        ["eval", "map", "m.yaml", "--world", "room"],
    ],
)
def test_every_robot_verb_takes_the_path_options(verb):
    from navlab.cli import build_parser

    args = build_parser().parse_args([*verb, "--package-path", "/p", "--model-path", "/m"])
    assert args.package_path == ["/p"] and args.model_path == ["/m"]
