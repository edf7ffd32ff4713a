"""Deprecations: the old name keeps working for one release, with a :class:`NavlabDeprecationWarning`."""

from __future__ import annotations

import warnings
from typing import Any

from navlab.errors import NavlabError


class NavlabDeprecationWarning(NavlabError, DeprecationWarning):
    """navlab's own deprecations (an old name, keyword or return shape that goes in the next release): a
    ``NavlabError`` as every navlab exception class, and a ``DeprecationWarning``, so filters and
    ``pytest.warns(DeprecationWarning)`` see it; a category of its own, so ``-W
    error::navlab.deprecation.NavlabDeprecationWarning`` finds your uses of old forms (navlab's tests run so)
    without turning third-party libraries' deprecations into errors."""


def renamed(value: Any, old_value: Any, *, old: str, new: str, where: str) -> Any:
    """The value of keyword ``new`` of ``where``, taking ``old`` (its name until this release) when that was
    given instead: ``old_value`` is None when the old name was not used. Warns once per call that uses it."""
    if old_value is None:
        return value
    warnings.warn(
        f"{where}({old}=...) is deprecated, use {new}= (the old name works until the next release)",
        NavlabDeprecationWarning,
        stacklevel=3,
    )
    return old_value
