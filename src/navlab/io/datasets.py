"""Where datasets live: the ``NAVLAB_DATA`` setting, never a machine path in the code.

``NAVLAB_DATA`` (environment variable) names the folder that holds the datasets (``mit-csail/`` ...).
Unset, it defaults to ``../shared/datasets`` relative to the repository root when navlab runs from a
checkout (``src/navlab`` beside ``pyproject.toml``), else relative to the current directory.
"""

from __future__ import annotations

import os
from pathlib import Path

from navlab.io.errors import DatasetNotFoundError

ENV_VAR = "NAVLAB_DATA"
DEFAULT_RELATIVE = Path("..", "shared", "datasets")


def repository_root() -> Path | None:
    """The checkout this package runs from (``<root>/src/navlab``), or None when installed elsewhere."""
    root = Path(__file__).resolve().parents[3]
    if Path(__file__).resolve().parents[2].name == "src" and (root / "pyproject.toml").is_file():
        return root
    return None


def default_data_dir() -> Path:
    """``../shared/datasets`` relative to the repository root, or to the current directory outside a checkout."""
    base = repository_root() or Path.cwd()
    return Path(os.path.normpath(base / DEFAULT_RELATIVE))


def data_dir() -> Path:
    """The datasets folder: ``$NAVLAB_DATA`` if set (``~`` expanded, relative to the current directory),
    else :func:`default_data_dir`. The folder need not exist."""
    value = os.environ.get(ENV_VAR, "").strip()
    return Path(value).expanduser().absolute() if value else default_data_dir()


def dataset(relpath: str | os.PathLike[str]) -> Path:
    """The path of ``relpath`` (e.g. ``"mit-csail/mit-csail.clf"``) inside :func:`data_dir`.

    Raises ``DatasetNotFoundError`` naming the path looked for and how to provide it when absent.
    """
    rel = Path(relpath)
    if rel.is_absolute():
        raise DatasetNotFoundError(f"dataset {rel}: expected a path relative to the datasets folder ({ENV_VAR})")
    path = data_dir() / rel
    if not path.exists():
        where = (
            f"{ENV_VAR}={os.environ[ENV_VAR]}"
            if os.environ.get(ENV_VAR, "").strip()
            else f"{ENV_VAR} is unset, so the default {default_data_dir()}"
        )
        raise DatasetNotFoundError(
            f"dataset {rel} not found at {path} ({where}); set {ENV_VAR} to the folder that holds "
            f"{rel.parts[0]}/, or put the data at ../shared/datasets relative to the repository root"
        )
    return path


def data_file(text: str | os.PathLike[str]) -> Path:
    """A file the user named: the path itself when it exists, else the same relative path inside :func:`data_dir`
    when that exists (``mit-csail/mit-csail.clf`` from any folder), else the path as given (its reader then says
    it is missing)."""
    path = Path(text).expanduser()
    if path.exists() or path.is_absolute():
        return path
    inside = data_dir() / path
    return inside if inside.exists() else path
