"""ROS package look-up and resource URIs: ``$(find pkg)``, ``package://pkg/...``, ``file://``, ``model://``.

A :class:`PackageIndex` is built per load from, in order of precedence: the search paths the user
gave, the ``ROS_PACKAGE_PATH`` environment variable, the packages above the loaded file (walking up
to a ``package.xml``), and the descriptions shipped with navlab (``mybot_description``). A search
path may be a package directory itself or a directory holding packages (searched a few levels deep,
as ``rospack`` does).

It is the one resolver of every verb: robot files, meshes, world includes and spawned models all
go through :meth:`PackageIndex.resolve_uri` / :meth:`PackageIndex.find_model`. ``model://name/...``
(and ``model:///name/...``) is looked up in every folder of the model path in order (the folders
given, ``GAZEBO_MODEL_PATH``, then the ``<export><gazebo_ros gazebo_model_path="..."/>`` folders of
the indexed packages, as gazebo_ros adds them), and the first folder holding the file wins. A URI
cannot leave its root: ``package://pkg/../..`` and ``model://../..`` are refused.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping
from pathlib import Path

from navlab import resources
from navlab.description.errors import DescriptionError, NotFoundError

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


def gazebo_model_paths(package_dir: Path) -> list[Path]:
    """The ``gazebo_model_path`` folders a package exports (``<export><gazebo_ros
    gazebo_model_path="${prefix}/models"/>``; ``${prefix}`` is the package directory)."""
    pkg_xml = package_dir / "package.xml"
    if not pkg_xml.is_file():
        return []
    try:
        root = ET.parse(pkg_xml).getroot()
    except ET.ParseError:
        return []
    out = []
    for el in root.findall("export/gazebo_ros"):
        for entry in (el.get("gazebo_model_path") or "").split(os.pathsep):
            entry = entry.strip().replace("${prefix}", str(package_dir)).replace("$(prefix)", str(package_dir))
            if entry:
                p = Path(entry)
                out.append(p if p.is_absolute() else package_dir / p)
    return out


def join_inside(root: Path, rel: str, uri: str) -> Path:
    """``root / rel``, refusing a ``rel`` that leaves ``root`` (``..`` segments or an absolute path)."""
    joined = Path(os.path.normpath(root / rel.lstrip("/"))) if rel.strip("/") else root
    base = Path(os.path.normpath(root))
    if joined != base and base not in joined.parents:
        raise DescriptionError(f"{uri!r}: the path leaves its root {root} (no '..' above a package or model)")
    return joined


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
        self._exported: list[Path] | None = None
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

    def exported_model_paths(self) -> list[Path]:
        """Every indexed package's exported ``gazebo_model_path`` folders (read on first use)."""
        if self._exported is None:
            self._exported = []
            for pkg in self.packages.values():
                self._exported += [p for p in gazebo_model_paths(pkg) if p not in self._exported]
        return self._exported

    def model_search_path(self, model_paths: Iterable[str | os.PathLike[str]] = ()) -> list[Path]:
        """The folders ``model://`` searches, in order: ``model_paths``, then the packages' exports."""
        out: list[Path] = []
        for p in [*(Path(m).expanduser() for m in model_paths), *self.exported_model_paths()]:
            if p not in out:
                out.append(p)
        return out

    def find_model(
        self, uri: str, model_paths: Iterable[str | os.PathLike[str]] = (), *, need_file: bool = False
    ) -> Path:
        """The path a ``model://name[/rel]`` (or ``model:///name/rel``) URI names: the first folder of
        the model search path holding ``name`` (and ``rel``, when ``need_file``); else a ROS package
        called ``name`` (gazebo_ros serves packages as models). NotFoundError names the model and
        every folder searched."""
        rest = uri.strip()[len("model://") :].lstrip("/")
        name, _, rel = rest.partition("/")
        if not name or name in (".", ".."):
            raise DescriptionError(f"{uri!r}: expected model://NAME/... with a model name")
        searched = self.model_search_path(model_paths)
        first: Path | None = None  # the model found without the file: its path is the one reported missing
        for root in searched:
            model_dir = join_inside(root, name, uri)
            if model_dir.is_dir():
                target = join_inside(model_dir, rel, uri)
                if not need_file or target.exists():
                    return target
                first = first or target
        if name in self.packages:
            return join_inside(self.packages[name], rel, uri)
        if first is not None:
            return first
        where = ", ".join(str(p) for p in searched) or "no folders"
        raise NotFoundError(
            f"model {name!r} ({uri}) not found; searched {where}; add the folder holding "
            f"{name}/ to GAZEBO_MODEL_PATH or pass --model-path"
        )

    def resolve_uri(self, uri: str, *, base_dir: Path, model_paths: Iterable[str | os.PathLike[str]] = ()) -> Path:
        """Absolute path of ``package://``, ``file://``, ``model://``, absolute or relative ``uri``.

        Relative paths are taken relative to ``base_dir`` (the file that names them). ``package://``
        and ``model://`` paths cannot leave their package or model. A ``model://`` URI must exist in
        the model search path (NotFoundError naming the folders searched); other paths are not
        checked for existence here.
        """
        uri = uri.strip()
        if uri.startswith("package://"):
            rest = uri[len("package://") :].lstrip("/")
            pkg, _, rel = rest.partition("/")
            try:
                root = self.find(pkg)
            except DescriptionError as exc:
                raise NotFoundError(str(exc)) from None
            return join_inside(root, rel, uri)
        if uri.startswith("file://"):
            return Path(uri[len("file://") :])
        if uri.startswith("model://"):
            return self.find_model(uri, model_paths, need_file=True)
        path = Path(uri).expanduser()
        return path if path.is_absolute() else base_dir / path


def find_package(name: str) -> Path:
    """``$(find NAME)`` of launch files: the package's directory (``ROS_PACKAGE_PATH``, then the packages
    navlab ships); DescriptionError naming where it looked when none is found."""
    return PackageIndex().find(name)
