"""The pure stepping API of the simulator: physics, wheel motors, true poses, lidar, IMU, spawning.

No topics and no clock here: time is integer nanoseconds of simulated time, advanced explicitly with
``advance_to``. The plugins in :mod:`navlab.sim.plugins` wrap this for the executor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from navlab.description import DiffDriveConfig, LidarConfig, RobotModel
from navlab.geometry import quat_from_rpy, quat_from_yaw, wxyz_from_xyzw, xyzw_from_wxyz, yaw_from_quat
from navlab.sim.builder import GROUND_CONTACT_BIT, GROUP_ROBOT, RAY_GEOMGROUP, mj_quat_from_rpy
from navlab.sim.clearance import clearance
from navlab.sim.errors import SimError
from navlab.sim.lidar_noise import NormalDraws
from navlab.sim.lidar_rays import beam_dirs, cast_primitives, ray_geom_sets, scan_args, scan_with
from navlab.sim.lidar_rays import lidar_angles as lidar_angles  # re-exported: its home before the split
from navlab.sim.raycast import finish_ranges, multiray
from navlab.sim.scene import add_world_model, build_spec, compile_spec, remove_world_model
from navlab.world import ModelSpec, WorldModel

SPAWN_GAP = 0.0005  # m between the robot's lowest point and the floor when it is placed


@dataclass(frozen=True)
class Pose3D:
    """A pose in the world frame: position (m) and quaternion (x, y, z, w), ROS's order."""

    position: np.ndarray
    quaternion: np.ndarray

    @property
    def yaw(self) -> float:
        """Heading about world z (rad)."""
        return yaw_from_quat(self.quaternion)


