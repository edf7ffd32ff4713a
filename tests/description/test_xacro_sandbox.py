"""A robot description is data (issue 14): xacro expressions cannot run code or read files outside the package."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from navlab import resources
from navlab.description import DescriptionError, load_robot

# the bypass seen in the issue: reflection through xacro's exposed `python.vars`/`python.type` reaches the
# globals of a xacro function and from there `os.system`
ESCAPE = (
    "python.vars(python.type(python.vars(python.type(xacro.fatal))['__globals__']))['__get__']"
    "(python.vars(python.type(xacro.fatal))['__globals__'], xacro.fatal)['os'].system('touch {marker}')"
)


@pytest.fixture
def package(tmp_path: Path) -> Path:
    """A copy of the shipped tb3_burger package to add lines to."""
    dst = tmp_path / "pkg"
    shutil.copytree(resources.robot("tb3_burger").parent, dst)
    return dst


def _add(package: Path, line: str) -> Path:
    top = package / "tb3_burger.xacro"
    top.write_text(top.read_text().replace("</robot>", line + "\n</robot>"))
    return top


@pytest.mark.parametrize(
    "expression",
    [
        ESCAPE,
        "__import__('os').system('touch {marker}')",
        "python.vars(python)['open']('{marker}', 'w')",
        "python['ty' + 'pe'](1).mro()[-1]",
        "'{{0.__class__}}'.format(1)",
        # issue 21: a generator's frame walked to a navlab module's globals
        "[*(g := (g.gi_frame.f_back.f_back.f_globals['os'].system('touch {marker}') for _ in [1]))]",
        "python.isinstance(1, int) and xacro.tokenize.__globals__['os'].system('touch {marker}')",
    ],
)
def test_expressions_cannot_run_commands(package: Path, tmp_path: Path, expression: str) -> None:
    marker = tmp_path / "escaped"
    top = _add(package, f'<fuzz v="${{{expression.format(marker=marker)}}}"/>')
    with pytest.raises(DescriptionError, match=r"tb3_burger\.xacro: xacro error"):
        load_robot(top)
    assert not marker.exists()


def test_eval_substitution_has_no_builtins(package: Path) -> None:
    top = _add(package, '<fuzz v="$(eval open)"/>')  # xacro's lexer ends $(...) at the first ')'
    with pytest.raises(DescriptionError, match=r"name 'open' is not defined"):
        load_robot(top)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("<fuzz v=\"${xacro.load_yaml('/etc/passwd')}\"/>", r"/etc/passwd is outside the robot's package"),
        ('<xacro:include filename="/etc/hostname"/>', r"/etc/hostname is outside the robot's package"),
        (
            '<xacro:include filename="$(find navlab_tb3_burger_description)/../../../../etc/hostname"/>',
            r"is outside the robot's package",
        ),
        ('<xacro:include filename="tb3_burger.xacro"/>', r"includes itself"),
    ],
)
def test_files_outside_the_package_and_include_loops_are_refused(package: Path, line: str, message: str) -> None:
    with pytest.raises(DescriptionError, match=message):
        load_robot(_add(package, line))


def test_entities_are_refused_and_yaml_inside_the_package_still_loads(package: Path) -> None:
    (package / "dims.yaml").write_text("radius: 0.25\n")
    top = _add(
        package,
        '<xacro:property name="dims" value="${xacro.load_yaml(\'dims.yaml\')}"/>'
        "<material name=\"extra_${int(dims['radius'] * 100)}\"/>",
    )
    assert "extra_25" in load_robot(top).urdf_xml
    text = top.read_text()
    top.write_text(
        text.replace(
            '<?xml version="1.0"?>',
            '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
            1,
        )
    )
    with pytest.raises(DescriptionError, match=r"DOCTYPE/ENTITY declarations are not allowed"):
        load_robot(top)


def test_what_xacro_documents_still_expands(package: Path) -> None:
    """Namespaces, YAML dotted access, xacro's python/math namespaces, conditionals and $(eval ...) with args."""
    (package / "dims.yaml").write_text("wheel: {radius: 0.25, names: [left, right]}\n")
    top = _add(
        package,
        '<xacro:arg name="scale" default="2"/>'
        '<xacro:property name="dims" value="${xacro.load_yaml(\'dims.yaml\')}"/>'
        '<xacro:property name="k" value="$(eval 3 * scale + 2)"/>'
        '<material name="m_${int(dims.wheel.radius * 100)}_${dims.wheel.names[1]}_${python.len(dims.wheel)}'
        "_${k}_${'yes' if math.pi > 3 else 'no'}_${'%.1f' % radians(180)}_${xacro.arg('scale')}\"/>",
    )
    assert 'material name="m_25_right_2_8_yes_3.1_2"' in load_robot(top).urdf_xml
