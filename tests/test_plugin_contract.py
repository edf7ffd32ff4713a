"""The plugin contract: every registered plugin passes check_plugin; a package of one's own adds one by name."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

from navlab import plugins
from navlab.experiments.navigate_run import run_navigation
from navlab.navigation.controllers import DWAPlannerROS, TrajectoryPlannerROS
from navlab.navigation.plugin_check import check_plugin
from navlab.plugins import KINDS, ControlResult, PluginError, load_plugin, plugin_names

DOCS = Path(__file__).resolve().parents[1] / "docs" / "plugins.md"
EVERY_PLUGIN = [(kind, name) for kind in KINDS for name in plugin_names(kind)]


@pytest.mark.parametrize(("kind", "name"), EVERY_PLUGIN, ids=[f"{k}:{n}" for k, n in EVERY_PLUGIN])
def test_every_registered_plugin_passes_the_checker(kind: str, name: str) -> None:
    check_plugin(kind, name)


def test_navlab_registers_its_ros_names_and_the_short_aliases_resolve() -> None:
    assert {"navfn/NavfnROS", "nav2_theta_star_planner/ThetaStarPlanner"} <= set(plugin_names("global_planner"))
    assert {"costmap_2d::StaticLayer", "nav2_costmap_2d::InflationLayer"} <= set(plugin_names("costmap_layer"))
    assert load_plugin("controller", "dwa") is DWAPlannerROS
    assert load_plugin("controller", "trajectory") is TrajectoryPlannerROS
    with pytest.raises(PluginError, match=r"unknown base_local_planner 'dwaa' \(did you mean 'dwa'\?"):
        load_plugin("controller", "dwaa", param="base_local_planner")
    with pytest.deprecated_call():
        old = plugins.REGISTRY
    assert old["controller"]["dwa_local_planner/DWAPlannerROS"] == "navlab.navigation.controllers.dwa:DWAPlannerROS"


def test_a_control_result_reads_as_the_old_v_w_pair() -> None:
    r = ControlResult(0.2, -0.1, True, np.zeros((3, 3)))
    v, w = r
    assert (v, w) == (r[0], r[1]) == (0.2, -0.1) and r == (0.2, -0.1)
    with pytest.deprecated_call():
        assert ControlResult.of((0.3, 0.0)) == ControlResult(0.3, 0.0)


BROKEN = '''
import numpy as np


class TupleController:
    """Returns the old (v, w) tuple and has no is_goal_reached."""

    @classmethod
    def from_params(cls, params, *, context):
        return cls()

    def set_plan(self, path):
        pass

    def compute_velocity(self, pose, velocity, costmap):
        return 0.1, 0.0


class WallBlindLayer:
    """A costmap layer without from_params."""

    def update_costs(self, master):
        pass
'''


def test_the_checker_names_what_a_broken_plugin_lacks(install_plugin_package) -> None:
    install_plugin_package(
        "navlab-test-broken-plugins",
        {
            "navlab.controllers": {"broken/TupleController": "broken_plugins:TupleController"},
            "navlab.costmap_layers": {"broken::WallBlindLayer": "broken_plugins:WallBlindLayer"},
        },
        {"broken_plugins.py": BROKEN},
    )
    assert "broken/TupleController" in plugin_names("controller")
    with pytest.raises(PluginError, match=r"does not implement Controller: missing is_goal_reached"):
        check_plugin("controller", "broken/TupleController")
    with pytest.raises(PluginError, match=r"broken::WallBlindLayer.*no from_params"):
        check_plugin("costmap_layer", "broken::WallBlindLayer")


def _package_from_docs(root: Path) -> None:
    """The files of docs/plugins.md's example package (each block after its **`name`** line) under ``root``."""
    blocks = re.findall(r"\*\*`([\w.]+)`\*\*\n\n```\w*\n(.*?)```", DOCS.read_text(), flags=re.S)
    assert [name for name, _ in blocks] == ["pyproject.toml", "carrot_controller.py"]
    root.mkdir()
    for name, text in blocks:
        (root / name).write_text(text)


def test_a_third_party_package_adds_a_controller_navlab_drives_with_by_name(
    install_plugin_package, tmp_path: Path
) -> None:
    _package_from_docs(tmp_path / "my-nav-plugins")
    install_plugin_package.install_dir("my-nav-plugins", tmp_path / "my-nav-plugins")
    check_plugin("controller", "my_nav_plugins/CarrotController")
    r = run_navigation([(2.0, 0.5, 0.0)], world="room", controller="my_nav_plugins/CarrotController", goal_timeout=40)
    assert "carrot_controller" in sys.modules  # it was the package's controller that drove
    (goal,) = r.goals
    assert goal["outcome"] == "succeeded" and goal["collisions"] == 0, goal
