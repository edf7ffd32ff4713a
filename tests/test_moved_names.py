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


def test_navlab_deprecations_are_errors_in_the_tests_and_others_are_not() -> None:
    """pyproject's filterwarnings: a use of an old form in a test fails it (outside pytest.warns); a
    third-party library's DeprecationWarning stays a warning."""
    import warnings

    from navlab.deprecation import NavlabDeprecationWarning

    with pytest.raises(NavlabDeprecationWarning):
        warnings.warn("old", NavlabDeprecationWarning, stacklevel=1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.warn("a library's", DeprecationWarning, stacklevel=1)
    assert [w.category for w in caught] == [DeprecationWarning]


def test_every_navlab_deprecation_warning_has_navlabs_category() -> None:
    """So the filter above catches them all: no plain DeprecationWarning is raised in src/navlab."""
    import ast
    from pathlib import Path

    def category(call: ast.Call) -> ast.expr | None:
        if not (isinstance(call.func, ast.Attribute) and call.func.attr == "warn"):  # warnings.warn(...)
            return None
        given = [k.value for k in call.keywords if k.arg == "category"] + call.args[1:2]
        return given[0] if given else None

    src = Path(__file__).resolve().parents[1] / "src" / "navlab"
    calls = [
        (f"{path.relative_to(src)}:{node.lineno}", category(node))
        for path in src.rglob("*.py")
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Call)
    ]
    plain = [where for where, cat in calls if isinstance(cat, ast.Name) and cat.id == "DeprecationWarning"]
    assert plain == [], plain
    assert sum(isinstance(c, ast.Name) and c.id == "NavlabDeprecationWarning" for _, c in calls) >= 9
