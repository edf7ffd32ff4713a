"""ROS 2 message types (from rosbags' typestore) and small helpers.

Messages are the typestore's dataclasses with the exact ROS field names; array fields are numpy
arrays. Helpers convert between yaw and quaternions, nanoseconds and ``builtin_interfaces/Time``,
and build the messages navlab publishes most often. The helpers pass the fields positionally, in the
message definition's order: a dataclass built so costs a third of one built by keywords, and these are
built tens of thousands of times a simulated minute.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from navlab.errors import NavlabError
from navlab.geometry import quat_from_yaw, yaw_from_quat

TYPESTORE = get_typestore(Stores.ROS2_HUMBLE)
# gazebo_msgs and costmap_2d (not in the ROS 2 store): the bumper plugin's contact messages, with the fields ROS
# Noetic and gazebo_ros_pkgs for ROS 2 give them, and the voxel layer's grid
TYPESTORE.register(
    {
        **get_types_from_msg(
            """string info
string collision1_name
string collision2_name
geometry_msgs/Wrench[] wrenches
geometry_msgs/Wrench total_wrench
geometry_msgs/Vector3[] contact_positions
geometry_msgs/Vector3[] contact_normals
float64[] depths
""",
            "gazebo_msgs/msg/ContactState",
        ),
        **get_types_from_msg(
            "std_msgs/Header header\ngazebo_msgs/ContactState[] states\n", "gazebo_msgs/msg/ContactsState"
        ),
        # costmap_2d's voxel layer (publish_voxel_map): the packed voxel columns
        **get_types_from_msg(
            "std_msgs/Header header\nuint32[] data\ngeometry_msgs/Point32 origin\n"
            "geometry_msgs/Vector3 resolutions\nuint32 size_x\nuint32 size_y\nuint32 size_z\n",
            "costmap_2d/msg/VoxelGrid",
        ),
    }
)
_T = TYPESTORE.types

Time = _T["builtin_interfaces/msg/Time"]
Duration = _T["builtin_interfaces/msg/Duration"]
Header = _T["std_msgs/msg/Header"]
String = _T["std_msgs/msg/String"]
Empty = _T["std_msgs/msg/Empty"]
Float64 = _T["std_msgs/msg/Float64"]
Vector3 = _T["geometry_msgs/msg/Vector3"]
Point = _T["geometry_msgs/msg/Point"]
Quaternion = _T["geometry_msgs/msg/Quaternion"]
Pose = _T["geometry_msgs/msg/Pose"]
PoseStamped = _T["geometry_msgs/msg/PoseStamped"]
PoseArray = _T["geometry_msgs/msg/PoseArray"]
PoseWithCovariance = _T["geometry_msgs/msg/PoseWithCovariance"]
PoseWithCovarianceStamped = _T["geometry_msgs/msg/PoseWithCovarianceStamped"]
Twist = _T["geometry_msgs/msg/Twist"]
TwistWithCovariance = _T["geometry_msgs/msg/TwistWithCovariance"]
Transform = _T["geometry_msgs/msg/Transform"]
TransformStamped = _T["geometry_msgs/msg/TransformStamped"]
Odometry = _T["nav_msgs/msg/Odometry"]
OccupancyGrid = _T["nav_msgs/msg/OccupancyGrid"]
MapMetaData = _T["nav_msgs/msg/MapMetaData"]
Path = _T["nav_msgs/msg/Path"]
LaserScan = _T["sensor_msgs/msg/LaserScan"]
Imu = _T["sensor_msgs/msg/Imu"]
JointState = _T["sensor_msgs/msg/JointState"]
TFMessage = _T["tf2_msgs/msg/TFMessage"]
Marker = _T["visualization_msgs/msg/Marker"]
MarkerArray = _T["visualization_msgs/msg/MarkerArray"]
ColorRGBA = _T["std_msgs/msg/ColorRGBA"]
Point32 = _T["geometry_msgs/msg/Point32"]
Polygon = _T["geometry_msgs/msg/Polygon"]
PolygonStamped = _T["geometry_msgs/msg/PolygonStamped"]
GoalStatus = _T["action_msgs/msg/GoalStatus"]
GoalStatusArray = _T["action_msgs/msg/GoalStatusArray"]
GoalInfo = _T["action_msgs/msg/GoalInfo"]
UUID = _T["unique_identifier_msgs/msg/UUID"]
Bool = _T["std_msgs/msg/Bool"]
Image = _T["sensor_msgs/msg/Image"]
CameraInfo = _T["sensor_msgs/msg/CameraInfo"]
RegionOfInterest = _T["sensor_msgs/msg/RegionOfInterest"]
PointCloud2 = _T["sensor_msgs/msg/PointCloud2"]
PointField = _T["sensor_msgs/msg/PointField"]
Range = _T["sensor_msgs/msg/Range"]
Wrench = _T["geometry_msgs/msg/Wrench"]
ContactState = _T["gazebo_msgs/msg/ContactState"]
ContactsState = _T["gazebo_msgs/msg/ContactsState"]
VoxelGrid = _T["costmap_2d/msg/VoxelGrid"]


class MessageTypeError(NavlabError, LookupError):
    """An unknown ROS message type name was asked for (also a ``LookupError``, as before)."""


def get_type(name: str) -> type:
    """Return the message class for a ROS type name (``geometry_msgs/msg/Twist`` or ``geometry_msgs/Twist``)."""
    key = name if "/msg/" in name else name.replace("/", "/msg/", 1)
    try:
        return _T[key]
    except KeyError:
        from navlab.errors import did_you_mean

        hint = did_you_mean(key, _T, template="; did you mean {}?", n=3)
        raise MessageTypeError(f"unknown message type {name!r}{hint}") from None


def type_name(msg_or_cls: Any) -> str:
    """ROS type name of a message or message class, e.g. ``nav_msgs/msg/Odometry``."""
    return str(msg_or_cls.__msgtype__)


# --- time -----------------------------------------------------------------------------------------


def time_from_ns(ns: int) -> Any:
    """``builtin_interfaces/Time`` from integer nanoseconds."""
    sec, nsec = divmod(int(ns), 1_000_000_000)
    return Time(sec, nsec)


def ns_from_time(t: Any) -> int:
    """Integer nanoseconds from a ``builtin_interfaces/Time`` (or Duration)."""
    return int(t.sec) * 1_000_000_000 + int(t.nanosec)


def header(stamp_ns: int, frame_id: str) -> Any:
    """``std_msgs/Header`` with a stamp in nanoseconds."""
    return Header(time_from_ns(stamp_ns), frame_id)


# --- rotations ------------------------------------------------------------------------------------


def quaternion_msg(q: Any) -> Any:
    """``geometry_msgs/Quaternion`` from (x, y, z, w) components."""
    return Quaternion(float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def xyzw(q: Any) -> tuple[float, float, float, float]:
    """(x, y, z, w) components of a ``geometry_msgs/Quaternion``."""
    return float(q.x), float(q.y), float(q.z), float(q.w)


def quaternion_from_yaw(yaw: float) -> Any:
    """``geometry_msgs/Quaternion`` for a rotation of ``yaw`` radians about z."""
    return quaternion_msg(quat_from_yaw(yaw))


def yaw_from_quaternion(q: Any) -> float:
    """Yaw (radians, about z) of a ``geometry_msgs/Quaternion``."""
    return yaw_from_quat(xyzw(q))


# --- poses ----------------------------------------------------------------------------------------


def pose_from_2d(x: float, y: float, yaw: float) -> Any:
    """``geometry_msgs/Pose`` in the plane."""
    return Pose(Point(float(x), float(y), 0.0), quaternion_from_yaw(yaw))


def pose2d(pose: Any) -> tuple[float, float, float]:
    """(x, y, yaw) of a ``geometry_msgs/Pose``."""
    return float(pose.position.x), float(pose.position.y), yaw_from_quaternion(pose.orientation)


def pose_stamped(stamp_ns: int, frame_id: str, x: float, y: float, yaw: float) -> Any:
    """``geometry_msgs/PoseStamped`` in the plane."""
    return PoseStamped(header(stamp_ns, frame_id), pose_from_2d(x, y, yaw))


def path(stamp_ns: int, frame_id: str, poses: Any) -> Any:
    """``nav_msgs/Path`` of (N, 2+) rows (x, y[, yaw]) in ``frame_id``; yaw 0 where the rows have none."""
    return Path(
        header(stamp_ns, frame_id),
        [pose_stamped(stamp_ns, frame_id, float(q[0]), float(q[1]), float(q[2]) if len(q) > 2 else 0.0) for q in poses],
    )


def transform_stamped(stamp_ns: int, parent: str, child: str, x: float, y: float, yaw: float, z: float = 0.0) -> Any:
    """``geometry_msgs/TransformStamped`` ``parent_T_child`` in the plane (plus height ``z``)."""
    return TransformStamped(
        header(stamp_ns, parent), child, Transform(Vector3(float(x), float(y), float(z)), quaternion_from_yaw(yaw))
    )


def transform_from_tuple(stamp_ns: int, parent: str, child: str, tf: Any) -> Any:
    """``geometry_msgs/TransformStamped`` ``parent_T_child`` from ``(x, y, z, qx, qy, qz, qw)``."""
    return TransformStamped(
        header(stamp_ns, parent),
        child,
        Transform(Vector3(float(tf[0]), float(tf[1]), float(tf[2])), Quaternion(*(float(v) for v in tf[3:]))),
    )


def twist(vx: float = 0.0, wz: float = 0.0, vy: float = 0.0) -> Any:
    """``geometry_msgs/Twist`` for a planar robot (m/s, rad/s)."""
    return Twist(Vector3(float(vx), float(vy), 0.0), Vector3(0.0, 0.0, float(wz)))


def vector3(v: Any) -> Any:
    """``geometry_msgs/Vector3`` from (x, y, z)."""
    return Vector3(float(v[0]), float(v[1]), float(v[2]))


def odometry(
    stamp_ns: int,
    frame_id: str,
    child_frame_id: str,
    position: Any,
    orientation: Any,
    linear: Any,
    angular: Any,
    pose_covariance: np.ndarray,
    twist_covariance: np.ndarray,
) -> Any:
    """``nav_msgs/Odometry``: the pose of ``child_frame_id`` in ``frame_id`` (``position`` x, y, z m;
    ``orientation`` x, y, z, w), its velocity in the child frame (``linear`` m/s, ``angular`` rad/s, x, y, z),
    and the 36-float row-major covariances (taken as they are: pass a copy)."""
    return Odometry(
        header(stamp_ns, frame_id),
        child_frame_id,
        PoseWithCovariance(
            Pose(Point(float(position[0]), float(position[1]), float(position[2])), quaternion_msg(orientation)),
            pose_covariance,
        ),
        TwistWithCovariance(Twist(vector3(linear), vector3(angular)), twist_covariance),
    )


# rosbags' base type names -> the numpy dtype of their arrays (ROS 2's; a ROS 1 bool is a uint8 on the wire)
NUMPY_DTYPES: dict[str, type] = {
    "float64": np.float64,
    "float32": np.float32,
    "double": np.float64,
    "float": np.float32,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "byte": np.uint8,
    "octet": np.uint8,
    "char": np.uint8,
    "bool": np.bool_,
}


def zero_value(base_type: str) -> Any:
    """The value a field of rosbags' base type ``base_type`` takes when it is not given ("", False, 0.0 or 0)."""
    if base_type in ("string", "wstring"):
        return ""
    if base_type == "bool":
        return False
    return 0.0 if base_type.startswith(("float", "double")) else 0


def covariance(diag: tuple[float, ...] | None = None) -> np.ndarray:
    """A 6×6 row-major covariance (36 float64) with the given diagonal (zeros if None)."""
    cov = np.zeros(36, dtype=np.float64)
    if diag is not None:
        cov[[0, 7, 14, 21, 28, 35][: len(diag)]] = diag
    return cov


def stamp_ns(msg: Any) -> int:
    """Header stamp of a message in nanoseconds."""
    return ns_from_time(msg.header.stamp)
