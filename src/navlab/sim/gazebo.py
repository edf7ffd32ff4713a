"""The ``gazebo`` node: owns the Simulation, steps it with the executor's clock, runs the robot's
plugins and offers ``/spawn_entity`` and ``/delete_entity``; :func:`launch_sim` starts it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from navlab.core import Executor, Node
from navlab.description import RobotModel
from navlab.description import load_robot_named as _load_robot_named
from navlab.sim.contacts import CollisionPlugin
from navlab.sim.errors import SimError
from navlab.sim.extensions import SimExtensions
from navlab.sim.imu import ImuSensorPlugin
from navlab.sim.plugins import DiffDrivePlugin, GroundTruthPlugin, JointStatePlugin, LidarPlugin, RobotStatePublisher
from navlab.sim.simulation import Simulation
from navlab.sim.spawn import check_spawn_clear, check_start_pose, load_sdf_model, parse_spawn_spec, primitive_model
from navlab.world import ModelSpec, WorldModel, load_world


def load_robot_named(name_or_path: str, args: list[str] | None = None) -> RobotModel:
    """Deprecated alias (until the next release) of :func:`navlab.description.load_robot_named`."""
    _moved("load_robot_named", "navlab.description")
    return _load_robot_named(name_or_path, args)


def load_world_named(name_or_path: str) -> WorldModel:
    """Deprecated alias (until the next release) of :func:`navlab.world.load_world`."""
    _moved("load_world_named", "navlab.world.load_world")
    return load_world(name_or_path)


def _moved(name: str, new: str) -> None:
    import warnings

    from navlab.deprecation import NavlabDeprecationWarning

    warnings.warn(
        f"navlab.sim.{name} moved to {new}; the old name works until the next release",
        NavlabDeprecationWarning,
        stacklevel=3,
    )


class GazeboSim(Node):
    """Gazebo in a node. Parameters: ``world`` (shipped name or file, default ``room``), ``robot``
    (default ``mybot``), ``robot_args`` (xacro arguments, ``["name:=value"]``),
    ``x``/``y``/``yaw`` (spawn pose, m/rad), ``timestep`` (s; 0 = 2 ms or the world's larger
    ``max_step_size``), ``joint_state_rate`` and ``ground_truth_rate`` (Hz; 0 = off), ``seed``
    (sensor noise seed; -1 = the executor's), ``visuals`` (build render-only geoms; default off, faster).
    ``odometry_noise`` (relative std dev of each wheel encoder's scale error; navlab extension, default 0).
    ``cmd_timeout`` (s; navlab's diff-drive watchdog: stop the wheels when no cmd_vel came for this long;
    default 0 = off, as ROS 1's gazebo_ros_diff_drive, where the last command holds until a new one).
    ``publish_odom_tf`` (default true: as the robot's plugin tags / the controller's ``enable_odom_tf`` say;
    false: neither the diff-drive plugin nor the wheel controller sends tf odom → base, an EKF owns it).
    ``robot_model``/``world_model`` replace the files."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "gazebo",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        robot_model: RobotModel | None = None,
        world_model: WorldModel | None = None,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        world_name = self.declare_parameter("world", "room")
        robot_name = self.declare_parameter("robot", "mybot")
        robot_args = [str(a) for a in self.declare_parameter("robot_args", [])]
        pose = (self.declare_parameter("x", 0.0), self.declare_parameter("y", 0.0), self.declare_parameter("yaw", 0.0))
        timestep = self.declare_parameter("timestep", 0.0)
        js_rate = self.declare_parameter("joint_state_rate", 30.0)
        gt_rate = self.declare_parameter("ground_truth_rate", 50.0)
        seed = self.declare_parameter("seed", -1)
        visuals = self.declare_parameter("visuals", False)
        odometry_noise = self.declare_parameter("odometry_noise", 0.0)
        cmd_timeout = float(self.declare_parameter("cmd_timeout", 0.0))
        publish_odom_tf = bool(self.declare_parameter("publish_odom_tf", True))
        robot = robot_model if robot_model is not None else _load_robot_named(robot_name, robot_args)
        world = world_model if world_model is not None else load_world(world_name)
        extensions = SimExtensions(self)  # wheel controller and disturbances (navlab.sim.extensions)
        robot = extensions.robot(robot)
        js_rate = extensions.controllers.joint_state_rate or js_rate  # joint_state_controller's publish_rate
        for warning in [*robot.warnings, *world.warnings]:
            self.get_logger().warning(warning)
        check_start_pose(robot, world, pose)  # a start inside an obstacle is refused, not thrown 7 m
        self.robot = robot
        self.sim = Simulation(
            robot,
            world,
            seed=self.rng,
            timestep=timestep or None,
            robot_pose=pose,
            visuals=visuals or bool(robot.sensors.cameras),
        )  # cameras draw visuals
        self.sim.time_ns = executor.now_ns  # started late: physics time begins at the current time
        for warning in self.sim.info.warnings:
            self.get_logger().warning(warning)
        executor.add_stepper(self)
        self.plugins: list[Node] = []
        if robot.diff_drive is not None:
            if odometry_noise > 0:
                robot.diff_drive.odometry_noise = odometry_noise
            if cmd_timeout > 0:
                robot.diff_drive.cmd_timeout = cmd_timeout
            if not publish_odom_tf:  # an EKF owns odom -> base
                robot.diff_drive.publish_tf = False
                if extensions.controller:
                    extensions.controller["enable_odom_tf"] = False
            drive = extensions.drive_plugin(executor, namespace, self.sim)
            self.plugins.append(
                drive or DiffDrivePlugin(executor, namespace=namespace, sim=self.sim, config=robot.diff_drive)
            )
        self.plugins += [
            LidarPlugin(executor, namespace=namespace, sim=self.sim, index=i) for i in range(len(robot.lidars))
        ]
        imus = [ImuSensorPlugin(executor, namespace=namespace, sim=self.sim, index=i) for i in range(len(robot.imus))]
        self.plugins += imus
        self._imu_timers = [t for imu in imus for t in imu.timers]  # MuJoCo's sensors only while one is awake
        self._sensors_on = True
        self.plugins.append(
            JointStatePlugin(executor, parameters={"publish_frequency": js_rate}, namespace=namespace, sim=self.sim)
        )
        self.plugins.append(RobotStatePublisher(executor, namespace=namespace, sim=self.sim))
        p3d_topics = {p.topic for p in robot.ground_truths}
        if gt_rate > 0 and "/ground_truth/odom" not in p3d_topics:  # navlab's own, for evaluation
            base = robot.diff_drive.robot_base_frame if robot.diff_drive else robot.root_link
            self.plugins.append(
                GroundTruthPlugin(
                    executor, parameters={"bodyName": base, "updateRate": gt_rate}, namespace=namespace, sim=self.sim
                )
            )
        self.plugins += [
            GroundTruthPlugin(
                executor,
                name=p.name,
                namespace=namespace,
                sim=self.sim,
                parameters={
                    "bodyName": p.link,
                    "topicName": p.topic,
                    "frameName": p.frame_id,
                    "updateRate": p.update_rate,
                },
            )
            for p in robot.ground_truths
        ]  # the robot's own p3d plugins
        self.plugins += extensions.plugins(executor, namespace, self.sim)
        if robot.sensors.all():  # cameras, 3D lidars, ranges, bumpers (imported only for a robot that has them)
            from navlab.sim.sensor_plugins import sensor_plugins

            self.plugins += sensor_plugins(executor, namespace, self.sim)
        if robot is not None:  # Gazebo's bumper: what the robot touches, on /collisions
            self.plugins.append(CollisionPlugin(executor, namespace=namespace, sim=self.sim))
        if seed >= 0:
            import zlib

            import numpy as np

            for node in [self, *self.plugins]:
                name_key = zlib.crc32(node.fully_qualified_name.encode())
                node.rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, name_key])))
        self.create_service("/spawn_entity", self._spawn_service)
        self.create_service("/delete_entity", self._delete_service)

    def advance_to(self, t_ns: int) -> None:
        """Stepper hook: integrate physics up to ``t_ns``; MuJoCo's sensors are computed only while an IMU plugin's
        timer is awake (parked: nobody reads it), so its first reading after waking is what it always was."""
        awake = False
        for t in self._imu_timers:  # a loop, not any(genexpr): this runs before every event
            if not t.parked:
                awake = True
                break
        if awake != self._sensors_on:
            self._sensors_on = awake
            self.sim.compute_sensors(awake)
        self.sim.advance_to(t_ns)

    def spawn(self, model: ModelSpec) -> list[str]:
        """Add a model to the running world; returns its MuJoCo body names."""
        check_spawn_clear(self.robot, self.sim.base_pose2d(), model)
        bodies = self.sim.spawn(model)
        self.get_logger().info(f"spawned {model.name!r}")
        return bodies

    def spawn_primitive(self, kind: str, name: str, dims: tuple[float, ...], **place: Any) -> list[str]:
        """Spawn a box (sx, sy, sz), cylinder (radius, length) or sphere (radius,); see ``primitive_model``."""
        return self.spawn(primitive_model(kind, name, dims, **place))

    def delete(self, name: str) -> None:
        """Remove a model from the running world."""
        self.sim.remove(name)
        self.get_logger().info(f"deleted {name!r}")

    def _spawn_service(self, request: Any) -> dict[str, Any]:
        """``/spawn_entity``: request is a ModelSpec, a spec string (``box:x=1,...``) or a dict with
        ``name`` and ``kind`` + ``dims`` (+ placement keys), or ``xml``/``file`` (an SDF model)."""
        try:
            if isinstance(request, ModelSpec):
                model = request
            elif isinstance(request, str):
                model, _ = parse_spawn_spec(request)
            elif isinstance(request, dict) and "file" in request:
                place = {k: request[k] for k in ("x", "y", "z", "yaw") if k in request}
                model = load_sdf_model(Path(request["file"]), name=request.get("name"), **place)
            elif isinstance(request, dict) and "kind" in request:
                extra = {k: v for k, v in request.items() if k not in ("kind", "name", "dims")}
                name = request["name"] if "name" in request else request["kind"]
                model = primitive_model(request["kind"], name, tuple(request["dims"]), **extra)
            else:
                raise SimError(
                    f"/spawn_entity: cannot spawn {request!r}; give a ModelSpec, a spec string "
                    "or a dict with kind+dims or file"
                )
            self.spawn(model)
        except SimError as exc:
            return {"success": False, "status_message": str(exc)}
        return {"success": True, "status_message": f"spawned {model.name}"}

    def _delete_service(self, request: Any) -> dict[str, Any]:
        """``/delete_entity``: request is the model name or ``{"name": ...}``."""
        name = request.get("name") if isinstance(request, dict) else request
        try:
            self.delete(str(name))
        except SimError as exc:
            return {"success": False, "status_message": str(exc)}
        return {"success": True, "status_message": f"deleted {name}"}


def launch_sim(
    executor: Executor,
    *,
    world: str | WorldModel = "room",
    robot: str | RobotModel = "mybot",
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    seed: int | None = None,
    **parameters: Any,
) -> GazeboSim:
    """Start the simulator with its plugins on ``executor``; returns the ``gazebo`` node.

    ``world``/``robot``: shipped names, file paths or loaded models; ``pose`` = (x, y, yaw) of the
    robot; ``seed``: sensor-noise seed (default: the executor's); other keywords are GazeboSim
    parameters (``timestep``, ``joint_state_rate``, ``ground_truth_rate``).
    """
    params: dict[str, Any] = {"x": pose[0], "y": pose[1], "yaw": pose[2], **parameters}
    if seed is not None:
        params["seed"] = int(seed)
    kwargs: dict[str, Any] = {}
    if isinstance(world, WorldModel):
        kwargs["world_model"] = world
    else:
        params["world"] = str(world)
    if isinstance(robot, RobotModel):
        kwargs["robot_model"] = robot
    else:
        params["robot"] = str(robot)
    return GazeboSim(executor, parameters=params, **kwargs)
