"""Robot descriptions: xacro/URDF files with Gazebo ``<gazebo>`` plugin tags → :class:`RobotModel`.

>>> from navlab.description import load_robot
>>> robot = load_robot(navlab.resources.robot("mybot"))
>>> robot.diff_drive.wheel_separation
0.4
"""

from navlab.description.errors import DescriptionError
from navlab.description.loader import load_robot
from navlab.description.model import (
    DiffDriveConfig,
    Geometry,
    ImuConfig,
    Inertial,
    Joint,
    LidarConfig,
    Link,
    Origin,
    RobotModel,
    Shape,
)
from navlab.description.packages import PackageIndex

__all__ = [
    "DescriptionError",
    "DiffDriveConfig",
    "Geometry",
    "ImuConfig",
    "Inertial",
    "Joint",
    "LidarConfig",
    "Link",
    "Origin",
    "PackageIndex",
    "RobotModel",
    "Shape",
    "load_robot",
]
