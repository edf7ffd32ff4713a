"""Robot descriptions: xacro/URDF files with Gazebo ``<gazebo>`` plugin tags → :class:`RobotModel`.

>>> from navlab.description import load_robot
>>> robot = load_robot(navlab.resources.robot("mybot"))
>>> robot.diff_drive.wheel_separation
0.4
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.description.errors import DescriptionError, NotFoundError
    from navlab.description.footprint import collision_reach
    from navlab.description.loader import load_robot, load_robot_named
    from navlab.description.materials import gazebo_material
    from navlab.description.meshes import cache_dir, is_convex, prepare_mesh, read_mesh, up_axis_warning
    from navlab.description.model import (
        ContactTags,
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
        is_geometry_kind,
    )
    from navlab.description.packages import PackageIndex, find_package
    from navlab.description.sensor_model import BumperConfig, CameraConfig, Lidar3dConfig, RangeConfig, SensorConfig
    from navlab.description.summary import format_robot, robot_summary, shape_summary

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
    "BumperConfig": "navlab.description.sensor_model",
    "CameraConfig": "navlab.description.sensor_model",
    "ContactTags": "navlab.description.model",
    "Lidar3dConfig": "navlab.description.sensor_model",
    "NotFoundError": "navlab.description.errors",
    "RangeConfig": "navlab.description.sensor_model",
    "SensorConfig": "navlab.description.sensor_model",
    "cache_dir": "navlab.description.meshes",
    "collision_reach": "navlab.description.footprint",
    "find_package": "navlab.description.packages",
    "format_robot": "navlab.description.summary",
    "gazebo_material": "navlab.description.materials",
    "is_convex": "navlab.description.meshes",
    "is_geometry_kind": "navlab.description.model",
    "prepare_mesh": "navlab.description.meshes",
    "read_mesh": "navlab.description.meshes",
    "robot_summary": "navlab.description.summary",
    "shape_summary": "navlab.description.summary",
    "up_axis_warning": "navlab.description.meshes",
}
__all__ = [
    "BumperConfig",
    "CameraConfig",
    "ContactTags",
    "DescriptionError",
    "DiffDriveConfig",
    "Geometry",
    "ImuConfig",
    "Inertial",
    "Joint",
    "Lidar3dConfig",
    "LidarConfig",
    "Link",
    "NotFoundError",
    "Origin",
    "PackageIndex",
    "RangeConfig",
    "RobotModel",
    "SensorConfig",
    "Shape",
    "cache_dir",
    "collision_reach",
    "find_package",
    "format_robot",
    "gazebo_material",
    "is_convex",
    "is_geometry_kind",
    "load_robot",
    "load_robot_named",
    "prepare_mesh",
    "read_mesh",
    "robot_summary",
    "shape_summary",
    "up_axis_warning",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
