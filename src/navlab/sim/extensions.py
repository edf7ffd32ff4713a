"""The ``gazebo`` node's navlab extensions, read from its parameters: the wheel speed controller that
replaces the ``gazebo_ros_diff_drive`` plugin, and the disturbances of a run.

Parameters (nested, as a ROS YAML file loaded into the ``gazebo`` node writes them):

- a ros_control YAML's controllers, found by their ``type`` (see :mod:`navlab.sim.ros_control`): a
  ``diff_drive_controller/DiffDriveController`` under any name (``mobile_base_controller.*`` also without a type;
  see :mod:`navlab.sim.wheel_control`) replaces the robot's ``gazebo_ros_diff_drive`` plugin (the default) or
  drives a ``gazebo_ros_control`` robot; a ``joint_state_controller/JointStateController`` sets the joint states'
  ``publish_rate``.
- ``gazebo_ros_control.control_period`` (s, default 0.01) and ``gazebo_ros_control.pid_gains.<joint>.{p,i,d,i_clamp}``.
- ``disturbances.*``: see :mod:`navlab.sim.disturbances`.
"""

from __future__ import annotations

from typing import Any

from navlab.core import Executor, Node
from navlab.description import RobotModel
from navlab.sim.disturbances import SlipPatchPlugin, add_payload, disturbed_robot, parse_disturbances
from navlab.sim.errors import SimError
from navlab.sim.ros_control import drive_from_controller, find_controllers
from navlab.sim.simulation import Simulation

PREFIXES = ("gazebo_ros_control", "disturbances")


def _nest(flat: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in flat.items():
        *path, last = key.split(".")
        node = out
        for part in path:
            node = node.setdefault(part, {})
        node[last] = value
    return out


class SimExtensions:
    """What the ``gazebo`` node's extension parameters ask for; built from the node before its simulation."""

    def __init__(self, node: Node) -> None:
        tops = {k.split(".")[0] for k in node.list_parameters() if "." in k}
        self.controllers = find_controllers(
            {f"{t}.{k}": v for t in tops for k, v in node.get_parameters_by_prefix(t).items()}
        )
        self.controller_name = self.controllers.diff_drive or ""
        self.controller = node.get_parameters_by_prefix(self.controller_name) if self.controller_name else {}
        ros_control = node.get_parameters_by_prefix("gazebo_ros_control")
        for prefix in (*PREFIXES, *self.controllers.names):
            node.accept_parameters(prefix)
        for ctrl in self.controllers.ignored:
            node.get_logger().warning(f"ros_control controller {ctrl} is not simulated; ignored")
        where = f"node {node.fully_qualified_name}"
        self.control_period = float(ros_control.pop("control_period", 0.01))
        gains = _nest(ros_control)
        unknown = sorted(set(gains) - {"pid_gains"})
        if unknown:
            raise SimError(
                f"{where}: unknown gazebo_ros_control parameter(s) {unknown} "
                "(known: control_period, pid_gains.<joint>.{p,i,d,i_clamp})"
            )
        self.pid_gains: dict[str, Any] = gains.get("pid_gains", {})
        self.disturbances = parse_disturbances(
            _nest(node.get_parameters_by_prefix("disturbances")), where=f"{where}: disturbances"
        )

    def robot(self, robot: RobotModel) -> RobotModel:
        """The robot as simulated: a ``gazebo_ros_control`` robot's drive from its diff-drive controller; wheel
        radius errors, motor torque."""
        if robot.ros_control is not None and robot.diff_drive is None and self.controller:
            robot.diff_drive = drive_from_controller(robot, self.controller)
        return disturbed_robot(robot, self.disturbances)

    def drive_plugin(self, executor: Executor, namespace: str, sim: Simulation) -> Node | None:
        """The wheel controller node when ``mobile_base_controller`` is configured (None: use the Gazebo plugin)."""
        if not self.controller:
            return None
        from navlab.sim.wheel_control import DiffDriveController

        assert sim.robot is not None and sim.robot.diff_drive is not None
        ros_control = sim.robot.ros_control
        period = (
            self.control_period if ros_control is None or not ros_control.control_period else ros_control.control_period
        )
        return DiffDriveController(
            executor,
            name=self.controller_name,
            parameters=self.controller,
            namespace=namespace,
            sim=sim,
            config=sim.robot.diff_drive,
            pid_gains=self.pid_gains,
            control_period=period,
            velocity_interface=ros_control is not None,
        )

    def plugins(self, executor: Executor, namespace: str, sim: Simulation) -> list[Node]:
        """Apply the payload; the slip-patch node when there are patches."""
        d = self.disturbances
        add_payload(sim, d.payload_mass)
        if not d.slip_patches:
            return []
        return [SlipPatchPlugin(executor, namespace=namespace, sim=sim, patches=d.slip_patches, rate=d.slip_rate)]
