"""Renamed keywords: the old name keeps working for one release, with a DeprecationWarning."""

from __future__ import annotations

import warnings
from typing import Any


def renamed(value: Any, old_value: Any, *, old: str, new: str, where: str) -> Any:
    """The value of keyword ``new`` of ``where``, taking ``old`` (its name until this release) when that was
    given instead: ``old_value`` is None when the old name was not used. Warns once per call that uses it."""
    if old_value is None:
        return value
    warnings.warn(
        f"{where}({old}=...) is deprecated, use {new}= (the old name works until the next release)",
        DeprecationWarning,
        stacklevel=3,
    )
    return old_value
