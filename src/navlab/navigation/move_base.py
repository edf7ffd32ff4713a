"""The ``move_base`` node: a goal in, a global plan and velocity commands out, recoveries when stuck.

As ROS 1's move_base: two ``Costmap2DROS`` (``global_costmap`` in ``map``, ``local_costmap`` rolling in
``odom``), a global planner (``base_global_planner``) and a local controller (``base_local_planner``)
picked by their ROS plugin names, the PLANNING / CONTROLLING / CLEARING states with
``planner_frequency``, ``planner_patience``, ``controller_frequency``, ``controller_patience``,
``oscillation_timeout``/``oscillation_distance`` and ``recovery_behaviors`` in ROS order (navlab's
``escalate_recoveries``: moving ``oscillation_distance`` restarts the list only once the progress checker has
seen progress since the last recovery). Goals come on ``move_base_simple/goal`` or through
:meth:`MoveBase.send_goal` (actionlib's SimpleActionClient in spirit: feedback, cancel, result succeeded /
aborted with a reason / preempted); state on ``/move_base/status``. Services ``/move_base/clear_costmaps`` and
``/move_base/make_plan``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.geometry import transform_points2, wrap_angle
from navlab.navigation.costmap_ros import Costmap2DROS
from navlab.navigation.errors import NavigationError
from navlab.navigation.goal import GoalHandle, GoalState, MoveBaseState, RecoveryTrigger, status_array, with_headings
from navlab.navigation.keepout import held_up_at, with_keepouts
from navlab.navigation.move_base_config import (
    MOVE_BASE_DEFAULTS,
    check_move_base_params,
    make_recoveries,
    short_name,
)
from navlab.navigation.progress_checker import SimpleProgressChecker
from navlab.navigation.recovery import DEFAULT_RECOVERIES
from navlab.navigation.scan_points import ScanPoints
from navlab.plugins import ControlResult, PluginContext, make_plugin, plugin_names, resolve_name

Pose = tuple[float, float, float]


class MoveBase(Node):
    """ROS 1 move_base over navlab's costmaps, planners and controllers (see the module docstring)."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "move_base",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.listen_tf()  # a tf2 TransformListener, as in ROS: the graph shows it reading /tf
        p = {k: self.declare_parameter(k, v) for k, v in MOVE_BASE_DEFAULTS.items()}
        self.p = p
        check_move_base_params(p)
        raw_recoveries = self.declare_parameter("recovery_behaviors", [dict(r) for r in DEFAULT_RECOVERIES])
        private = self.fully_qualified_name
        self._scan_points = ScanPoints()  # both costmaps read the same scans: their points are worked out once
        self.global_costmap = self._costmap("global_costmap", private)
        self.local_costmap = self._costmap("local_costmap", private)
        self.costmaps = {"global": self.global_costmap, "local": self.local_costmap}
        gp = resolve_name("global_planner", str(p["base_global_planner"]))
        lp = resolve_name("controller", str(p["base_local_planner"]))
        self.planner_name, self.controller_name = short_name(gp), short_name(lp)
        self.planner = make_plugin(
            "global_planner",
            gp,
            self._namespace(self.planner_name),
            context=PluginContext(name=self.planner_name, rng=self.rng, footprint=self.local_costmap.layered.footprint),
            param="base_global_planner",
        )
        # as ROS's planners see them: the costmap's footprint (a round robot's radius, for costmap_2d's 16-gon)
        # and move_base's controller_frequency (they search the parameter upward)
        context = PluginContext(
            name=self.controller_name,
            rng=self.rng,
            footprint=self.local_costmap.layered.footprint,
            controller_frequency=p["controller_frequency"],
        )
        self.controller = make_plugin(
            "controller", lp, self._namespace(self.controller_name), context=context, param="base_local_planner"
        )
        self.recoveries = make_recoveries(
            raw_recoveries,
            self._namespace,
            conservative_reset_dist=p["conservative_reset_dist"],
            circumscribed_radius=self.local_costmap.layered.circumscribed_radius,
            rng=self.rng,
        )
        # Nav2's progress checker beside ROS 1's oscillation timeout: no progress -> the next recovery, then `stuck`
        self.progress_checker = SimpleProgressChecker(self._namespace("progress_checker"))
        # a parameter file may configure several planners (TrajectoryPlannerROS: and DWAPlannerROS:); ROS ignores
        # the sections of the ones not in use, and so does navlab
        for kind in ("global_planner", "controller"):
            for plugin in plugin_names(kind):
                self.accept_parameters(short_name(plugin))
        self.check_parameters()

        self.cmd_pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self.plan_pub = self.create_publisher(msgs.Path, f"{private}/{self.planner_name}/plan", 1, latched=True)
        self.local_plan_pub = self.create_publisher(msgs.Path, f"{private}/{self.controller_name}/local_plan", 1)
        self.goal_pub = self.create_publisher(msgs.PoseStamped, f"{private}/current_goal", 1, latched=True)
        self.status_pub = self.create_publisher(msgs.GoalStatusArray, f"{private}/status", 1)
        self.create_subscription(msgs.PoseStamped, "move_base_simple/goal", self._on_goal_msg, 1)
        self.create_subscription(msgs.Odometry, "odom", self._on_odom, 1)
        self.create_service(f"{private}/clear_costmaps", self._srv_clear)
        self.create_service(f"{private}/make_plan", self._srv_make_plan)
        self.create_timer(1.0 / p["controller_frequency"], self._cycle)
        self.create_timer(0.2, self._publish_status, idle=self._status_unwatched, idle_until_graph_changes=True)
        self.velocity = (0.0, 0.0)
        self.handle: GoalHandle | None = None
        self.state = MoveBaseState.IDLE
        self.global_plan: np.ndarray | None = None
        self._plan_local: tuple[np.ndarray, tuple[float, float, float], np.ndarray] | None = None  # the last one
        self._ids = 0
        self._reset_goal_state()

    # --- construction -------------------------------------------------------------------------------

    def _namespace(self, prefix: str) -> dict[str, Any]:
        self.accept_parameters(prefix)
        return self.get_parameters_by_prefix(prefix)

    def _costmap(self, name: str, private: str) -> Costmap2DROS:
        return Costmap2DROS(
            self, name, self._namespace(name), topic_prefix=f"{private}/{name}", scan_points=self._scan_points
        )

    # --- goals ---------------------------------------------------------------------------------------

    def _reset_goal_state(self) -> None:
        now = self.executor.now_ns
        self.recovery_index = 0
        self.recovery_trigger = RecoveryTrigger.NONE
        self.active_recovery: Any = None
        self.last_valid_plan_ns = now
        self.last_valid_control_ns = now
        self.last_plan_ns: int | None = None
        self.planning_retries = 0
        self.plan_failure = ""
        self.recovery_log: list[str] = []  # the recovery behaviors run for this goal, in order
        self.keepouts: list[tuple[float, float]] = []  # gaps that held the robot up (navigation.keepout)
        self.oscillation_pose: Pose | None = None
        self.last_oscillation_reset_ns = now
        self.progress_since_recovery = True  # the progress checker saw progress since the last recovery began
        if hasattr(self, "progress_checker"):
            self.progress_checker.reset(None, now / 1e9)

    def send_goal(
        self,
        x: float,
        y: float,
        yaw: float,
        *,
        frame_id: str = "map",
        feedback: Callable[[Pose], None] | None = None,
        on_done: Callable[[GoalHandle], None] | None = None,
    ) -> GoalHandle:
        """Start driving to (x, y, yaw) in ``frame_id``; a goal still running is PREEMPTED. Returns its handle."""
        if self.handle is not None and not self.handle.done():
            self._finish(GoalState.PREEMPTED, "preempted by a new goal")
        self._ids += 1
        handle = GoalHandle(
            (float(x), float(y), float(yaw)),
            frame_id.lstrip("/") or "map",
            self._ids,
            start_s=self.executor.now_ns / 1e9,
            feedback=feedback,
            on_done=on_done,
        )
        self.handle = handle
        if not all(math.isfinite(v) for v in handle.goal):
            self._finish(GoalState.ABORTED, f"goal {handle.goal} is not finite")
            return handle
        handle.state = GoalState.ACTIVE
        self._reset_goal_state()
        self.global_plan = None
        self.state = MoveBaseState.PLANNING
        self.goal_pub.publish(msgs.pose_stamped(self.executor.now_ns, handle.frame_id, *handle.goal))
        return handle

    def cancel_goal(self) -> None:
        """Stop the current goal (PREEMPTED) and the robot."""
        if self.handle is not None and not self.handle.done():
            self._finish(GoalState.PREEMPTED, "cancelled")

    def _on_goal_msg(self, msg: Any) -> None:
        self.send_goal(*msgs.pose2d(msg.pose), frame_id=str(msg.header.frame_id) or "map")

    def _on_odom(self, msg: Any) -> None:
        t = msg.twist.twist
        self.velocity = (float(t.linear.x), float(t.angular.z))

    def _finish(self, state: GoalState, reason: str = "") -> None:
        h = self.handle
        self.cmd_pub.publish(msgs.twist(0.0, 0.0))
        self.state = MoveBaseState.IDLE
        self.active_recovery = None
        if h is None or h.done():
            return
        h.state, h.reason, h.end_s = state, reason, self.executor.now_ns / 1e9
        log = self.get_logger().info if state == GoalState.SUCCEEDED else self.get_logger().warning
        log(f"goal {h.id} {state.lower()}" + (f": {reason}" if reason else ""))
        self._publish_status()
        if h.on_done is not None:
            h.on_done(h)

    # --- frames ----------------------------------------------------------------------------------------

    def _goal_in(self, frame: str) -> Pose | None:
        h = self.handle
        assert h is not None
        if h.frame_id == frame:
            return h.goal
        try:
            t = self.executor.tf.lookup_pose2d(frame, h.frame_id)
        except TfError:
            return None
        x, y = transform_points2(t, np.array([h.goal[:2]]))[0]
        return float(x), float(y), float(wrap_angle(h.goal[2] + t[2]))

    def _plan_in_local(self) -> np.ndarray | None:
        plan = self.global_plan
        gf, lf = self.global_costmap.global_frame, self.local_costmap.global_frame
        if plan is None or gf == lf:
            return plan
        try:
            t = self.executor.tf.lookup_pose2d(lf, gf)
        except TfError:
            return None
        last = self._plan_local
        if last is not None and last[0] is plan and last[1] == t:  # amcl moves map -> odom only now and then
            return last[2]  # the same read-only array: a controller may keep it and know it unchanged
        out = transform_points2(t, plan[:, :2])
        if plan.shape[1] > 2:
            out = np.column_stack([out, wrap_angle(plan[:, 2] + t[2])])
        out = np.ascontiguousarray(out, dtype=np.float64)
        out.flags.writeable = False
        self._plan_local = (plan, t, out)
        return out

    # --- planning --------------------------------------------------------------------------------------

    def _check_goal(self, goal: Pose) -> str | None:
        """Why ``goal`` cannot be planned to on the global costmap (None if it may be)."""
        g = self.global_costmap.costmap
        ij = g.world_to_cell(np.array([goal[:2]]))
        if not g.in_bounds(ij)[0]:
            x0, y0, x1, y1 = g.bounds()
            return (
                f"goal ({goal[0]:.2f}, {goal[1]:.2f}) is outside the map (x {x0:.2f}..{x1:.2f}, y {y0:.2f}..{y1:.2f})"
            )
        return None

    def _on_map_obstacle(self, goal: Pose) -> bool:
        """Whether ``goal`` (global frame) lies on an occupied cell of a static layer's map."""
        return any(layer.on_map_obstacle(goal[:2]) for layer in self.global_costmap.layered.map_layers)

    def make_plan(self, start: Pose, goal: Pose) -> np.ndarray | None:
        """A global plan (N, 2+) in the global costmap's frame, or None."""
        try:
            plan = self.planner.make_plan(with_keepouts(self.global_costmap.costmap, self.keepouts), start, goal)
        except NavigationError as exc:
            self.get_logger().debug(f"planner: {exc}")
            return None
        if plan is None or len(plan) == 0:
            return None
        return with_headings(np.asarray(plan, dtype=np.float64)[:, :2], goal[2])

    def _plan(self) -> bool:
        gf = self.global_costmap.global_frame
        start = self.global_costmap.robot_pose()
        goal = self._goal_in(gf)
        if start is None or goal is None:
            return False
        if self.global_costmap.updated_ns is None:
            self.global_costmap.update()
        why = self._check_goal(goal)
        if why is not None:
            self._finish(GoalState.ABORTED, why)
            return False
        plan = self.make_plan(start, goal)
        self.last_plan_ns = self.executor.now_ns
        if plan is None:
            self.planning_retries += 1
            self.plan_failure = str(self.planner.last_failure or "")
            if self._on_map_obstacle(goal):  # no recovery clears the map itself: say so now
                self._finish(
                    GoalState.ABORTED,
                    f"goal ({goal[0]:.2f}, {goal[1]:.2f}) is in an obstacle on the map"
                    + (f" ({self.plan_failure})" if self.plan_failure else ""),
                )
            return False
        self.global_plan = plan
        self.last_valid_plan_ns = self.executor.now_ns
        self.planning_retries = 0
        if self.recovery_trigger == RecoveryTrigger.PLANNING:
            self.recovery_index = 0
        self._publish_path(self.plan_pub, plan, gf)
        local = self._plan_in_local()
        if local is not None:
            self.controller.set_plan(local)
        return True

    # --- the cycle -------------------------------------------------------------------------------------

    def _cycle(self) -> None:
        if self.handle is None or self.handle.done() or self.state == MoveBaseState.IDLE:
            return
        now = self.executor.now_ns
        pose = self.local_costmap.robot_pose()
        if pose is None:
            return
        if self.handle.feedback is not None:
            self.handle.feedback(pose)
        self._check_oscillation(pose, now)
        if self.state == MoveBaseState.PLANNING:
            if self._plan():
                self.state = MoveBaseState.CONTROLLING
            elif self.handle.done():
                return
            elif self._timed_out(self.last_valid_plan_ns, self.p["planner_patience"]) or (
                0 <= self.p["max_planning_retries"] < self.planning_retries
            ):
                self._enter_clearing(RecoveryTrigger.PLANNING)
            self.cmd_pub.publish(msgs.twist(0.0, 0.0))
            return
        if self.state == MoveBaseState.CLEARING:
            self._clearing(pose)
            return
        self._controlling(pose, now)

    def _timed_out(self, since_ns: int, patience_s: float) -> bool:
        return (self.executor.now_ns - since_ns) / 1e9 > patience_s

    def _check_oscillation(self, pose: Pose, now: int) -> None:
        if (
            self.oscillation_pose is None
            or math.dist(pose[:2], self.oscillation_pose[:2]) >= self.p["oscillation_distance"]
        ):
            self.oscillation_pose = pose
            self.last_oscillation_reset_ns = now
            if self.recovery_trigger == RecoveryTrigger.OSCILLATION and (
                self.progress_since_recovery or not self.p["escalate_recoveries"]
            ):
                self.recovery_index = 0

    def _progressing(self, pose: Pose, now: int, local: np.ndarray | None) -> bool:
        """The progress checker's verdict (``local``: the plan, to the goal); progress restarts the recoveries."""
        ok = self.progress_checker.check(pose, now / 1e9, local[-1][:2] if local is not None and len(local) else None)
        if self.progress_checker.progressed:
            self.progress_since_recovery = True
            if self.recovery_trigger == RecoveryTrigger.PROGRESS:
                self.recovery_index = 0
        return ok

    def _controlling(self, pose: Pose, now: int) -> None:
        p = self.p
        if (
            p["planner_frequency"] > 0
            and self.last_plan_ns is not None
            and (now - self.last_plan_ns) / 1e9 >= 1.0 / p["planner_frequency"]
        ):
            if not self._plan() and self._timed_out(self.last_valid_plan_ns, p["planner_patience"]):
                self._enter_clearing(RecoveryTrigger.PLANNING)
                return
            if self.handle is None or self.handle.done():
                return
        local = self._plan_in_local()
        if local is not None:
            self.controller.set_plan(local)
        if self.controller.is_goal_reached(pose, self.velocity):
            self._finish(GoalState.SUCCEEDED)
            return
        if p["oscillation_timeout"] > 0 and self._timed_out(self.last_oscillation_reset_ns, p["oscillation_timeout"]):
            self._enter_clearing(RecoveryTrigger.OSCILLATION)
            return
        if not self._progressing(pose, now, local):
            self._enter_clearing(RecoveryTrigger.PROGRESS)
            return
        try:
            cmd: ControlResult | None = ControlResult.of(
                self.controller.compute_velocity(pose, self.velocity, self.local_costmap.costmap)
            )
        except NavigationError as exc:
            self.get_logger().debug(f"controller: {exc}")
            cmd = None
        if cmd is not None and cmd.valid and math.isfinite(cmd.v) and math.isfinite(cmd.w):
            self.last_valid_control_ns = now
            if self.recovery_trigger == RecoveryTrigger.CONTROLLING:
                self.recovery_index = 0
            self.cmd_pub.publish(msgs.twist(cmd.v, cmd.w))
        else:
            self.cmd_pub.publish(msgs.twist(0.0, 0.0))
            if self._timed_out(self.last_valid_control_ns, p["controller_patience"]):
                self._enter_clearing(RecoveryTrigger.CONTROLLING)
            elif p["planner_frequency"] <= 0:
                self.state = MoveBaseState.PLANNING  # ROS replans when the controller fails
        if cmd is not None and len(cmd.local_plan):
            self._publish_path(self.local_plan_pub, cmd.local_plan, self.local_costmap.global_frame)

    def _publish_path(self, pub: Any, poses: np.ndarray, frame: str) -> None:
        """``nav_msgs/Path`` of (N, 2+) poses, built only when someone listens (hundreds of messages each)."""
        if not self._unwatched(pub):
            pub.publish(msgs.path(self.executor.now_ns, frame, poses))

    # --- recoveries ------------------------------------------------------------------------------------

    def _enter_clearing(self, trigger: RecoveryTrigger) -> None:
        self.recovery_trigger = trigger
        self.progress_since_recovery = False
        if trigger == RecoveryTrigger.PROGRESS and self.progress_checker.toward_goal:  # plan around the hold-up
            gap = held_up_at(self.global_plan, self.global_costmap.costmap, self.global_costmap.robot_pose())
            if gap is not None:
                self.keepouts.append(gap)
        self.cmd_pub.publish(msgs.twist(0.0, 0.0))
        usable = [
            (n, r)
            for n, r in self.recoveries
            if self.p["clearing_rotation_allowed"] or "rotate" not in type(r).__name__.lower()
        ]
        if not self.p["recovery_behavior_enabled"] or self.recovery_index >= len(usable):
            reason = (
                self.progress_checker.stuck_reason(self.executor.now_ns / 1e9)
                if trigger == RecoveryTrigger.PROGRESS
                else trigger.abort_reason
            )
            if trigger == RecoveryTrigger.PLANNING and self.plan_failure:
                reason += f" ({self.plan_failure})"
            self._finish(GoalState.ABORTED, reason)
            return
        name, behavior = usable[self.recovery_index]
        self.recovery_index += 1
        self.recovery_log.append(name)
        pose = self.local_costmap.robot_pose()
        if pose is None:
            return
        self.get_logger().info(f"recovery {self.recovery_index}/{len(usable)}: {name} ({trigger.lower()} failed)")
        behavior.start(pose)
        self.active_recovery = behavior
        self.state = MoveBaseState.CLEARING

    def _clearing(self, pose: Pose) -> None:
        cmd = self.active_recovery.step(pose, self.costmaps) if self.active_recovery is not None else None
        if cmd is not None:
            self.cmd_pub.publish(msgs.twist(*cmd))
            return
        self.cmd_pub.publish(msgs.twist(0.0, 0.0))
        self.active_recovery = None
        now = self.executor.now_ns
        self.last_valid_plan_ns = self.last_valid_control_ns = self.last_oscillation_reset_ns = now
        self.oscillation_pose = pose
        # Nav2 restarts the progress clock with each new control run, from where the robot is now (the
        # baseline pose stays: a recovery that only wiggles does not count as progress)
        self.progress_checker.restart_clocks(now / 1e9)
        self.state = MoveBaseState.PLANNING

    # --- services and status ---------------------------------------------------------------------------

    def _srv_clear(self, request: Any = None) -> dict[str, Any]:
        for cm in self.costmaps.values():
            cm.clear()
        return {}

    def _srv_make_plan(self, request: Any) -> dict[str, Any]:
        """``make_plan``: request ``{"start": (x, y, yaw) | None, "goal": (x, y, yaw)}`` in the global frame
        (or PoseStamped messages); response ``{"plan": (N, 2+) array | None}``."""

        def pose(v: Any) -> Pose | None:
            if v is None:
                return None
            return msgs.pose2d(v.pose) if hasattr(v, "pose") else (float(v[0]), float(v[1]), float(v[2]))

        start = pose(request.get("start")) or self.global_costmap.robot_pose()
        goal = pose(request.get("goal"))
        if start is None or goal is None:
            return {"plan": None}
        self.global_costmap.update()
        return {"plan": self.make_plan(start, goal)}

    def _unwatched(self, pub: Any) -> bool:
        """Whether nobody subscribes to ``pub``'s topic or listens (recorder, echo, bridge)."""
        return not (pub.get_subscription_count() or self.executor.has_listeners)

    def _status_unwatched(self) -> bool:
        """The status timer's idle test: it parks until someone subscribes or listens."""
        return self._unwatched(self.status_pub)

    def _publish_status(self) -> None:
        if not self._status_unwatched():  # built only when someone listens, as the paths are
            self.status_pub.publish(status_array(self.handle))
