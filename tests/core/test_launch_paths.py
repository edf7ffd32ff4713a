"""Paths resolve as ROS resolves them (issue 21): a relative path given on the command line is relative to the
current folder; a relative path written inside a launch file is relative to that file's folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from navlab.core.launch import start

LAUNCH = """launch:
- arg: {name: params, default: defaults}
- node: {pkg: navlab, exec: talker, name: talker, param: [{from: "$(var params)/talker.yaml"}]}
"""


@pytest.fixture
def layout(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "launches" / "defaults").mkdir(parents=True)
    (tmp_path / "launches" / "a.launch.yaml").write_text(LAUNCH)
    (tmp_path / "launches" / "defaults" / "talker.yaml").write_text("rate: 3.0\n")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "talker.yaml").write_text("rate: 7.0\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_a_relative_argument_is_relative_to_the_current_folder(layout: Path) -> None:
    session = start("launches/a.launch.yaml", params="mine")  # as `navlab launch launches/a.launch.yaml params:=mine`
    assert session.node("talker").get_parameter("rate") == 7.0


def test_a_relative_path_inside_the_file_is_relative_to_the_file(layout: Path) -> None:
    session = start("launches/a.launch.yaml")
    assert session.node("talker").get_parameter("rate") == 3.0
