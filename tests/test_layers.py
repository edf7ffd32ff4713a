"""The import-layer check (tools/check_layers.py): the real tree passes; planted violations fail it."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

REPO = Path(__file__).resolve().parent.parent
TOOL = REPO / "tools" / "check_layers.py"
SRC = REPO / "src" / "navlab"


def _load_tool() -> ModuleType:
    spec = importlib.util.spec_from_file_location("check_layers", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while the class is built
    spec.loader.exec_module(module)
    return module


check = _load_tool()


def _run(src: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(TOOL), str(src)], capture_output=True, text=True, check=False)


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A copy of src/navlab's Python files to plant imports in."""
    dst = tmp_path / "navlab"

    def ignore(folder: str, names: list[str]) -> list[str]:
        return [n for n in names if n == "__pycache__" or not (n.endswith(".py") or (Path(folder) / n).is_dir())]

    shutil.copytree(SRC, dst, ignore=ignore)
    return dst


def _plant(path: Path, line: str, *, in_function: bool = False) -> int:
    """Append an import (at module level or inside a function) to ``path``; returns its line number."""
    text = path.read_text() if path.exists() else ""
    if text and not text.endswith("\n"):
        text += "\n"
    lines = text.count("\n")
    if in_function:
        path.write_text(text + "\n\ndef _planted() -> None:\n    " + line + "\n")
        return lines + 4
    path.write_text(text + line + "\n")
    return lines + 1


def test_real_tree_passes():
    result = _run(SRC)
    assert result.stdout == "" and result.returncode == 0, result.stdout + result.stderr


def test_copy_passes_before_planting(tree):
    assert check.violations(tree) == []


def test_upward_import_inside_a_function_fails(tree):
    line = _plant(tree / "io" / "files.py", "from navlab.mapping.errors import MappingError", in_function=True)
    result = _run(tree)
    assert result.returncode == 1
    assert f"io/files.py:{line}: io.files -> mapping.errors (upward: io is layer 0" in result.stdout
    assert "import-layer violation" in result.stderr


def test_relative_and_plain_upward_imports_fail(tree):
    rel = _plant(tree / "core" / "tf.py", "from ..sim import simulation")
    plain = _plant(tree / "geometry.py", "import navlab.core.executor")
    found = "\n".join(check.violations(tree))
    assert f"core/tf.py:{rel}: core.tf -> sim.simulation (upward" in found
    assert f"geometry.py:{plain}: geometry -> core.executor (upward" in found


def test_two_packages_importing_each_other_fail(tree):
    # geometry and resources are both leaves: one importing the other is allowed sideways,
    # both importing each other is a circle
    a = _plant(tree / "geometry.py", "from navlab.resources import robot", in_function=True)
    assert check.violations(tree) == []
    b = _plant(tree / "resources" / "__init__.py", "from navlab.geometry import wrap_angle")
    found = check.violations(tree)
    assert any(
        v.endswith(f"geometry.py:{a}: geometry -> resources (circle: geometry and resources import each other)")
        for v in found
    )
    assert any(
        v.endswith(
            f"resources/__init__.py:{b}: resources -> geometry (circle: resources and geometry import each other)"
        )
        for v in found
    )
    assert len(found) == 2
    assert _run(tree).returncode == 1


def test_longer_cycle_within_a_layer_fails(tree):
    _plant(tree / "geometry.py", "import navlab.resources")
    _plant(tree / "resources" / "__init__.py", "import navlab.nodes")
    _plant(tree / "nodes.py", "from navlab import geometry")
    found = check.violations(tree)
    assert len(found) == 3
    assert all("circle: import cycle among geometry, nodes, resources" in v for v in found)


def test_cli_and_bench_sit_on_top_and_strings_are_not_imports(tree):
    # the cli and bench packages may import anything (through the packages' __init__s)
    _plant(tree / "cli" / "mapping.py", "from navlab.experiments import relations_error")
    _plant(tree / "bench" / "core.py", "from navlab.mapping import run_offline", in_function=True)
    # the registries and navlab/__init__.py name modules in strings: not imports
    _plant(tree / "nodes.py", 'LATER = "navlab.navigation.move_base:MoveBase"')
    assert check.violations(tree) == []
    # but cli or bench imported from below is an upward import
    line = _plant(tree / "mapping" / "slam.py", "from navlab.cli.mapping import register")
    assert any(f"mapping/slam.py:{line}: mapping.slam -> cli.mapping (upward" in v for v in check.violations(tree))
    line = _plant(tree / "sim" / "gazebo.py", "from navlab.bench import BENCHES", in_function=True)
    assert any(f"sim/gazebo.py:{line}: sim.gazebo -> bench (upward" in v for v in check.violations(tree))


def test_a_package_cli_module_is_no_exception(tree):
    # a cli.py inside a package belongs to its package: importing upward from it is reported
    line = _plant(tree / "mapping" / "cli.py", "from navlab.experiments import metrics")
    assert any(
        f"mapping/cli.py:{line}: mapping.cli -> experiments.metrics (upward" in v for v in check.violations(tree)
    )


def test_deep_import_into_another_package_fails(tree):
    """Each package's __init__ is its only public entry: a module of another package, imported directly
    (at module level or lazily, plainly or relatively), is reported; the same name from the __init__ is not."""
    fine = [
        _plant(tree / "mapping" / "slam.py", "from navlab.io import write_text_atomic"),
        _plant(tree / "sim" / "spawn.py", "from navlab.world import occupancy", in_function=True),  # a name too
        _plant(tree / "navigation" / "costmap" / "layer.py", "from navlab.navigation.planners import common"),
    ]
    assert fine and check.violations(tree) == []
    deep = _plant(tree / "mapping" / "slam.py", "from navlab.io.files import write_text_atomic", in_function=True)
    module = _plant(tree / "cli" / "sim.py", "from navlab.sim import decompose")
    plain = _plant(tree / "experiments" / "plots.py", "import navlab.navigation.costmap.footprint")
    relative = _plant(tree / "viz" / "hub.py", "from ..core.graph import Graph")
    found = check.violations(tree)
    assert found == [
        f"{tree}/cli/sim.py:{module}: cli.sim -> sim.decompose (deep: import it from navlab.sim, which exports "
        "it in sim/__init__.py)",
        f"{tree}/experiments/plots.py:{plain}: experiments.plots -> navigation.costmap.footprint (deep: import it "
        "from navlab.navigation, which exports it in navigation/__init__.py)",
        f"{tree}/mapping/slam.py:{deep}: mapping.slam -> io.files (deep: import it from navlab.io, which exports "
        "it in io/__init__.py)",
        f"{tree}/viz/hub.py:{relative}: viz.hub -> core.graph (deep: import it from navlab.core, which exports "
        "it in core/__init__.py)",
    ]


def test_deep_import_allowed_by_name(tree, monkeypatch):
    line = _plant(tree / "cli" / "sim.py", "from navlab.sim import decompose", in_function=True)
    assert [v for v in check.violations(tree) if f"cli/sim.py:{line}:" in v]
    monkeypatch.setitem(check.DEEP_ALLOWED, ("cli.sim", "sim.decompose"), "a test")
    assert check.violations(tree) == []


def test_package_in_no_layer_fails(tree):
    (tree / "planning").mkdir()
    (tree / "planning" / "__init__.py").write_text("from navlab.grid import Grid\n")
    found = check.violations(tree)
    assert any("package 'planning' is in no layer" in v for v in found)


def test_not_a_package_directory(tmp_path):
    result = _run(tmp_path)
    assert result.returncode == 2 and "not a package directory" in result.stderr
