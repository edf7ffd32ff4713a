"""Errors of the viewer (server, replay, Foxglove bridge)."""

from __future__ import annotations

from navlab.errors import NavlabError


class VizError(NavlabError):
    """A viewer problem: a bad option, a port in use, an unreadable recording, a malformed page input."""
