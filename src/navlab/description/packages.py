"""ROS package look-up and resource URIs: ``$(find pkg)``, ``package://pkg/...``, ``file://``, ``model://``.

A :class:`PackageIndex` is built per load from, in order of precedence: the search paths the user
gave, the ``ROS_PACKAGE_PATH`` environment variable, the packages above the loaded file (walking up
to a ``package.xml``), and the descriptions shipped with navlab (``mybot_description``). A search
path may be a package directory itself or a directory holding packages (searched a few levels deep,
as ``rospack`` does).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping
from pathlib import Path

from navlab import resources
from navlab.description.errors import DescriptionError

_MAX_DEPTH = 4  # directory levels searched below each search path
_SKIP_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")


def package_name(package_dir: Path) -> str | None:
    """The ``<name>`` in ``package_dir/package.xml`` (or the directory name for a ``manifest.xml``)."""
    pkg_xml = package_dir / "package.xml"
    if pkg_xml.is_file():
        try:
            name = ET.parse(pkg_xml).getroot().findtext("name")
        except ET.ParseError as exc:
            raise DescriptionError(f"{pkg_xml}: malformed package.xml ({exc})") from None
        return name.strip() if name else None
    if (package_dir / "manifest.xml").is_file():
        return package_dir.name
    return None


def crawl(root: Path, depth: int = _MAX_DEPTH) -> dict[str, Path]:
    """Packages at or below ``root`` (a package's own subdirectories are not searched further)."""
    found: dict[str, Path] = {}
    if not root.is_dir() or any((root / m).exists() for m in _SKIP_MARKERS):
        return found
    name = package_name(root)
    if name:
        found[name] = root.resolve()
        return found
    if depth <= 0:
        return found
    try:
        children = sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith("."))
    except OSError:
        return found
    for child in children:
        for pkg, path in crawl(child, depth - 1).items():
            found.setdefault(pkg, path)
    return found


def _walk_up(start: Path) -> dict[str, Path]:
    """Every package directory above (and including) ``start``, nearest first."""
    found: dict[str, Path] = {}
    here = start.resolve()
    for d in (here, *here.parents):
        name = package_name(d)
        if name:
            found.setdefault(name, d)
    return found


class PackageIndex:
    """Maps ROS package names to directories and resolves resource URIs to absolute paths."""

    def __init__(
        self,
        search_paths: Iterable[str | os.PathLike[str]] = (),
        *,
        near: Path | None = None,
        extra: Mapping[str, Path] | None = None,
        use_env: bool = True,
    ) -> None:
        """Build the index. ``near``: a file whose enclosing packages are found by walking up."""
        self.packages: dict[str, Path] = {}
        self._roots: list[Path] = [Path(p).expanduser() for p in search_paths]
        if use_env:
            env = os.environ.get("ROS_PACKAGE_PATH", "")
            self._roots += [Path(p) for p in env.split(os.pathsep) if p]
        for root in self._roots:
            for name, path in crawl(root).items():
                self.packages.setdefault(name, path)
        if near is not None:
            for name, path in _walk_up(near.parent if near.is_file() else near).items():
                self.packages.setdefault(name, path)
        for name, path in (extra or {}).items():
            self.packages.setdefault(name, Path(path))
        for name, path in resources.package_paths().items():
            self.packages.setdefault(name, path)

    def find(self, name: str) -> Path:
        """The directory of package ``name``; DescriptionError listing where it looked if unknown."""
        try:
            return self.packages[name]
        except KeyError:
            where = ", ".join(str(r) for r in self._roots) or "no search paths"
            raise DescriptionError(
                f"ROS package {name!r} not found (searched {where}, ROS_PACKAGE_PATH and the shipped "
                f"packages {', '.join(sorted(resources.package_paths()))}); pass its parent directory "
                "in search_paths / --package-path"
            ) from None

    def resolve_uri(self, uri: str, *, base_dir: Path, model_paths: Iterable[Path] = ()) -> Path:
        """Absolute path of ``package://``, ``file://``, ``model://``, absolute or relative ``uri``.

        Relative paths are taken relative to ``base_dir`` (the file that names them). The path is
        not checked for existence here.
        """
        uri = uri.strip()
        if uri.startswith("package://"):
            rest = uri[len("package://") :]
            pkg, _, rel = rest.partition("/")
            return self.find(pkg) / rel
        if uri.startswith("file://"):
            return Path(uri[len("file://") :])
        if uri.startswith("model://"):
            rest = uri[len("model://") :]
            model, _, rel = rest.partition("/")
            for root in model_paths:
                if (Path(root) / model).is_dir():
                    return Path(root) / model / rel
            if model in self.packages:  # ROS packages double as model directories in gazebo_ros
                return self.packages[model] / rel
            return base_dir / model / rel
        path = Path(uri)
        return path if path.is_absolute() else base_dir / path
