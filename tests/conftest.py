"""Fixtures shared by every test folder: installing a plugin package into this virtual environment."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from navlab.plugins import refresh_plugins


def _pip(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", "--quiet", *args], check=True,
                   capture_output=True, text=True, timeout=300)


@pytest.fixture
def install_plugin_package(tmp_path: Path) -> Iterator[Callable[..., None]]:
    """``install(dist, entry_points, modules={})``: write a package (``pyproject.toml`` declaring
    ``entry_points`` {group: {name: "module:attr"}}, plus ``modules`` {file name: source}) to a temporary
    folder and ``pip install`` it into this environment as a user would; uninstalled after the test."""
    installed: list[str] = []

    def install(dist: str, entry_points: dict[str, dict[str, str]], modules: dict[str, str] | None = None) -> None:
        root = tmp_path / dist
        root.mkdir()
        modules = modules or {}
        groups = "\n".join(f'[project.entry-points."{group}"]\n' + "".join(f'"{k}" = "{v}"\n' for k, v in eps.items())
                           for group, eps in entry_points.items())
        names = ", ".join(f'"{Path(m).stem}"' for m in modules)
        (root / "pyproject.toml").write_text(textwrap.dedent(f"""\
            [build-system]
            requires = ["setuptools>=70"]
            build-backend = "setuptools.build_meta"

            [project]
            name = "{dist}"
            version = "0.1.0"

            [tool.setuptools]
            py-modules = [{names}]

            """) + groups)
        for file, source in modules.items():
            (root / file).write_text(source)
        _pip("uninstall", "-y", dist)  # a leftover of an interrupted run
        _pip("install", "--no-deps", "--no-build-isolation", str(root))
        installed.append(dist)
        refresh_plugins()

    yield install
    for dist in installed:
        _pip("uninstall", "-y", dist)
    refresh_plugins()
