"""Errors of the simulator package."""

from navlab.errors import NavlabError


class SimError(NavlabError):
    """Bad robot/world input for the simulator, or a simulator operation that cannot be done."""
