"""Lazy package exports (PEP 562), so ``navlab --help`` and ``import navlab.x`` load no physics or Numba.

A package ``__init__`` lists its public names and the module each comes from; the module is imported
the first time the name is used::

    __getattr__, __dir__ = lazy_exports(__name__, {"Simulation": "navlab.sim.simulation"})

``"module:attr"`` exports ``module``'s ``attr`` (or its submodule ``attr``) under another name, where two
modules of a package define the same name or the name is a module.
"""

from __future__ import annotations

import importlib
import sys
import warnings
from collections.abc import Callable
from typing import Any

from navlab.deprecation import NavlabDeprecationWarning


def lazy_exports(package: str, exports: dict[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package`` exporting ``name -> module`` (or ``module:attr``) lazily."""

    def __getattr__(name: str) -> Any:
        target = exports.get(name)
        if target is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attr = target.partition(":")
        parent = importlib.import_module(module)
        attr = attr or name
        value = getattr(parent, attr) if hasattr(parent, attr) else importlib.import_module(f"{module}.{attr}")
        setattr(sys.modules[package], name, value)  # later lookups skip this function
        return value

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *exports})

    return __getattr__, __dir__


def moved_exports(old: str, exports: dict[str, str]) -> Callable[[str], Any]:
    """``__getattr__`` for a module whose names moved (``name -> new module``): each look-up warns with a
    ``DeprecationWarning`` naming the new home, then returns the name from there (kept for one release)."""

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        warnings.warn(
            f"{old}.{name} moved to {module}.{name}; the old name goes in the next release",
            NavlabDeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module(module), name)

    return __getattr__
