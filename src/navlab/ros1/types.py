"""ROS 1 message types on the wire: Noetic definitions, md5sums, and conversion to and from navlab's ROS 2 messages.

The Noetic typestore of ``rosbags`` serializes and defines the ROS 1 messages. The few packages it lacks
(``tf2_msgs``, ``move_base_msgs``, the services navlab offers) are registered here from their ``.msg``/``.srv``
text as published in the ROS 1 packages. navlab's runtime uses ROS 2 dataclasses; :class:`Ros1Types` converts
field by field between the two (ROS 1's ``Header.seq`` is filled in, everything else has the same names).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from hashlib import md5
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype

from navlab.msgs import NUMPY_DTYPES, zero_value
from navlab.msgs import TYPESTORE as ROS2_STORE
from navlab.ros1.errors import Ros1Error

# ROS 1 definitions the Noetic typestore of rosbags does not ship (text from the packages' msg/ and srv/ files)
EXTRA_MSGS: dict[str, str] = {
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "move_base_msgs/msg/MoveBaseGoal": "geometry_msgs/PoseStamped target_pose",
    "move_base_msgs/msg/MoveBaseResult": "",
    "move_base_msgs/msg/MoveBaseFeedback": "geometry_msgs/PoseStamped base_position",
    "move_base_msgs/msg/MoveBaseActionGoal": (
        "Header header\nactionlib_msgs/GoalID goal_id\nmove_base_msgs/MoveBaseGoal goal"
    ),
    "move_base_msgs/msg/MoveBaseActionResult": (
        "Header header\nactionlib_msgs/GoalStatus status\nmove_base_msgs/MoveBaseResult result"
    ),
    "move_base_msgs/msg/MoveBaseActionFeedback": (
        "Header header\nactionlib_msgs/GoalStatus status\nmove_base_msgs/MoveBaseFeedback feedback"
    ),
}
# services: name -> (request text, response text)
EXTRA_SRVS: dict[str, tuple[str, str]] = {
    "std_srvs/srv/Empty": ("", ""),
    "nav_msgs/srv/GetMap": ("", "nav_msgs/OccupancyGrid map"),
    "nav_msgs/srv/GetPlan": (
        "geometry_msgs/PoseStamped start\ngeometry_msgs/PoseStamped goal\nfloat32 tolerance",
        "nav_msgs/Path plan",
    ),
    "gazebo_msgs/srv/DeleteModel": ("string model_name", "bool success\nstring status_message"),
    "gazebo_msgs/srv/SpawnModel": (
        "string model_name\nstring model_xml\nstring robot_namespace\ngeometry_msgs/Pose initial_pose\n"
        "string reference_frame",
        "bool success\nstring status_message",
    ),
}


def wire_name(typename: str) -> str:
    """``nav_msgs/msg/Odometry`` -> ``nav_msgs/Odometry`` (the ROS 1 spelling in connection headers)."""
    return typename.replace("/msg/", "/").replace("/srv/", "/")


def full_name(wire: str) -> str:
    """``nav_msgs/Odometry`` -> ``nav_msgs/msg/Odometry`` (the typestore's key)."""
    return wire if "/msg/" in wire else wire.replace("/", "/msg/", 1)


@dataclass(frozen=True)
class WireType:
    """One ROS 1 message type as TCPROS announces it: name, md5sum and full definition."""

    typename: str  # typestore key, e.g. sensor_msgs/msg/LaserScan
    md5sum: str
    definition: str

    @property
    def wire(self) -> str:
        return wire_name(self.typename)


@dataclass(frozen=True)
class ServiceType:
    """One ROS 1 service type: its request and response message types and the service md5sum."""

    name: str  # e.g. std_srvs/srv/Empty
    request: str
    response: str
    md5sum: str


class Ros1Types:
    """The Noetic typestore plus navlab's extra definitions; md5sums, (de)serialization and conversion."""

    def __init__(self) -> None:
        self.store = get_typestore(Stores.ROS1_NOETIC)
        extra: dict[str, Any] = {}
        for name, text in EXTRA_MSGS.items():
            extra.update(get_types_from_msg(text, name))
        self.services: dict[str, ServiceType] = {}
        for name, (req, res) in EXTRA_SRVS.items():
            pkg, _, base = name.split("/")
            reqname, resname = f"{pkg}/msg/{base}_Request", f"{pkg}/msg/{base}_Response"
            extra.update(get_types_from_msg(req, reqname))
            extra.update(get_types_from_msg(res, resname))
            self.services[name] = ServiceType(name, reqname, resname, "")
        self.store.register(extra)
        self._wire: dict[str, WireType] = {}
        self._convert: dict[tuple[int, str], Callable[[Any], Any]] = {}
        self._lock = threading.Lock()
        for name, srv in list(self.services.items()):
            digest = md5((self._hashtext(srv.request) + self._hashtext(srv.response)).encode()).hexdigest()
            self.services[name] = ServiceType(name, srv.request, srv.response, digest)

    # --- definitions -----------------------------------------------------------------------------------

    def _hashtext(self, typename: str) -> str:
        """The md5 text of a message (ROS 1's gendeps: constants, then fields with nested types as their md5)."""
        consts, fields = self.store.fielddefs[typename]
        lines = [f"{typ} {name}={value}" for name, typ, value in consts]
        for name, desc in fields:
            if name == "structure_needs_at_least_one_member":
                continue
            if desc[0] == Nodetype.BASE:
                lines.append(f"{desc[1][0]} {name}")
            elif desc[0] == Nodetype.NAME:
                sub = str(desc[1])
                lines.append(f"{_ROS1_TIME.get(sub) or self.wire_type(sub).md5sum} {name}")
            else:
                (kind, element), num = desc[1]
                count = "" if num == 0 else str(num)
                if kind == Nodetype.BASE:
                    lines.append(f"{element[0]}[{count}] {name}")
                elif str(element) in _ROS1_TIME:
                    lines.append(f"{_ROS1_TIME[str(element)]}[{count}] {name}")
                else:  # a nested message array: its md5sum, no brackets (genmsg's md5 text)
                    lines.append(f"{self.wire_type(str(element)).md5sum} {name}")
        return "\n".join(lines)

    def wire_type(self, typename: str) -> WireType:
        """The md5sum and definition of a ROS 1 type (``Ros1Error`` if the type is unknown)."""
        typename = full_name(typename)
        found = self._wire.get(typename)
        if found is None:
            if typename not in self.store.fielddefs:
                raise Ros1Error(f"no ROS 1 message type {wire_name(typename)!r}")
            definition, digest = self.store.generate_msgdef(typename, ros_version=1)
            found = self._wire[typename] = WireType(typename, digest, definition)
        return found

    def ros1_type_of(self, ros2_typename: str) -> str | None:
        """The ROS 1 type carrying navlab's ROS 2 type ``ros2_typename`` on the wire (None: no counterpart)."""
        return ros2_typename if ros2_typename in self.store.fielddefs else None

    # --- bytes -----------------------------------------------------------------------------------------

    def serialize(self, msg: Any, typename: str) -> bytes:
        return bytes(self.store.serialize_ros1(msg, full_name(typename)))

    def deserialize(self, raw: bytes, typename: str) -> Any:
        return self.store.deserialize_ros1(raw, full_name(typename))

    # --- conversion ------------------------------------------------------------------------------------

    def to_ros1(self, msg: Any, typename: str) -> Any:
        """navlab's ROS 2 message as the ROS 1 message ``typename`` (same field names; missing fields default)."""
        return self._converter(self.store, type(msg), full_name(typename))(msg)

    def to_ros2(self, msg: Any, ros2_typename: str) -> Any:
        """A ROS 1 message as navlab's ROS 2 message ``ros2_typename``."""
        return self._converter(ROS2_STORE, type(msg), ros2_typename)(msg)

    def _converter(self, store: Any, src: type, dst: str) -> Callable[[Any], Any]:
        key = (id(store), f"{src.__msgtype__}>{dst}")  # type: ignore[attr-defined]
        fn = self._convert.get(key)
        if fn is None:
            with self._lock:
                fn = self._convert[key] = self._build(store, dst)
        return fn

    def _build(self, store: Any, dst: str) -> Callable[[Any], Any]:
        """A function copying a message's fields into the ``dst`` class of ``store`` (recursively)."""
        cls = store.types[dst]
        plan: list[tuple[str, Callable[[Any], Any], Any]] = []
        for name, desc in store.fielddefs[dst][1]:
            plan.append((name, self._field_fn(store, desc), _default(store, desc)))

        def convert(msg: Any) -> Any:
            values = {}
            for name, fn, default in plan:
                value = getattr(msg, name, _MISSING)
                values[name] = default() if value is _MISSING else fn(value)
            return cls(**values)

        return convert

    def _field_fn(self, store: Any, desc: Any) -> Callable[[Any], Any]:
        if desc[0] == Nodetype.BASE:
            return _same
        if desc[0] == Nodetype.NAME:
            sub = str(desc[1])
            return lambda v: self._converter(store, type(v), sub)(v)
        (kind, sub), _ = desc[1]
        if kind == Nodetype.BASE:
            return _same
        return lambda v: [self._converter(store, type(x), sub)(x) for x in v]


_ROS1_TIME = {"builtin_interfaces/msg/Time": "time", "builtin_interfaces/msg/Duration": "duration"}
_MISSING = object()
_NUMPY = {**NUMPY_DTYPES, "bool": np.uint8}  # ROS 1 arrays of bool are uint8 on the wire


def _same(v: Any) -> Any:
    return v


def _default(store: Any, desc: Any) -> Callable[[], Any]:
    """The zero value of a field missing on the other side (ROS 1's Header.seq, ...)."""
    if desc[0] == Nodetype.BASE:
        zero = zero_value(desc[1][0])
        return lambda: zero
    if desc[0] == Nodetype.NAME:
        sub = str(desc[1])
        return lambda: store.types[sub](**{n: _default(store, d)() for n, d in store.fielddefs[sub][1]})
    (kind, sub), num = desc[1]
    if kind == Nodetype.BASE and sub[0] in _NUMPY:
        return lambda: np.zeros(num, dtype=_NUMPY[sub[0]])
    return lambda: []
