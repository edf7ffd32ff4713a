"""Errors of the experiment runner."""

from navlab.errors import NavlabError


class ExperimentError(NavlabError):
    """A scenario file or an experiment's settings are wrong (unknown key, bad value, missing file)."""