class Simulation:
    """One robot in one world, stepped in MuJoCo.

    ``robot_pose`` = (x, y, yaw) of the robot's root link in the world (m, rad); the robot is placed
    with its lowest collision point on the floor. ``seed`` (int or ``numpy.random.Generator``) drives
    sensor noise when no generator is passed to a sensor call. ``timestep`` (s) defaults to 2 ms (see
    ``builder.DEFAULT_STEP``). ``visuals=False`` builds no render-only geoms (faster).
    ``lidar_backend``: "numba" (fast planar caster for primitives) or "mujoco" (``mj_multiRay``).
    """

    def __init__(
        self,
        robot: RobotModel | None,
        world: WorldModel,
        *,
        seed: int | np.random.Generator = 0,
        timestep: float | None = None,
        robot_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        visuals: bool = True,
        lidar_backend: str = "numba",
    ) -> None:
        if lidar_backend not in ("numba", "mujoco"):
            raise SimError(f"lidar_backend must be 'numba' or 'mujoco', got {lidar_backend!r}")
        self.robot = robot
        self.world = world
        self.lidar_backend = lidar_backend
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        x, y, yaw = robot_pose
        self.spec, self.info = build_spec(robot, world, timestep=timestep, robot_pose=(x, y, 0.0, yaw), visuals=visuals)
        self.model = compile_spec(self.spec, f"world {world.name!r}")
        self.data = mujoco.MjData(self.model)
        self.dt_ns = round(self.model.opt.timestep * 1e9)
        self.time_ns = 0
        self._synced = True
        # per lidar: (2, n) cos, sin of its beam angles in its frame
        self._lidar_dirs = [beam_dirs(cfg) for cfg in robot.lidars] if robot is not None else []
        self._no_noise = np.zeros(0)
        self._normals: dict[int, NormalDraws] = {}  # lidar -> its noise draws (see scan)
        self._vel6 = np.zeros(6)  # mj_objectVelocity's output, reused
        self._sensors_off = False  # see compute_sensors
        self._refresh_ids()
        if robot is not None:
            self._place_on_floor()

    # --- bookkeeping ------------------------------------------------------------------------------

    def _refresh_ids(self) -> None:
        m = self.model
        name2id = mujoco.mj_name2id
        self._act = [name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in (self.info.wheel_actuators or ())]
        self._act_sides: tuple[list[int], list[int]] | None = None  # (left, right) actuator ids
        self._wheel_qpos: tuple[list[int], list[int]] | None = None  # (left, right) wheel joints' qpos addresses
        self._lidar_site = [name2id(m, mujoco.mjtObj.mjOBJ_SITE, n) for n in self.info.lidar_sites]
        self._imu_site = [name2id(m, mujoco.mjtObj.mjOBJ_SITE, n) for n in self.info.imu_sites]
        self._ray_fast, self._ray_slow_groups = ray_geom_sets(m)
        self._scan_args: dict[int, tuple] = {}  # lidar -> lidar_rays.scan_args (views of this data)
        self._body = self._link_frames()
        # links whose frame is their MuJoCo body's own frame (no offset): poses and twists read directly
        self._body_frame = {k: not xyz.any() and quat[0] == 1.0 for k, (_, xyz, quat) in self._body.items()}
        self._geom_robot: list[bool] = (m.geom_group == GROUP_ROBOT).tolist()
        self._geom_ground: list[bool] = ((m.geom_contype.astype(np.int64) & GROUND_CONTACT_BIT) != 0).tolist()
        # clearance(): the robot's collision geoms against the world's (the floor is not an obstacle)
        collides = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        ground = (m.geom_contype.astype(np.int64) & GROUND_CONTACT_BIT) != 0
        self._clear_world = np.flatnonzero(
            collides & (m.geom_group != GROUP_ROBOT) & ~ground & (m.geom_type != mujoco.mjtGeom.mjGEOM_PLANE)
        )
        wtype = np.bitwise_or.reduce(m.geom_contype[self._clear_world], initial=0)
        waff = np.bitwise_or.reduce(m.geom_conaffinity[self._clear_world], initial=0)
        meets = ((m.geom_contype & waff) | (m.geom_conaffinity & wtype)) != 0  # not the wheels' floor spheres
        self._clear_robot = np.flatnonzero(meets & (m.geom_group == GROUP_ROBOT))
        self._joints: dict[str, tuple[int, int]] = {}
        self._joint_arrays: dict[tuple[str, ...], tuple[np.ndarray, np.ndarray]] = {}  # see joint_addresses
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
            mujoco.mj_step(self.model, self.data, nstep=int(n))
            self.time_ns += int(n) * self.dt_ns
            self._synced = False

    def compute_sensors(self, on: bool) -> None:
        """Whether physics steps compute MuJoCo's sensors (the IMUs'): they feed nothing else, so turning them off
        while no IMU is read changes no motion, bit for bit (:meth:`imu` computes them when it reads)."""
        self._sensors_off = not on
        flags, bit = int(self.model.opt.disableflags), int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
        self.model.opt.disableflags = flags & ~bit if on else flags | bit

    def _sync(self) -> None:
        """mj_step leaves poses and velocities of the state before its last integration: refresh them
        (lazily, once per advance, when something asks)."""
        if not self._synced:
            m, d = self.model, self.data
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            mujoco.mj_comVel(m, d)
            self._synced = True

    def step(self, n: int = 1) -> None:
        """Integrate ``n`` physics steps."""
        self.advance_to(self.time_ns + n * self.dt_ns)

    def set_wheel_velocity_targets(self, left: float, right: float) -> None:
        """Target angular velocities (rad/s) of the diff-drive wheel joints; torque capped by the motors."""
        if not self._act:
            raise SimError("this robot has no diff_drive wheels to command")
        if self._act_sides is None:
            n = self.info.left_wheel_count
            self._act_sides = (list(self._act[:n]), list(self._act[n:]))
        ctrl = self.data.ctrl
        for i in self._act_sides[0]:  # one or two wheels a side: cheaper than an index array
            ctrl[i] = left
        for i in self._act_sides[1]:
            ctrl[i] = right

    # --- state ------------------------------------------------------------------------------------

    def _link_frames(self) -> dict[str, tuple[int, np.ndarray, np.ndarray]]:
        """link -> (MuJoCo body id, offset xyz, offset quat) of the link frame in that body (fixed links
        are fused into their nearest moving ancestor)."""
        if self.robot is None:
            return {}
        parent_joint = {j.child: j for j in self.robot.joints}
        out: dict[str, tuple[int, np.ndarray, np.ndarray]] = {}

        def frame(link: str) -> tuple[int, np.ndarray, np.ndarray]:
            if link not in out:
                b = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, self.info.link_bodies[link])
                joint = parent_joint.get(link)
                if b >= 0 or joint is None:
                    out[link] = (b, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
                else:
                    pb, pxyz, pquat = frame(joint.parent)
                    rot = np.zeros(9)
                    mujoco.mju_quat2Mat(rot, pquat)
                    quat = np.zeros(4)
                    mujoco.mju_mulQuat(quat, pquat, mj_quat_from_rpy(joint.origin.rpy))
                    out[link] = (pb, pxyz + rot.reshape(3, 3) @ np.asarray(joint.origin.xyz), quat)
            return out[link]

        for link in self.info.link_bodies:
            frame(link)
        return out

    def link_pose(self, link: str | None = None) -> Pose3D:
        """True world pose of a robot link's frame (default: the root link)."""
        b, xyz, quat, own = self._link_frame(link)
        self._sync()
        if own:  # the link is the body's own frame
            return Pose3D(self.data.xpos[b].copy(), np.array(xyzw_from_wxyz(self.data.xquat[b])))
        rot = self.data.xmat[b].reshape(3, 3)
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, self.data.xquat[b], quat)
        return Pose3D(self.data.xpos[b] + rot @ xyz, np.array(xyzw_from_wxyz(q)))

    def robot_collisions(self) -> list[str]:
        """Names of the world models the robot touches now (contacts of the last physics step; the floor
        does not count): what Gazebo's bumper plugin would report."""
        m, d = self.model, self.data
        n = int(d.ncon)
        if n == 0:
            return []
        robot, ground = self._geom_robot, self._geom_ground
        out: set[str] = set()
        for g1, g2 in d.contact.geom[:n].tolist():
            if robot[g1] != robot[g2]:  # the robot against something else ...
                other = g2 if robot[g1] else g1
                if not ground[other]:  # ... that is not the floor
                    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, other) or ""
                    out.add(name.split("::")[0] or "world")
        return sorted(out)

    def clearance(self, max_distance: float = 2.0) -> float:
        """Distance (m) between the robot's collision geometry and the nearest collision geom of the world (the
        floor excluded), from MuJoCo's ``mj_geomDistance``: negative when they interpenetrate, ``max_distance``
        when nothing is closer. Cheap: only the pairs that can still be the nearest are asked (``sim.clearance``)."""
        return clearance(self.model, self.data, self._clear_robot, self._clear_world, max_distance)

    def teleport(self, x: float, y: float, yaw: float) -> None:
        """Move the robot's root to (x, y, yaw) in the world (m, rad), at rest: Gazebo's set_model_state
        (the 'kidnapped robot')."""
        if self.robot is None:
            raise SimError("there is no robot in this simulation to teleport")
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise SimError(f"teleport pose ({x}, {y}, {yaw}) is not finite")
        q, v = self._root_qpos, self._root_dof
        self.data.qpos[q : q + 2] = (x, y)
        self.data.qpos[q + 3 : q + 7] = wxyz_from_xyzw(quat_from_yaw(yaw))
        self.data.qvel[v : v + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self._synced = True

    def base_pose2d(self, link: str | None = None) -> tuple[float, float, float]:
        """True (x, y, yaw) of a robot link in the world (m, rad)."""
        b, _, _, own = self._link_frame(link)
        if own:  # the body's own frame: link_pose's values, read as floats (the monitors ask at 10 Hz)
            self._sync()
            x, y = self.data.xpos[b, :2].tolist()
            w, qx, qy, qz = self.data.xquat[b].tolist()
            return x, y, yaw_from_quat((qx, qy, qz, w))
        pose = self.link_pose(link)
        return float(pose.position[0]), float(pose.position[1]), pose.yaw

    def link_velocity(self, link: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(linear m/s, angular rad/s) of a robot link's frame, both expressed in that link's frame."""
        b, xyz, quat, own = self._link_frame(link)
        self._sync()
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_XBODY, b, vel, 1)
        if own:  # the link is the body's own frame
            return vel[3:], vel[:3]
        wx, wy, wz = vel[:3]
        rx, ry, rz = xyz
        lin = vel[3:] + np.array([wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx])  # v + w x r
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, quat)
        rot_t = rot.reshape(3, 3).T
        return rot_t @ lin, rot_t @ vel[:3]

    def link_state(
        self, link: str | None = None
    ) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        """(position xyz, quaternion xyzw, linear velocity, angular velocity) of a robot link as floats: the
        values of :meth:`link_pose` and :meth:`link_velocity`, read at once (ground truth at 50 Hz)."""
        b, _, _, own = self._link_frame(link)
        if not own:
            pose = self.link_pose(link)
            lin, ang = self.link_velocity(link)
            return (
                tuple(pose.position.tolist()),
                tuple(float(v) for v in pose.quaternion),
                tuple(lin.tolist()),
                tuple(ang.tolist()),
            )
        self._sync()
        d = self.data
        vel = self._vel6
        mujoco.mj_objectVelocity(self.model, d, mujoco.mjtObj.mjOBJ_XBODY, b, vel, 1)
        v = vel.tolist()
        return tuple(d.xpos[b].tolist()), xyzw_from_wxyz(d.xquat[b]), (v[3], v[4], v[5]), (v[0], v[1], v[2])

    def _link_frame(self, link: str | None) -> tuple[int, np.ndarray, np.ndarray, bool]:
        """(body id, offset xyz, offset quat, whether the link is the body's own frame) of a robot link."""
        if self.robot is None:
            raise SimError("there is no robot in this simulation")
        name = self.robot.root_link if link is None else link
        if name not in self._body:
            raise SimError(f"robot {self.robot.name!r} has no link {name!r}")
        return (*self._body[name], self._body_frame[name])

    def joint_names(self) -> list[str]:
        """The robot's moving single-DOF joints (URDF order)."""
        return list(self._joints)

    def joint_position(self, name: str) -> float:
        """Joint angle (rad) or position (m)."""
        return float(self.data.qpos[self._joint(name)[0]])

    def joint_velocity(self, name: str) -> float:
        """Joint rate (rad/s or m/s)."""
        return float(self.data.qvel[self._joint(name)[1]])

    def joint_addresses(self, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """(qpos addresses, qvel addresses) of the named joints, as index arrays: ``data.qpos[qpos]`` are their
        positions, as :meth:`joint_position` reads them one by one (kept until the model is recompiled)."""
        key = tuple(names)
        hit = self._joint_arrays.get(key)
        if hit is None:
            adr = [self._joint(n) for n in names]
            hit = self._joint_arrays[key] = (
                np.array([a[0] for a in adr], dtype=np.intp),
                np.array([a[1] for a in adr], dtype=np.intp),
            )
        return hit

    def _joint(self, name: str) -> tuple[int, int]:
        if name not in self._joints:
            raise SimError(f"unknown joint {name!r}; moving joints are {list(self._joints)}")
        return self._joints[name]

    def wheel_angles(self) -> tuple[float, float]:
        """(left, right) diff-drive wheel angles (rad), unwrapped: each side's mean over its wheels (a skid-steer
        robot's front and rear wheels), as diff_drive_controller averages them."""
        if self._wheel_qpos is None:
            sides = self._diff_drive().wheel_joints()
            self._wheel_qpos = ([self._joint(j)[0] for j in sides[0]], [self._joint(j)[0] for j in sides[1]])
        lefts, rights = self._wheel_qpos
        q = self.data.qpos
        return (sum([float(q[a]) for a in lefts]) / len(lefts), sum([float(q[a]) for a in rights]) / len(rights))

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
        if self.lidar_backend == "mujoco" or self._ray_slow_groups is not None:
            dist = self.true_ranges(index)
            normals = self._draw_normals(index, cfg, len(dist), rng)
            out = np.empty(len(dist), dtype=np.float32)
            finish_ranges(dist, normals, cfg.noise_mean, cfg.noise_stddev, cfg.range_min, cfg.range_max, out)
            return out
        # primitives only: the cast and the noise in one compiled call (the same values as the path above)
        self._sync()
        args = self._scan_args.get(index)
        if args is None:
            site, dirs = self._lidar_site[index], self._lidar_dirs[index]
            args = self._scan_args[index] = scan_args(self.model, self.data, site, dirs, cfg, self._ray_fast)
        normals = self._draw_normals(index, cfg, args[2].shape[0], rng)  # the cast draws nothing: the same draws
        return scan_with(args, cfg, normals)

    def _draw_normals(self, index: int, cfg: LidarConfig, n: int, rng: np.random.Generator | None) -> np.ndarray:
        """Lidar ``index``'s noise draws for one scan of ``n`` beams: standard_normal(n) from ``rng`` (or the
        simulation's generator) into a buffer kept per lidar; none without noise."""
        if cfg.noise_stddev <= 0:
            return self._no_noise
        gen = self.rng if rng is None else rng
        kept = self._normals.get(index)
        if kept is None or kept.buf.shape[0] != n or kept.gen is not gen:
            kept = self._normals[index] = NormalDraws(gen, n)
        return kept.draw()

    def true_ranges(self, index: int = 0, *, backend: str | None = None) -> np.ndarray:
        """Noise-free ranges (m, float64) of lidar ``index``; ``backend`` "numba" (primitives by
        :mod:`navlab.sim.raycast`, meshes by ``mj_multiRay``) or "mujoco" (all by ``mj_multiRay``)."""
        assert self.robot is not None
        cfg = self.robot.lidars[index]
        self._sync()
        m, d = self.model, self.data
        site = self._lidar_site[index]
        angles = self._lidar_dirs[index]
        rot = d.site_xmat[site].reshape(3, 3)
        pnt = d.site_xpos[site].copy()
        if (backend or self.lidar_backend) == "mujoco":
            return multiray(m, d, cfg.range_min, cfg.range_max, rot, pnt, angles, RAY_GEOMGROUP)
        dist = cast_primitives(m, d, pnt, rot, angles, cfg, self._ray_fast)
        if self._ray_slow_groups is not None:
            slow = multiray(m, d, cfg.range_min, cfg.range_max, rot, pnt, angles, self._ray_slow_groups)
            np.minimum(dist, slow, out=dist)
        return dist

    def link_body(self, link: str) -> int:
        """The MuJoCo body id that carries a robot link (fixed links are fused into a moving ancestor)."""
        if link not in self._body:
            raise SimError(f"no link named {link!r} on the robot")
        return int(self._body[link][0])

    def ray_geoms(self) -> tuple[np.ndarray, np.ndarray | None]:
        """(ids of the world's primitive geoms the fast casters test, geom groups of the rest for
        ``mj_multiRay`` or None): what every ray sensor sees (the robot's own geoms are not seen)."""
        self._sync()
        return self._ray_fast, self._ray_slow_groups

    def imu(self, index: int = 0, rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(orientation quaternion x,y,z,w in world, angular velocity rad/s, linear acceleration m/s²) of IMU
        ``index``; rates and accelerations in the IMU frame, with the configured gaussian noise."""
        if self.robot is None or not 0 <= index < len(self.robot.imus):
            raise SimError(f"no imu number {index} on this robot")
        cfg = self.robot.imus[index]
        site = self.info.imu_sites[index]
        off = self._sensors_off
        self.compute_sensors(True)
        mujoco.mj_forward(self.model, self.data)
        self.compute_sensors(not off)
        quat, gyro, accel = (self.data.sensor(f"{site}_{k}").data.copy() for k in ("quat", "gyro", "accel"))
        gen = self.rng if rng is None else rng
        if cfg.gyro_noise_stddev > 0:
            gyro = gyro + gen.normal(0.0, cfg.gyro_noise_stddev, 3)
        if cfg.accel_noise_stddev > 0:
            accel = accel + gen.normal(0.0, cfg.accel_noise_stddev, 3)
        return np.array(xyzw_from_wxyz(quat)), gyro, accel

    # --- spawning ---------------------------------------------------------------------------------

    def spawn(self, model: ModelSpec) -> list[str]:
        """Add an SDF model to the running world (state of everything else kept); returns its parts' names."""
        parts = add_world_model(self.spec, model, self.info)
        self._recompile(f"model {model.name!r}")
        return parts

    def remove(self, name: str) -> None:
        """Delete a model (by its SDF name) from the running world."""
        remove_world_model(self.spec, name, self.info)
        self._recompile(f"world after removing {name!r}")

    def model_names(self) -> list[str]:
        """Names of the world's models (not the robot)."""
        return list(self.info.world_parts)

    def model_pose(self, name: str) -> Pose3D:
        """World pose of a model (its first link's body for dynamic models, its SDF pose if static)."""
        if name not in self.info.world_parts:
            raise SimError(f"no model named {name!r}; models: {sorted(self.info.world_parts)}")
        bodies, _ = self.info.world_parts[name]
        self._sync()
        if bodies:
            b = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, bodies[0])
            return Pose3D(self.data.xpos[b].copy(), np.array(xyzw_from_wxyz(self.data.xquat[b])))
        x, y, z, roll, pitch, yaw = self.info.model_poses[name]
        return Pose3D(np.array([x, y, z]), np.array(quat_from_rpy(roll, pitch, yaw)))

    def _recompile(self, what: str) -> None:
        ctrl = {n: self.data.ctrl[i] for n, i in zip(self.info.wheel_actuators or (), self._act, strict=False)}
        try:
            self.model, self.data = self.spec.recompile(self.model, self.data)
        except ValueError as exc:
            raise SimError(f"MuJoCo could not compile the {what}: {exc}") from None
        self._refresh_ids()
        self.compute_sensors(not self._sensors_off)
        for i, name in zip(self._act, ctrl, strict=False):
            self.data.ctrl[i] = ctrl[name]
        mujoco.mj_forward(self.model, self.data)
