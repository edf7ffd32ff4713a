"""navlab's services as ROS 1 services: ``std_srvs/Empty`` ones, ``nav_msgs/GetMap``, ``nav_msgs/GetPlan``
and gazebo's model spawning and deletion (``gazebo_msgs``), each run in the executor's thread.

navlab's services take and return plain values (dicts, messages); an adapter per service type turns the
ROS 1 request into that call and its result into the ROS 1 response.
"""

from __future__ import annotations

import functools
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from navlab import msgs
from navlab.core import Executor
from navlab.ros1.errors import Ros1Error
from navlab.ros1.wire import Service

if TYPE_CHECKING:
    from navlab.ros1.bridge import RosBridge

T = TypeVar("T")
CALL_TIMEOUT = 30.0  # wall seconds a service call waits for the executor

# navlab service (last name part) -> (ROS 1 name it is offered under, or None for the same, ROS 1 service type)
SERVICES: dict[str, tuple[str | None, str]] = {
    "clear_costmaps": (None, "std_srvs/srv/Empty"),
    "global_localization": (None, "std_srvs/srv/Empty"),
    "request_nomotion_update": (None, "std_srvs/srv/Empty"),
    "static_map": (None, "nav_msgs/srv/GetMap"),
    "make_plan": (None, "nav_msgs/srv/GetPlan"),
    "spawn_entity": ("/gazebo/spawn_sdf_model", "gazebo_msgs/srv/SpawnModel"),
    "delete_entity": ("/gazebo/delete_model", "gazebo_msgs/srv/DeleteModel"),
}


def offer_services(bridge: RosBridge) -> None:
    """Register every service of the run that has a ROS 1 counterpart."""
    for name in list(bridge.ex.services):
        entry = SERVICES.get(name.rsplit("/", 1)[-1])
        if entry is None:
            continue
        wire_name, stype_name = entry
        wire_name = wire_name or name
        stype = bridge.types.services[stype_name]
        caller = name.rsplit("/", 1)[0] or bridge.name
        caller = caller if caller in bridge.ex.nodes else bridge.name
        adapter = _ADAPTERS[stype_name]
        srv = Service(wire_name, stype, caller, _handler(bridge, name, stype.request, stype.response, adapter))
        bridge.tcpros.services[wire_name] = srv
        bridge._jobs.put(
            functools.partial(bridge._master, "registerService", srv.caller_id, srv.name, bridge.tcpros.uri, bridge.uri)
        )


def call_in_executor(executor: Executor, fn: Callable[[], T], timeout: float = 30.0) -> T:
    """Run ``fn()`` in the executor's thread (through its inbox) and return its value or raise its error."""
    out: list[Any] = []
    done = threading.Event()

    def run() -> None:
        try:
            out.append(fn())
        except Exception as exc:
            out.append(exc)
        finally:
            done.set()

    executor.post(run)
    if not done.wait(timeout):
        raise Ros1Error(f"the run did not answer within {timeout:.0f} s (is it paused?)")
    if isinstance(out[0], Exception):
        raise out[0]
    return out[0]


Adapter = Callable[["RosBridge", Callable[[Any], Any], Any, Any], Any]


def _handler(bridge: RosBridge, name: str, req_type: str, res_type: str, adapter: Adapter) -> Callable[[bytes], bytes]:
    def handle(raw: bytes) -> bytes:
        request = bridge.types.deserialize(raw, req_type)
        response = bridge.types.store.types[res_type]
        result = call_in_executor(
            bridge.ex,
            lambda: adapter(bridge, lambda r: bridge.ex.call_service(name, r), request, response),
            CALL_TIMEOUT,
        )
        return bridge.types.serialize(result, res_type)

    return handle


def _empty(bridge: RosBridge, call: Callable[[Any], Any], request: Any, response: type) -> Any:
    call(None)
    return response()


def _get_map(bridge: RosBridge, call: Callable[[Any], Any], request: Any, response: type) -> Any:
    return response(map=bridge.types.to_ros1(call(None), "nav_msgs/msg/OccupancyGrid"))


def _get_plan(bridge: RosBridge, call: Callable[[Any], Any], request: Any, response: type) -> Any:
    start = bridge.types.to_ros2(request.start, "geometry_msgs/msg/PoseStamped")
    goal = bridge.types.to_ros2(request.goal, "geometry_msgs/msg/PoseStamped")
    empty_start = not start.header.frame_id  # move_base: an empty start frame means "from the robot's pose"
    plan = call({"start": None if empty_start else start, "goal": goal}).get("plan")
    stamp = bridge.ex.now_ns
    frame = goal.header.frame_id or "map"
    path = msgs.path(stamp, frame, [] if plan is None else plan)
    return response(plan=bridge.types.to_ros1(path, "nav_msgs/msg/Path"))


def _spawn(bridge: RosBridge, call: Callable[[Any], Any], request: Any, response: type) -> Any:
    from navlab.msgs import yaw_from_quaternion

    pose = request.initial_pose
    with tempfile.TemporaryDirectory(prefix="navlab-spawn-") as folder:  # navlab spawns SDF models from files
        path = Path(folder) / "model.sdf"
        path.write_text(request.model_xml)
        result = call(
            {
                "file": str(path),
                "name": request.model_name,
                "x": pose.position.x,
                "y": pose.position.y,
                "z": pose.position.z,
                "yaw": yaw_from_quaternion(pose.orientation),
            }
        )
    return response(success=bool(result.get("success", True)), status_message=str(result.get("status_message", "")))


def _delete(bridge: RosBridge, call: Callable[[Any], Any], request: Any, response: type) -> Any:
    result = call({"name": request.model_name})
    return response(success=bool(result.get("success")), status_message=str(result.get("status_message", "")))


_ADAPTERS: dict[str, Adapter] = {
    "std_srvs/srv/Empty": _empty,
    "nav_msgs/srv/GetMap": _get_map,
    "nav_msgs/srv/GetPlan": _get_plan,
    "gazebo_msgs/srv/SpawnModel": _spawn,
    "gazebo_msgs/srv/DeleteModel": _delete,
}
