"""Fixtures shared by every test folder (here at the repository root, not in tests/, so that the test
folders' own ``from conftest import ...`` stay the only first-party ``conftest`` for ruff's import sorting)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from navlab.io.datasets import dataset as find_dataset
from navlab.io.errors import DatasetNotFoundError
from navlab.plugins import refresh_plugins


@pytest.fixture
def dataset() -> Callable[[str], Path]:
    """``dataset("mit-csail/mit-csail.clf")`` -> its path under ``NAVLAB_DATA``; a missing dataset FAILS
    the test with a message saying where to put it (CI has the datasets, so a silent skip would hide a
    broken setup)."""

    def find(relpath: str) -> Path:
        try:
            return find_dataset(relpath)
        except DatasetNotFoundError as exc:
            pytest.fail(f"{exc} (CI has it)", pytrace=False)

    return find


def _pip(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", "--quiet", *args], check=True,
                   capture_output=True, text=True, timeout=300)


class PluginInstaller:
    """Installs plugin packages into this environment with pip, as a user would; uninstalls them at the end."""

    def __init__(self, tmp_path: Path) -> None:
        self.tmp_path = tmp_path
        self.installed: list[str] = []

    def __call__(self, dist: str, entry_points: dict[str, dict[str, str]],
                 modules: dict[str, str] | None = None) -> None:
        """Write a package declaring ``entry_points`` {group: {name: "module:attr"}}, plus ``modules`` {file
        name: source}, and install it."""
        root = self.tmp_path / dist
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
        self.install_dir(dist, root)

    def install_dir(self, dist: str, root: Path) -> None:
        """``pip install --no-deps --no-build-isolation ROOT`` (the package named ``dist``)."""
        _pip("uninstall", "-y", dist)  # a leftover of an interrupted run
        self.installed.append(dist)
        _pip("install", "--no-deps", "--no-build-isolation", str(root))
        refresh_plugins()

    def uninstall_all(self) -> None:
        for dist in self.installed:
            _pip("uninstall", "-y", dist)
        refresh_plugins()


@pytest.fixture
def install_plugin_package(tmp_path: Path) -> Iterator[PluginInstaller]:
    """``install(dist, entry_points, modules={})`` / ``install.install_dir(dist, root)``: a plugin package
    installed into this environment for the test (pip, no build isolation), uninstalled afterwards."""
    installer = PluginInstaller(tmp_path)
    yield installer
    installer.uninstall_all()
