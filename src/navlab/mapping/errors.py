"""Errors of the mapping package."""

from __future__ import annotations

from navlab.errors import NavlabError


class MappingError(NavlabError):
    """Bad map file, log, relations file or SLAM input; the message names the file/key and what was expected."""
