"""Errors of robot-description loading."""

from navlab.errors import NavlabError


class DescriptionError(NavlabError):
    """A robot description (xacro/URDF/<gazebo> tags or a mesh it names) is missing or malformed.

    The message names the file and the element (``<link name="...">/<inertial>``) and says what was
    expected.
    """


class NotFoundError(DescriptionError):
    """A file, ROS package or Gazebo model that a description names cannot be found. The message
    names what was looked for and every folder searched. A visual whose mesh is not found is skipped
    with a warning, as Gazebo does; a collision's stays an error."""
