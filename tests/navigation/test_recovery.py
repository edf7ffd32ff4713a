"""Recovery behaviors in the simulator: a back-up remembers what the laser saw before the local window was cleared."""

from __future__ import annotations

import math
from typing import Any

from navlab import msgs
from navlab.experiments.session import start_run
from navlab.navigation.recovery import BackUpRecovery
from navlab.sim import primitive_model


class _Turn:
    """Turn in place to ``yaw`` (rad), then done: puts what the laser saw ahead behind the robot."""

    def __init__(self, yaw: float) -> None:
        self.yaw = yaw

    def step(self, pose: Any, costmaps: Any) -> tuple[float, float] | None:
        err = math.remainder(self.yaw - pose[2], 2 * math.pi)
        return None if abs(err) < 0.05 else (0.0, max(-1.0, min(1.0, 2.0 * err)))


def test_a_back_up_after_the_local_window_was_cleared_stops_short_of_a_cylinder_behind_the_laser() -> None:
    """The Jackal's 270° laser sees a cylinder ahead, the robot turns its back to it (the cylinder is now in the
    blind 90°), the local window is cleared (clutter's first recovery) and forgets it. A 1.5 m back-up then
    stops on the global costmap's memory of the cylinder instead of driving into it."""
    run = start_run("navigation_mapless", world="empty", robot="jackal")
    run.gazebo.spawn(primitive_model("cylinder", "post", (0.075, 1.0), x=1.0, y=0.0))
    mb: Any = run.node("move_base")
    steps: list[Any] = [_Turn(math.pi)]

    def tick() -> None:
        pose = mb.local_costmap.robot_pose()
        cmd = steps[0].step(pose, mb.costmaps) if steps and pose is not None else None
        if cmd is None and steps:
            steps.pop(0)
        mb.cmd_pub.publish(msgs.twist(*(cmd or (0.0, 0.0))))

    mb.create_timer(0.05, tick)
    run.run(8.0, until=lambda: not steps)
    assert not steps and abs(math.remainder(run.sim.base_pose2d()[2] - math.pi, 2 * math.pi)) < 0.1
    run.run(0.5)
    mb.local_costmap.clear_outside(0.0)
    post = (1.0 - run.sim.base_pose2d()[0], 0.0)  # odom starts at the world origin
    assert mb.local_costmap.cost_at(post) == 0 and mb.global_costmap.cost_at(post) == 254
    backup = BackUpRecovery({"backup_dist": 1.5, "backup_speed": 0.25})
    backup.start(mb.local_costmap.robot_pose())
    steps.append(backup)
    run.run(10.0, until=lambda: not steps)
    bumper = next(p for p in run.gazebo.plugins if type(p).__name__ == "CollisionPlugin")
    x = run.sim.base_pose2d()[0]
    assert not steps and bumper.collisions == 0
    assert 0.3 < x < 1.0 - 0.075 - 0.254, x  # it backed up, and its rear (0.254 m) stopped short of the post


def test_escalating_recoveries_restart_only_after_progress() -> None:
    """ROS 1 restarts ``recovery_behaviors`` whenever the robot moves ``oscillation_distance`` (0.2 m in clutter), so
    a robot rocking in a pocket runs the first recoveries over and over. With ``escalate_recoveries`` the list
    restarts only once the progress checker has seen progress since the last recovery began."""
    from navlab.navigation.goal import RecoveryTrigger

    run = start_run("navigation_mapless", world="empty", robot="jackal")
    mb: Any = run.node("move_base")
    now = run.executor.now_ns

    def rocked(escalate: bool) -> int:
        """The recovery to run next after the third recovery, once the robot has moved 0.3 m."""
        mb.p["escalate_recoveries"] = escalate
        mb.recovery_index, mb.oscillation_pose = 3, (0.0, 0.0, 0.0)
        mb._enter_clearing(RecoveryTrigger.OSCILLATION)  # the fourth starts: no progress since
        mb.active_recovery, mb.recovery_index = None, 3
        mb._check_oscillation((0.3, 0.0, 0.0), now)
        return int(mb.recovery_index)

    assert rocked(False) == 0  # ROS 1: back to the first
    assert rocked(True) == 3  # escalating: the next one
    mb.progress_checker.reset((0.0, 0.0, 0.0), now / 1e9)
    mb._progressing((1.0, 0.0, 0.0), now, None)  # 1 m from the checker's baseline: progress
    mb._check_oscillation((0.0, 0.0, 0.0), now)
    assert mb.recovery_index == 0
