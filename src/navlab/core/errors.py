"""Errors of the runtime."""

from navlab.errors import NavlabError


class CoreError(NavlabError):
    """Misuse of the runtime: conflicting topic types, duplicate nodes, unknown services."""


class ParameterError(CoreError):
    """A parameter file or value is wrong (unknown key, wrong type, malformed YAML)."""


class TfError(CoreError):
    """A transform cannot be looked up: unknown frame, no path, or extrapolation."""


class LaunchError(CoreError):
    """A launch file is malformed or names something that does not exist."""
