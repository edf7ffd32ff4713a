"""Worlds cannot recurse without end (issue 21): nesting is bounded and include loops are refused in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from navlab.world import WorldError, load_world

HEAD = "<?xml version='1.0'?><sdf version='1.6'>"


def _model(folder: Path, name: str, includes: str) -> None:
    (folder / name).mkdir(parents=True)
    (folder / name / "model.config").write_text(f"<model><name>{name}</name><sdf>model.sdf</sdf></model>")
    (folder / name / "model.sdf").write_text(
        f"{HEAD}<model name='{name}'><include><uri>model://{includes}</uri></include><link name='l'/></model></sdf>"
    )


@pytest.mark.parametrize(("a_includes", "chain"), [("a", "model.sdf -> model.sdf"), ("b", "-> model.sdf")])
def test_include_loops_are_refused_naming_the_chain(tmp_path: Path, a_includes: str, chain: str) -> None:
    _model(tmp_path / "models", "a", a_includes)
    _model(tmp_path / "models", "b", "a")
    world = tmp_path / "w.world"
    world.write_text(f"{HEAD}<world name='w'><include><uri>model://a</uri></include></world></sdf>")
    with pytest.raises(WorldError, match="includes itself") as info:
        load_world(world, model_path=[tmp_path / "models"])
    assert chain in str(info.value) and "\n" not in str(info.value)


def test_models_nested_without_end_are_refused(tmp_path: Path) -> None:
    depth = 2000
    world = tmp_path / "deep.world"
    world.write_text(
        f"{HEAD}<world name='w'>"
        + "<model name='m'>" * depth
        + "<link name='l'/>"
        + "</model>" * depth
        + "</world></sdf>"
    )
    with pytest.raises(WorldError, match="nest deeper than 32 levels"):
        load_world(world)
    shallow = tmp_path / "shallow.world"
    shallow.write_text(
        f"{HEAD}<world name='w'>" + "<model name='m'>" * 5 + "<link name='l'/>" + "</model>" * 5 + "</world></sdf>"
    )
    (model,) = load_world(shallow).models
    assert model.links[0].name == "m::m::m::m::l"
