"""Errors of the navigation package (costmaps, planners, controllers, move_base)."""

from __future__ import annotations

from navlab.errors import NavlabError


class NavigationError(NavlabError):
    """Bad navigation input: a bad parameter (named with its value and what was expected), a start or goal
    outside the costmap, a malformed footprint or map."""
