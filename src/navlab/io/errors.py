"""Errors of the io package (file formats and datasets)."""

from __future__ import annotations

from navlab.errors import NavlabError


class IoError(NavlabError):
    """A file cannot be read or written, or its content is not the expected format; the message names
    the file (and line) and what was expected."""


class BagError(IoError):
    """A rosbag2 directory cannot be written or read."""


class DatasetNotFoundError(IoError):
    """A dataset is not where ``NAVLAB_DATA`` says; the message names the path and how to provide it."""
