"""Names that moved in the house refactor (issue 26) still work from their old place for one release, with a
DeprecationWarning, and give what the new place gives."""

from __future__ import annotations

import importlib
import sys

import pytest


def test_world_truth_moved_from_experiments() -> None:
    import navlab.world as world

    sys.modules.pop("navlab.experiments.truth", None)
    with pytest.warns(DeprecationWarning, match="navlab.experiments.truth moved to navlab.world"):
        old = importlib.import_module("navlab.experiments.truth")
    assert old.true_map is world.true_map and old.world_T_map is world.world_T_map


def test_loaders_moved_from_sim_to_description_and_world() -> None:
    from navlab import sim
    from navlab.description import load_robot_named
    from navlab.world import load_world

    with pytest.warns(DeprecationWarning, match="navlab.description"):
        robot = sim.load_robot_named("mybot", ["unused"])
    assert robot.name == load_robot_named("mybot").name
    with pytest.warns(DeprecationWarning, match="navlab.world.load_world"):
        world = sim.load_world_named("room")
    assert [m.name for m in world.models] == [m.name for m in load_world("room").models]


@pytest.mark.parametrize(
    ("old", "name", "new"),
    [
        ("navlab.mapping.explore", "plan_to_frontier", "navlab.drivers.frontiers"),
        ("navlab.mapping.explore_node", "Explore", "navlab.drivers.explore"),
        ("navlab.mapping.follow", "PurePursuit", "navlab.navigation.controllers.pure_pursuit"),
        ("navlab.mapping.teleop", "TeleopKeyboard", "navlab.drivers.teleop"),
        ("navlab.mapping.teleop", "load_route", "navlab.drivers.routes"),
    ],
)
def test_drivers_moved_out_of_mapping(old: str, name: str, new: str) -> None:
    with pytest.warns(DeprecationWarning, match=f"{old}.{name} moved to {new}.{name}"):
        got = getattr(importlib.import_module(old), name)
    assert got is getattr(importlib.import_module(new), name)
    with pytest.raises(AttributeError, match="ClearanceLayer"):
        importlib.import_module("navlab.mapping.explore").ClearanceLayer  # noqa: B018 - gone, not moved
