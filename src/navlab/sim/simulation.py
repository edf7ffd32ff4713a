"""The pure stepping API of the simulator: physics, wheel motors, true poses, lidar, IMU, spawning.

No topics and no clock here: time is integer nanoseconds of simulated time, advanced explicitly with
``advance_to``. The plugins in :mod:`navlab.sim.plugins` wrap this for the executor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from navlab.description.model import DiffDriveConfig, LidarConfig, RobotModel
from navlab.sim.builder import GROUP_ROBOT, RAY_GEOMGROUP, add_world_model, build_spec, compile_spec
from navlab.sim.errors import SimError
from navlab.world.model import ModelSpec, WorldModel

SPAWN_GAP = 0.0005  # m between the robot's lowest point and the floor when it is placed


@dataclass(frozen=True)
class Pose3D:
    """A pose in the world frame: position (m) and quaternion (w, x, y, z)."""

    position: np.ndarray
    quaternion: np.ndarray

    @property
    def yaw(self) -> float:
        """Heading about world z (rad)."""
        w, x, y, z = self.quaternion
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def lidar_angles(cfg: LidarConfig) -> np.ndarray:
    """Beam angles (rad, laser frame) as Gazebo spaces them: ``samples`` from min to max inclusive."""
    if cfg.samples < 1:
        raise SimError(f"lidar {cfg.name!r}: samples must be >= 1, got {cfg.samples}")
    if cfg.samples == 1:
        return np.array([cfg.min_angle])
    return np.linspace(cfg.min_angle, cfg.max_angle, cfg.samples)


class Simulation:
    """One robot in one world, stepped in MuJoCo.

    ``robot_pose`` = (x, y, yaw) of the robot's root link in the world (m, rad); the robot is placed
    with its lowest collision point on the floor. ``seed`` (int or ``numpy.random.Generator``) drives
    sensor noise when no generator is passed to a sensor call. ``timestep`` (s) defaults to the
    world's ``max_step_size``.
    """

    def __init__(
        self,
        robot: RobotModel | None,
        world: WorldModel,
        *,
        seed: int | np.random.Generator = 0,
        timestep: float | None = None,
        robot_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        self.robot = robot
        self.world = world
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        x, y, yaw = robot_pose
        self.spec, self.info = build_spec(robot, world, timestep=timestep, robot_pose=(x, y, 0.0, yaw))
        self.model = compile_spec(self.spec, f"world {world.name!r}")
        self.data = mujoco.MjData(self.model)
        self.dt_ns = round(self.model.opt.timestep * 1e9)
        self.time_ns = 0
        self._lidar_dirs: dict[int, np.ndarray] = {}
        self._refresh_ids()
        if robot is not None:
            self._place_on_floor()

    # --- bookkeeping ------------------------------------------------------------------------------

    def _refresh_ids(self) -> None:
        m = self.model
        name2id = mujoco.mj_name2id
        self._act = [name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in (self.info.wheel_actuators or ())]
        self._lidar_site = [name2id(m, mujoco.mjtObj.mjOBJ_SITE, n) for n in self.info.lidar_sites]
        self._imu_site = [name2id(m, mujoco.mjtObj.mjOBJ_SITE, n) for n in self.info.imu_sites]
        self._body = {link: name2id(m, mujoco.mjtObj.mjOBJ_BODY, b) for link, b in self.info.link_bodies.items()}
        self._joints: dict[str, tuple[int, int]] = {}
        if self.robot is not None:
            for joint in self.robot.joints:
                jid = name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint.name)
                if jid >= 0:
                    self._joints[joint.name] = (int(m.jnt_qposadr[jid]), int(m.jnt_dofadr[jid]))
            root = name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{self.robot.name}::root")
            self._root_qpos = int(m.jnt_qposadr[root])
            self._root_dof = int(m.jnt_dofadr[root])

    def _place_on_floor(self) -> None:
        """Lift or lower the robot so its lowest collision geom just clears z = 0."""
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        robot_geoms = np.flatnonzero((m.geom_group == GROUP_ROBOT) & (m.geom_contype != 0))
        lowest = math.inf
        for g in robot_geoms:
            rot = d.geom_xmat[g].reshape(3, 3)
            half = m.geom_aabb[g, 3:]
            centre = d.geom_xpos[g] + rot @ m.geom_aabb[g, :3]
            lowest = min(lowest, centre[2] - float(np.abs(rot[2]) @ half))
        if math.isfinite(lowest):
            d.qpos[self._root_qpos + 2] += SPAWN_GAP - lowest
        mujoco.mj_forward(m, d)

    @property
    def timestep(self) -> float:
        """Physics step (s)."""
        return float(self.model.opt.timestep)

    # --- stepping and actuation -------------------------------------------------------------------

    def advance_to(self, t_ns: int) -> None:
        """Integrate physics up to simulated time ``t_ns`` (whole steps; never goes back)."""
        n = (int(t_ns) - self.time_ns) // self.dt_ns
        if n > 0:
            m, d = self.model, self.data
            mujoco.mj_step(m, d, nstep=int(n))
            self.time_ns += int(n) * self.dt_ns
            # mj_step leaves poses and velocities of the state before its last integration: refresh them
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            mujoco.mj_comVel(m, d)

    def step(self, n: int = 1) -> None:
        """Integrate ``n`` physics steps."""
        self.advance_to(self.time_ns + n * self.dt_ns)

    def set_wheel_velocity_targets(self, left: float, right: float) -> None:
        """Target angular velocities (rad/s) of the diff-drive wheel joints; torque capped by the motors."""
        if not self._act:
            raise SimError("this robot has no diff_drive wheels to command")
        self.data.ctrl[self._act[0]] = left
        self.data.ctrl[self._act[1]] = right

    # --- state ------------------------------------------------------------------------------------

    def link_pose(self, link: str | None = None) -> Pose3D:
        """True world pose of a robot link's frame (default: the root link)."""
        b = self._body_id(link)
        return Pose3D(self.data.xpos[b].copy(), self.data.xquat[b].copy())

    def base_pose2d(self, link: str | None = None) -> tuple[float, float, float]:
        """True (x, y, yaw) of a robot link in the world (m, rad)."""
        pose = self.link_pose(link)
        return float(pose.position[0]), float(pose.position[1]), pose.yaw

    def link_velocity(self, link: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(linear m/s, angular rad/s) of a robot link's frame, both expressed in that link's frame."""
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_XBODY, self._body_id(link), vel, 1)
        return vel[3:].copy(), vel[:3].copy()

    def _body_id(self, link: str | None) -> int:
        if self.robot is None:
            raise SimError("there is no robot in this simulation")
        name = self.robot.root_link if link is None else link
        if name not in self._body:
            raise SimError(f"robot {self.robot.name!r} has no link {name!r}")
        return self._body[name]

    def joint_names(self) -> list[str]:
        """The robot's moving single-DOF joints (URDF order)."""
        return list(self._joints)

    def joint_position(self, name: str) -> float:
        """Joint angle (rad) or position (m)."""
        return float(self.data.qpos[self._joint(name)[0]])

    def joint_velocity(self, name: str) -> float:
        """Joint rate (rad/s or m/s)."""
        return float(self.data.qvel[self._joint(name)[1]])

    def _joint(self, name: str) -> tuple[int, int]:
        if name not in self._joints:
            raise SimError(f"unknown joint {name!r}; moving joints are {list(self._joints)}")
        return self._joints[name]

    def wheel_angles(self) -> tuple[float, float]:
        """(left, right) diff-drive wheel angles (rad), unwrapped."""
        dd = self._diff_drive()
        return self.joint_position(dd.left_joint), self.joint_position(dd.right_joint)

    def _diff_drive(self) -> DiffDriveConfig:
        if self.robot is None or self.robot.diff_drive is None:
            raise SimError("this robot has no diff_drive plugin")
        return self.robot.diff_drive

    # --- sensors ----------------------------------------------------------------------------------

    def scan(self, index: int = 0, rng: np.random.Generator | None = None) -> np.ndarray:
        """Ranges (m, float32) of lidar ``index`` from its site, Gazebo semantics.

        Rays start at ``range_min`` (closer surfaces are not seen), returns beyond ``range_max`` and
        misses are ``inf``; gaussian noise (``rng`` or the simulation's generator) is added to hits,
        which are then clamped to [range_min, range_max].
        """
        if self.robot is None or not 0 <= index < len(self.robot.lidars):
            raise SimError(f"no lidar number {index} on this robot")
        cfg = self.robot.lidars[index]
        m, d = self.model, self.data
        site = self._lidar_site[index]
        local = self._lidar_dirs.get(index)
        if local is None:
            angles = lidar_angles(cfg)
            local = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)
            self._lidar_dirs[index] = local
        n = len(local)
        vec = local @ d.site_xmat[site].reshape(3, 3).T
        pnt = d.site_xpos[site].copy()
        dist = np.empty(n)
        geomid = np.empty(n, dtype=np.int32)
        mujoco.mj_multiRay(m, d, pnt, vec.ravel(), RAY_GEOMGROUP, 1, -1, geomid, dist, None, n, cfg.range_max)
        dist[geomid < 0] = np.inf
        close = np.flatnonzero(dist < cfg.range_min)
        if len(close):
            one = np.empty(1, dtype=np.int32)
            for i in close:  # Gazebo's rays begin at range_min: look past what is closer
                r = mujoco.mj_ray(m, d, pnt + cfg.range_min * vec[i], vec[i], RAY_GEOMGROUP, 1, -1, one)
                dist[i] = cfg.range_min + r if r >= 0 else np.inf
        dist[dist > cfg.range_max] = np.inf
        gen = self.rng if rng is None else rng
        if cfg.noise_stddev > 0 or cfg.noise_mean != 0:
            noise = gen.normal(cfg.noise_mean, cfg.noise_stddev, n) if cfg.noise_stddev > 0 else cfg.noise_mean
            hit = np.isfinite(dist)
            dist[hit] = np.clip(dist[hit] + np.broadcast_to(noise, (n,))[hit], cfg.range_min, cfg.range_max)
        return dist.astype(np.float32)

    def imu(
        self, index: int = 0, rng: np.random.Generator | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(orientation quaternion w,x,y,z in world, angular velocity rad/s, linear acceleration m/s²) of IMU
        ``index``; rates and accelerations in the IMU frame, with the configured gaussian noise."""
        if self.robot is None or not 0 <= index < len(self.robot.imus):
            raise SimError(f"no imu number {index} on this robot")
        cfg = self.robot.imus[index]
        site = self.info.imu_sites[index]
        mujoco.mj_forward(self.model, self.data)
        quat, gyro, accel = (self.data.sensor(f"{site}_{k}").data.copy() for k in ("quat", "gyro", "accel"))
        gen = self.rng if rng is None else rng
        if cfg.gyro_noise_stddev > 0:
            gyro = gyro + gen.normal(0.0, cfg.gyro_noise_stddev, 3)
        if cfg.accel_noise_stddev > 0:
            accel = accel + gen.normal(0.0, cfg.accel_noise_stddev, 3)
        return quat, gyro, accel

    # --- spawning ---------------------------------------------------------------------------------

    def spawn(self, model: ModelSpec) -> list[str]:
        """Add an SDF model to the running world (state of everything else kept); returns its body names."""
        bodies = add_world_model(self.spec, model, self.info)
        self._recompile(f"model {model.name!r}")
        return bodies

    def remove(self, name: str) -> None:
        """Delete a model (by its SDF name) from the running world."""
        if name not in self.info.world_bodies:
            raise SimError(f"no model named {name!r}; models: {sorted(self.info.world_bodies)}")
        for body in self.info.world_bodies.pop(name):
            self.spec.delete(self.spec.body(body))
        self._recompile(f"world after removing {name!r}")

    def model_names(self) -> list[str]:
        """Names of the world's models (not the robot)."""
        return list(self.info.world_bodies)

    def model_pose(self, name: str) -> Pose3D:
        """World pose of a model's first link."""
        if name not in self.info.world_bodies:
            raise SimError(f"no model named {name!r}")
        b = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, self.info.world_bodies[name][0])
        return Pose3D(self.data.xpos[b].copy(), self.data.xquat[b].copy())

    def _recompile(self, what: str) -> None:
        ctrl = {n: self.data.ctrl[i] for n, i in zip(self.info.wheel_actuators or (), self._act, strict=False)}
        try:
            self.model, self.data = self.spec.recompile(self.model, self.data)
        except ValueError as exc:
            raise SimError(f"MuJoCo could not compile the {what}: {exc}") from None
        self._refresh_ids()
        for i, name in zip(self._act, ctrl, strict=False):
            self.data.ctrl[i] = ctrl[name]
        mujoco.mj_forward(self.model, self.data)
