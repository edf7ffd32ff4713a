"""Each package's ``__init__`` is its only public entry (tools/check_layers.py enforces it for imports): every
name a package lists in ``__all__`` resolves, and a lazy export is the very object of the module it names."""

from __future__ import annotations

import importlib
import pkgutil

import pytest

import navlab

PACKAGES = sorted(m.name for m in pkgutil.iter_modules(navlab.__path__, "navlab.") if m.ispkg)


@pytest.mark.parametrize("name", PACKAGES)
def test_every_public_name_resolves_to_its_module_object(name: str) -> None:
    package = importlib.import_module(name)
    public_names = getattr(package, "__all__", [])  # cli, bench, resources: entries of their own, no __all__
    table = getattr(package, "_EXPORTS", {})
    for public in public_names:
        value = getattr(package, public)
        target = table.get(public)
        if target is None:
            continue
        module, _, attr = target.partition(":")
        source = importlib.import_module(module)
        attr = attr or public
        expected = getattr(source, attr) if hasattr(source, attr) else importlib.import_module(f"{module}.{attr}")
        assert value is expected, f"{name}.{public} is not {target}"
    assert set(table) <= set(public_names), f"{name}: exported but not in __all__: {set(table) - set(public_names)}"


def test_lazy_export_of_a_module_and_a_renamed_name() -> None:
    from navlab.localization import AmclNode
    from navlab.localization.amcl_node import Amcl
    from navlab.navigation import synthetic
    from navlab.navigation.controllers import synthetic as direct

    assert AmclNode is Amcl and synthetic is direct
