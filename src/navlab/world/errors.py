"""Errors of world (SDF) loading."""

from navlab.errors import NavlabError


class WorldError(NavlabError):
    """An SDF world, an included model or a mesh it names is missing or malformed.

    The message names the file and the element (``<model name="...">/<link name="...">``) and says
    what was expected.
    """
