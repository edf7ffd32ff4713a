"""move_base's actionlib interface on the wire: ``/move_base/goal``, ``cancel``, ``status``, ``feedback`` and
``result`` with ``move_base_msgs`` and ``actionlib_msgs`` types, so a rospy or roscpp
``SimpleActionClient('move_base', MoveBaseAction)`` drives navlab's move_base.

The action server is navlab's move_base node itself: goals go to its ``send_goal`` (a new goal preempts the
running one, as move_base's simple action server does), cancels to ``cancel_goal``; its goal handles' state
changes come back as status, feedback and result messages.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from navlab import msgs
from navlab.core import Timer

if TYPE_CHECKING:
    from navlab.ros1.bridge import RosBridge

# actionlib_msgs/GoalStatus codes
PENDING, ACTIVE, PREEMPTED, SUCCEEDED, ABORTED = 0, 1, 2, 3, 4
CODE = {"PENDING": PENDING, "ACTIVE": ACTIVE, "PREEMPTED": PREEMPTED, "SUCCEEDED": SUCCEEDED, "ABORTED": ABORTED}
STATUS_PERIOD_NS = 200_000_000  # move_base publishes its status at 5 Hz


@runtime_checkable
class GoalServer(Protocol):
    """What the action server needs of navlab's move_base node."""

    fully_qualified_name: str

    def send_goal(
        self, x: float, y: float, yaw: float, *, frame_id: str = "map", feedback: Any = None, on_done: Any = None
    ) -> Any: ...

    def cancel_goal(self) -> None: ...


def offer_move_base(bridge: RosBridge) -> None:
    """Serve the actionlib interface of every move_base node of the run."""
    for name, node in bridge.ex.nodes.items():
        if name.rsplit("/", 1)[-1] == "move_base" and isinstance(node, GoalServer):
            MoveBaseActionServer(bridge, node)


class MoveBaseActionServer:
    """The five actionlib topics of one move_base node, under its name."""

    def __init__(self, bridge: RosBridge, node: GoalServer) -> None:
        self.bridge, self.node = bridge, node
        ns = node.fully_qualified_name
        self.types = bridge.types
        self.store = bridge.types.store.types
        self.goals: dict[str, tuple[Any, Any]] = {}  # goal id -> (actionlib GoalID, navlab handle)
        self.status_pub = bridge.offer(f"{ns}/status", "actionlib_msgs/msg/GoalStatusArray", ns)
        self.feedback_pub = bridge.offer(f"{ns}/feedback", "move_base_msgs/msg/MoveBaseActionFeedback", ns)
        self.result_pub = bridge.offer(f"{ns}/result", "move_base_msgs/msg/MoveBaseActionResult", ns)
        bridge.subscribe(
            f"{ns}/goal",
            "move_base_msgs/msg/MoveBaseActionGoal",
            ns,
            self._receiver("move_base_msgs/msg/MoveBaseActionGoal", self._on_goal),
        )
        bridge.subscribe(
            f"{ns}/cancel",
            "actionlib_msgs/msg/GoalID",
            ns,
            self._receiver("actionlib_msgs/msg/GoalID", self._on_cancel),
        )
        self.timer = Timer(bridge.ex, STATUS_PERIOD_NS, self._publish_status, 0, bridge.ex.now_ns)

    def _receiver(self, ros1: str, handler: Any) -> Any:
        def deliver(payload: bytes) -> None:
            msg = self.types.deserialize(payload, ros1)
            self.bridge.ex.post(lambda: handler(msg))

        return deliver

    # --- executor thread --------------------------------------------------------------------------------

    def _on_goal(self, action_goal: Any) -> None:
        goal_id = action_goal.goal_id
        if not goal_id.id:  # actionlib's servers name anonymous goals
            goal_id = self.store["actionlib_msgs/msg/GoalID"](
                stamp=msgs.time_from_ns(self.bridge.ex.now_ns), id=f"{self.node.fully_qualified_name}-{len(self.goals)}"
            )
        target = action_goal.goal.target_pose
        x, y, yaw = msgs.pose2d(target.pose)
        key = goal_id.id

        def feedback(pose: Any) -> None:
            self._feedback(key, pose)

        def done(handle: Any) -> None:
            self._result(key)

        handle = self.node.send_goal(
            x, y, yaw, frame_id=target.header.frame_id or "map", feedback=feedback, on_done=done
        )
        self.goals[key] = (goal_id, handle)
        if handle.done():
            self._result(key)
        self._publish_status()

    def _on_cancel(self, goal_id: Any) -> None:
        """actionlib's cancel policy: an empty id and zero stamp cancels all; an id cancels that goal; a stamp
        cancels every goal given before it."""
        stamp_ns = msgs.ns_from_time(goal_id.stamp)
        for key, (gid, handle) in self.goals.items():
            hit = (
                (not goal_id.id and stamp_ns == 0)
                or key == goal_id.id
                or (stamp_ns and msgs.ns_from_time(gid.stamp) <= stamp_ns)
            )
            if hit and not handle.done():  # only the newest goal can still run: a new goal preempts the last
                self.node.cancel_goal()

    def _status(self, key: str) -> Any:
        gid, handle = self.goals[key]
        return self.store["actionlib_msgs/msg/GoalStatus"](
            goal_id=gid, status=CODE.get(handle.state, ABORTED), text=handle.reason
        )

    def _header(self) -> Any:
        return self.store["std_msgs/msg/Header"](seq=0, stamp=msgs.time_from_ns(self.bridge.ex.now_ns), frame_id="")

    def _publish_status(self) -> None:
        if not self.status_pub.connections:
            return
        latest = list(self.goals)[-20:]  # recent goals, as actionlib keeps finished ones for a while
        msg = self.store["actionlib_msgs/msg/GoalStatusArray"](
            header=self._header(), status_list=[self._status(k) for k in latest]
        )
        self.status_pub.send(self.types.serialize(msg, "actionlib_msgs/msg/GoalStatusArray"))

    def _feedback(self, key: str, pose: Any) -> None:
        if not self.feedback_pub.connections or key not in self.goals:
            return
        _gid, handle = self.goals[key]
        position = self.types.to_ros1(
            msgs.pose_stamped(self.bridge.ex.now_ns, handle.frame_id, *pose), "geometry_msgs/msg/PoseStamped"
        )
        msg = self.store["move_base_msgs/msg/MoveBaseActionFeedback"](
            header=self._header(),
            status=self._status(key),
            feedback=self.store["move_base_msgs/msg/MoveBaseFeedback"](base_position=position),
        )
        self.feedback_pub.send(self.types.serialize(msg, "move_base_msgs/msg/MoveBaseActionFeedback"))

    def _result(self, key: str) -> None:
        msg = self.store["move_base_msgs/msg/MoveBaseActionResult"](
            header=self._header(), status=self._status(key), result=self.store["move_base_msgs/msg/MoveBaseResult"]()
        )
        self.result_pub.send(self.types.serialize(msg, "move_base_msgs/msg/MoveBaseActionResult"))
        self._publish_status()
