"""Errors of robot-description loading."""

from navlab.errors import NavlabError


class DescriptionError(NavlabError):
    """A robot description (xacro/URDF/<gazebo> tags or a mesh it names) is missing or malformed.

    The message names the file and the element (``<link name="...">/<inertial>``) and says what was
    expected.
    """
