"""Robot descriptions: xacro/URDF files with Gazebo ``<gazebo>`` plugin tags → :class:`RobotModel`.

>>> from navlab.description import load_robot
>>> robot = load_robot(navlab.resources.robot("mybot"))
>>> robot.diff_drive.wheel_separation
0.4
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.description.errors import DescriptionError
    from navlab.description.loader import load_robot, load_robot_named
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

_EXPORTS = {
    "DescriptionError": "navlab.description.errors",
    "DiffDriveConfig": "navlab.description.model",
    "Geometry": "navlab.description.model",
    "ImuConfig": "navlab.description.model",
    "Inertial": "navlab.description.model",
    "Joint": "navlab.description.model",
    "LidarConfig": "navlab.description.model",
    "Link": "navlab.description.model",
    "Origin": "navlab.description.model",
    "PackageIndex": "navlab.description.packages",
    "RobotModel": "navlab.description.model",
    "Shape": "navlab.description.model",
    "load_robot": "navlab.description.loader",
    "load_robot_named": "navlab.description.loader",
}
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
    "load_robot_named",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
