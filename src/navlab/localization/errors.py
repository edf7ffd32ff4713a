"""Errors of the localization package."""

from __future__ import annotations

from navlab.errors import NavlabError


class LocalizationError(NavlabError):
    """Bad input to AMCL: a pose outside the map or not finite, a map without free cells, a bad parameter."""
