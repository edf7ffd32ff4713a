"""Errors of the ROS 1 wire bridge."""

from __future__ import annotations

from navlab.errors import NavlabError


class Ros1Error(NavlabError):
    """A ROS 1 master, peer, message type or setting that navlab cannot use."""
