"""RobotModel → MuJoCo bodies, built directly with ``mujoco.MjSpec``, and the conventions shared with
:mod:`navlab.sim.scene` (which adds the world and builds the whole spec).

Conventions of the built model (what the simulator and the lidar rely on):

- The robot's links become bodies nested along the joint tree, named as in the URDF, and the root gets
  a free joint at the spawn pose. Fixed links are fused into their parent body when compiling
  (MuJoCo's ``fusestatic``); sensor frames survive as sites and link frames as fixed offsets.
- World models keep Gazebo's scoped names (``model::link``): a static model's geoms are welded onto
  the world body (``model::link::collisionN``), each dynamic link is a free body ``model::link``.
- Geom groups: 0 world collision (rays hit), 1 robot collision (rays ignore), 2 visuals (render only,
  no contacts), 3 ray-only true surfaces of world meshes, 4 collision hulls of world meshes.
- Contact bits: the world's static geoms only touch the robot and dynamic models; robot parts never
  touch each other (Gazebo's ``self_collide`` off); wheels touch the floor through a sphere
  (WHEEL_FLOOR_SPHERES below) and everything else through their cylinder.
- Friction follows Gazebo (combined by min, not MuJoCo's max): robot geoms get contact priority so
  their own friction decides; passive casters (links rigidly fixed to the chassis without an explicit
  ``mu1``, or with ``mu1 == 0``) are frictionless (``condim`` 1) so they do not drag.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from navlab.description import Geometry, Joint, Link, Origin, RobotModel, Shape
from navlab.geometry import matrix_from_rpy, quat_from_rpy, wxyz_from_xyzw
from navlab.sim.errors import SimError
from navlab.sim.ode_contact import combined_mu, contact_solimp, contact_solref

GROUP_WORLD = 0
GROUP_ROBOT = 1
GROUP_VISUAL = 2
GROUP_RAY_MESH = 3
GROUP_WORLD_HULL = 4
#: geom groups a lidar ray can hit (mj_multiRay's geomgroup filter)
RAY_GEOMGROUP = np.array([1, 0, 0, 1, 0, 0], dtype=np.uint8)

# contact bits: a pair touches when (contype1 & conaffinity2) or (contype2 & conaffinity1)
_STATIC, _ROBOT, _DYNAMIC, _GROUND, _WHEEL_FLOOR, _WHEEL = 1, 2, 4, 8, 16, 32
GROUND_CONTACT_BIT = _GROUND  # the floor's contype (contacts with it are not collisions)
_CONTACT_BITS = {
    "static": (_STATIC, _ROBOT | _DYNAMIC | _WHEEL),
    "ground": (_GROUND, _ROBOT | _DYNAMIC | _WHEEL_FLOOR),
    "robot": (_ROBOT, _STATIC | _DYNAMIC | _GROUND),
    "wheel": (_WHEEL, _STATIC | _DYNAMIC),  # a wheel's true cylinder: obstacles, not the floor
    "wheel_floor": (_WHEEL_FLOOR, _GROUND),  # its floor contact (see WHEEL_FLOOR_SPHERES)
    "dynamic": (_DYNAMIC, _STATIC | _ROBOT | _DYNAMIC | _GROUND | _WHEEL),
}
#: WHEEL_TAU: ODE's joint motor (Gazebo's diff drive) is a hard velocity constraint capped by the
#: torque; here each wheel is a velocity actuator (an implicit damper capped by forcerange) whose gain
#: kv = I_eff / WHEEL_TAU makes the wheel reach its target speed with this time constant (s), where
#: I_eff is the wheel's own inertia about its axis plus its share of the robot's mass at the wheel
#: radius. A fixed large gain is not stable: with TurtleBot3's 28 g wheels a kv of 50 diverges.
WHEEL_TAU = 0.005
#: WHEEL_FLOOR_SPHERES: a robot cylinder spinning about its own axis (a wheel) touches the floor through
#: a sphere of its radius at its centre, and everything else through its true cylinder. MuJoCo's
#: cylinder-plane contact puts points on both rim edges; the outer edge then sets the turning rate
#: (7 % slow on mybot) and the flat rim bounces. The sphere touches the floor in one point at
#: mid-tread, like a wheel's contact patch, and sphere-plane is MuJoCo's cheapest collision (an
#: inscribed ellipsoid does the same through the general convex collider at ~4x the step cost).
#: contact softness for the robot (time constant s, damping ratio): critically damped, no bounce
ROBOT_SOLREF = (0.005, 1.0)
ROBOT_SOLIMP = (0.95, 0.99, 0.001, 0.5, 2.0)
DEFAULT_MU = 1.0  # Gazebo/ODE's friction when a link names none
#: SKID_ARMATURE: a skid-steer wheel joint gets rotor inertia (MuJoCo ``armature``, kg m²) of this fraction of its
#: share of the robot's mass at the wheel radius — a geared motor's reflected inertia, which URDF cannot state.
#: Without it a wheel (0.5 kg) rocks the robot on every speed change (measured, jackal_skid from rest to 0.5 m/s:
#: its wheels ran 0.08 m ahead of it; with it 0.01 m, the Coulomb figure v^2/2 (1/(mu g) - 1/a) for mu 0.8).
SKID_ARMATURE = 0.5
MIN_MASS = 1e-3  # kg given to a moving link that has no <inertial>
MIN_STEP, MAX_STEP = 0.0005, 0.002  # s; 5 ms tips robots over
#: DEFAULT_STEP: MuJoCo's implicit integrator is as accurate at 2 ms as at Gazebo/ODE's usual 1 ms for
#: these robots (straight-line and turning tests agree within 0.3 %) at half the cost, so a world's
#: ``max_step_size`` below 2 ms is raised to it unless a timestep is asked for explicitly.
DEFAULT_STEP = 0.002


@dataclass
class BuildInfo:
    """Names in the built model that the simulator needs, plus warnings raised while building."""

    robot_name: str = ""
    root_body: str = ""
    link_bodies: dict[str, str] = field(default_factory=dict)  # URDF link -> MuJoCo body name
    lidar_sites: list[str] = field(default_factory=list)  # one per RobotModel.lidars entry
    imu_sites: list[str] = field(default_factory=list)  # one per RobotModel.imus entry
    wheel_actuators: tuple[str, ...] | None = None  # velocity actuators: the left side's wheels, then the right's
    left_wheel_count: int = 1  # how many of wheel_actuators drive the left side
    #: model name -> (free body names, geom names welded to the world)
    world_parts: dict[str, tuple[list[str], list[str]]] = field(default_factory=dict)
    model_poses: dict[str, tuple[float, ...]] = field(default_factory=dict)  # model name -> SDF pose
    visuals: bool = True  # build visual geoms (rendering only)
    decompose_reach: float | None = None  # m above the floor up to which concave meshes get convex parts
    warnings: list[str] = field(default_factory=list)


# --- rotations ------------------------------------------------------------------------------------


def mj_quat_from_rpy(rpy: tuple[float, float, float]) -> np.ndarray:
    """MuJoCo's quaternion (w, x, y, z) of URDF roll-pitch-yaw: the MuJoCo boundary of ``geometry``."""
    return wxyz_from_xyzw(quat_from_rpy(*(float(a) for a in rpy)))


def set_pose(element: Any, origin: Origin) -> None:
    """Set ``pos``/``quat`` of a MuJoCo spec element (``MjsBody``, ``MjsGeom``, ``MjsSite``...; untyped)."""
    element.pos = np.asarray(origin.xyz, dtype=float)
    element.quat = mj_quat_from_rpy(origin.rpy)


# --- geometry -------------------------------------------------------------------------------------


class Geoms:
    """Adds shapes to bodies, registering mesh assets once per (file, scale)."""

    def __init__(self, spec: mujoco.MjSpec, info: BuildInfo) -> None:
        self.spec = spec
        self.info = info

    def mesh_asset(self, geometry: Geometry, where: str) -> str:
        path = geometry.mesh_path
        if path is None or not path.is_file():
            raise SimError(f"{where}: mesh file {path} not found (expected a resolved STL/OBJ path)")
        if path.suffix.lower() not in (".stl", ".obj"):
            raise SimError(
                f"{where}: mesh {path} is {path.suffix or 'of unknown type'}; MuJoCo reads STL and OBJ "
                "(convert COLLADA .dae meshes to .stl/.obj)"
            )
        scale = tuple(float(s) for s in geometry.mesh_scale)
        name = f"mesh_{hashlib.sha1(repr((str(path), scale)).encode()).hexdigest()[:12]}_{path.stem}"
        if self.spec.mesh(name) is None:  # one asset per (file, scale), shared by every geom using it
            mesh = self.spec.add_mesh(name=name, file=str(path))
            mesh.scale = np.asarray(scale)
        return name

    def add(self, body: mujoco.MjsBody, shape: Shape, where: str, **props: object) -> mujoco.MjsGeom:
        g = shape.geometry
        geom = body.add_geom()
        size = tuple(float(s) for s in g.size)
        try:
            if g.kind == "box":
                geom.type = mujoco.mjtGeom.mjGEOM_BOX
                geom.size = np.array([size[0] / 2, size[1] / 2, size[2] / 2])
            elif g.kind == "cylinder":
                geom.type = mujoco.mjtGeom.mjGEOM_CYLINDER
                geom.size = np.array([size[0], size[1] / 2, 0.0])
            elif g.kind == "sphere":
                geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
                geom.size = np.array([size[0], 0.0, 0.0])
            elif g.kind == "mesh":
                geom.type = mujoco.mjtGeom.mjGEOM_MESH
                geom.meshname = self.mesh_asset(g, where)
            else:
                raise SimError(f"{where}: unknown geometry kind {g.kind!r} (expected box/cylinder/sphere/mesh)")
        except IndexError:
            raise SimError(f"{where}: {g.kind} geometry needs more size values than {size}") from None
        if g.kind != "mesh" and min(s for s in size if s is not None) <= 0:
            raise SimError(f"{where}: {g.kind} size {size} must be positive")
        set_pose(geom, shape.origin)
        for key, value in props.items():
            setattr(geom, key, value)
        return geom


def contact_props(kind: str, group: int) -> dict[str, object]:
    contype, conaffinity = _CONTACT_BITS[kind]
    return {"contype": contype, "conaffinity": conaffinity, "group": group}


VISUAL_PROPS: dict[str, object] = {"contype": 0, "conaffinity": 0, "group": GROUP_VISUAL, "mass": 0.0}


def set_inertial(body: mujoco.MjsBody, link: Link, moving: bool, info: BuildInfo, where: str) -> None:
    inertial = link.inertial
    if inertial is None:
        if moving:
            info.warnings.append(f"{where}: moving link has no <inertial>; given {MIN_MASS} kg")
        body.mass = MIN_MASS if moving else 0.0  # URDF: a link without <inertial> is massless
        body.inertia = np.full(3, 1e-6 if moving else 0.0)
        body.explicitinertial = True
        return
    if inertial.mass <= 0:
        raise SimError(f"{where}: <inertial> mass must be positive, got {inertial.mass}")
    tensor = np.array(
        [
            [inertial.ixx, inertial.ixy, inertial.ixz],
            [inertial.ixy, inertial.iyy, inertial.iyz],
            [inertial.ixz, inertial.iyz, inertial.izz],
        ]
    )
    rot = matrix_from_rpy(*inertial.origin.rpy)
    tensor = rot @ tensor @ rot.T
    if np.all(np.abs(tensor) < 1e-12):
        tensor = np.eye(3) * 1e-6
    body.mass = float(inertial.mass)
    body.ipos = np.asarray(inertial.origin.xyz, dtype=float)
    body.iquat = np.array([1.0, 0.0, 0.0, 0.0])
    body.fullinertia = np.array([tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]])
    body.explicitinertial = True


# --- robot ----------------------------------------------------------------------------------------


def _link_friction(link: Link, rigid_to_root: bool) -> tuple[float, int]:
    """(mu, condim) of a robot link's contacts under Gazebo semantics (see module docstring)."""
    mu = combined_mu(link.mu1, link.mu2)
    if mu is None:
        return (0.0, 1) if rigid_to_root else (DEFAULT_MU, 3)
    if mu < 0:
        raise SimError(f"link {link.name!r}: friction mu1/mu2 must be >= 0, got {(link.mu1, link.mu2)}")
    return (0.0, 1) if mu <= 1e-6 else (mu, 3)


def _check_tree(robot: RobotModel) -> dict[str, list]:
    """Validate links/joints form a tree under ``root_link``; return parent link -> child joints."""
    where = f"robot {robot.name!r}" + (f" ({robot.source})" if robot.source else "")
    if robot.root_link not in robot.links:
        raise SimError(f"{where}: root link {robot.root_link!r} is not among its links")
    children: dict[str, list] = {}
    parents: dict[str, str] = {}
    for joint in robot.joints:
        for end in (joint.parent, joint.child):
            if end not in robot.links:
                raise SimError(f"{where}: joint {joint.name!r} names unknown link {end!r}")
        if joint.child in parents:
            raise SimError(f"{where}: link {joint.child!r} has two parent joints")
        parents[joint.child] = joint.name
        children.setdefault(joint.parent, []).append(joint)
    if robot.root_link in parents:
        raise SimError(f"{where}: root link {robot.root_link!r} has a parent joint {parents[robot.root_link]!r}")
    return children


def add_robot(
    spec: mujoco.MjSpec,
    robot: RobotModel,
    info: BuildInfo,
    pose: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0),
) -> None:
    """Add ``robot`` with its root at ``pose`` = (x, y, z, yaw) in the world frame (m, rad)."""
    children = _check_tree(robot)
    geoms = Geoms(spec, info)
    info.robot_name = robot.name
    info.root_body = robot.root_link
    contact = {**contact_props("robot", GROUP_ROBOT), "priority": 1}
    total_mass = sum(lk.inertial.mass for lk in robot.links.values() if lk.inertial is not None)
    wheels = sum(map(len, robot.diff_drive.wheel_joints())) if robot.diff_drive is not None else 1
    if wheels > 2:  # skid steer: wheels slide sideways; isotropic Coulomb friction (see navlab.sim.ode_contact)
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC

    def fill(body: mujoco.MjsBody, link: Link, axis: np.ndarray | None, rigid_to_root: bool) -> None:
        where = f"robot {robot.name!r} link {link.name!r}"
        info.link_bodies[link.name] = body.name
        set_inertial(body, link, axis is not None, info, where)
        mu, condim = _link_friction(link, rigid_to_root)
        # ODE contact tags map onto a skid-steer robot's wheels; two-wheel robots keep the contact their
        # straight-line and turning tests were measured with (TurtleBot3's kp/kd would slow it by 10 %)
        skid = wheels > 2 and axis is not None and not rigid_to_root
        tags = link.contact if skid else None
        contact["solref"] = np.array(
            contact_solref(tags, total_mass / wheels, timestep=MAX_STEP, default=ROBOT_SOLREF, skid=skid)
        )
        contact["solimp"] = np.array(contact_solimp(tags, default=ROBOT_SOLIMP, skid=skid))
        for i, shape in enumerate(link.collisions):
            g = geoms.add(
                body, shape, f"{where} collision {i}", friction=np.array([mu, 0.005, 0.0001]), condim=condim, **contact
            )
            if shape.geometry.kind == "cylinder" and axis is not None:
                cyl_axis = matrix_from_rpy(*shape.origin.rpy)[:, 2]
                if abs(float(cyl_axis @ axis)) > 0.99:  # a wheel: see WHEEL_FLOOR_SPHERES
                    g.contype, g.conaffinity = _CONTACT_BITS["wheel"]
                    floor = Shape(Geometry("sphere", (float(shape.geometry.size[0]),)), origin=shape.origin)
                    f = geoms.add(
                        body,
                        floor,
                        f"{where} collision {i}",
                        friction=np.array([mu, 0.005, 0.0001]),
                        condim=condim,
                        **contact,
                    )
                    f.contype, f.conaffinity = _CONTACT_BITS["wheel_floor"]
        shown = (link.visuals or link.collisions) if info.visuals else []
        for i, shape in enumerate(shown):
            try:
                g = geoms.add(body, shape, f"{where} visual {i}", **VISUAL_PROPS)
            except SimError as exc:
                info.warnings.append(f"{exc}; visual skipped")
                continue
            g.rgba = np.array(shape.rgba if shape.rgba is not None else (0.6, 0.6, 0.65, 1.0))
        for joint in children.get(link.name, []):
            child = robot.links[joint.child]
            cbody = body.add_body(name=child.name)
            set_pose(cbody, joint.origin)
            _add_joint(cbody, joint, f"robot {robot.name!r} joint {joint.name!r}", info)
            fixed = joint.type == "fixed"
            jaxis = None if fixed else np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
            fill(cbody, child, jaxis, rigid_to_root=rigid_to_root and fixed)

    x, y, z, yaw = pose
    root = spec.worldbody.add_body(name=robot.root_link)
    set_pose(root, Origin(xyz=(x, y, z), rpy=(0.0, 0.0, yaw)))
    root.add_freejoint(name=f"{robot.name}::root")
    fill(root, robot.links[robot.root_link], None, rigid_to_root=True)

    for i, lidar in enumerate(robot.lidars):
        info.lidar_sites.append(_add_site(spec, info, lidar.link, lidar.origin, f"{lidar.name}_{i}", robot))
    for i, imu in enumerate(robot.imus):
        site = _add_site(spec, info, imu.link, imu.origin, f"{imu.name}_{i}", robot)
        info.imu_sites.append(site)
        for kind, suffix in (
            (mujoco.mjtSensor.mjSENS_GYRO, "gyro"),
            (mujoco.mjtSensor.mjSENS_ACCELEROMETER, "accel"),
            (mujoco.mjtSensor.mjSENS_FRAMEQUAT, "quat"),
        ):
            spec.add_sensor(name=f"{site}_{suffix}", type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site)
    if robot.diff_drive is not None:
        info.wheel_actuators = _add_wheel_motors(spec, robot, info)


def _add_joint(body: mujoco.MjsBody, joint: Joint, where: str, info: BuildInfo) -> None:
    kind = joint.type
    if kind == "fixed":
        return
    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm < 1e-9:
        raise SimError(f"{where}: <axis> must be non-zero, got {tuple(axis)}")
    axis /= norm
    common = {"damping": float(joint.damping), "frictionloss": float(joint.friction)}
    if kind in ("continuous", "revolute", "prismatic"):
        jtype = mujoco.mjtJoint.mjJNT_SLIDE if kind == "prismatic" else mujoco.mjtJoint.mjJNT_HINGE
        j = body.add_joint(name=joint.name, type=jtype, axis=axis, **common)
        lower, upper = joint.lower, joint.upper
        if kind != "continuous" and lower is not None and upper is not None and upper > lower:
            j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            j.range = np.array([lower, upper])
        else:
            j.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    elif kind == "planar":
        a = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        u = np.cross(axis, a)
        u /= np.linalg.norm(u)
        v = np.cross(axis, u)
        for suffix, ax in (("x", u), ("y", v)):
            body.add_joint(name=f"{joint.name}_{suffix}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=ax, **common)
        body.add_joint(name=f"{joint.name}_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis, **common)
    elif kind == "floating":
        info.warnings.append(f"{where}: floating joint below the root is simulated as fixed")
    else:
        raise SimError(f"{where}: unknown joint type {kind!r}")


def _add_site(spec: mujoco.MjSpec, info: BuildInfo, link: str, origin: Origin, name: str, robot: RobotModel) -> str:
    if link not in info.link_bodies:
        raise SimError(f"robot {robot.name!r}: sensor {name!r} is attached to unknown link {link!r}")
    body = spec.body(info.link_bodies[link])
    site = body.add_site(name=name)
    set_pose(site, origin)
    return name


def _wheel_inertia(robot: RobotModel, joint: Joint) -> float:
    """Effective inertia (kg m²) a wheel motor drives: the wheel about its axis plus half the robot's
    mass at the wheel radius (what the wheel feels when it rolls without slipping)."""
    dd = robot.diff_drive
    assert dd is not None
    total = sum(link.inertial.mass for link in robot.links.values() if link.inertial is not None)
    own = 0.0
    inertial = robot.links[joint.child].inertial
    if inertial is not None:
        tensor = np.array(
            [
                [inertial.ixx, inertial.ixy, inertial.ixz],
                [inertial.ixy, inertial.iyy, inertial.iyz],
                [inertial.ixz, inertial.iyz, inertial.izz],
            ]
        )
        rot = matrix_from_rpy(*inertial.origin.rpy)
        axis = np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
        com = np.asarray(inertial.origin.xyz, dtype=float)
        own = float(axis @ rot @ tensor @ rot.T @ axis) + inertial.mass * float(com @ com - (com @ axis) ** 2)
    return max(own + 0.5 * total * (dd.wheel_diameter / 2) ** 2, 1e-6)


def _add_wheel_motors(spec: mujoco.MjSpec, robot: RobotModel, info: BuildInfo) -> tuple[str, ...]:
    dd = robot.diff_drive
    assert dd is not None
    names = []
    lefts, rights = dd.wheel_joints()
    info.left_wheel_count = len(lefts)
    for jname in (*lefts, *rights):
        joint = next((j for j in robot.joints if j.name == jname), None)
        if joint is None or joint.type not in ("continuous", "revolute"):
            found = "missing" if joint is None else f"a {joint.type} joint"
            raise SimError(
                f"robot {robot.name!r}: diff_drive wheel joint {jname!r} is {found}; expected a continuous joint"
            )
        act = spec.add_actuator(name=f"{jname}::motor", target=jname, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        if len(lefts) + len(rights) > 2:  # see SKID_ARMATURE
            total = sum(lk.inertial.mass for lk in robot.links.values() if lk.inertial is not None)
            share = total / (len(lefts) + len(rights)) * (dd.wheel_diameter / 2) ** 2
            spec.joint(jname).armature = SKID_ARMATURE * share
        act.set_to_velocity(kv=_wheel_inertia(robot, joint) / WHEEL_TAU)
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = np.array([-dd.max_torque, dd.max_torque])
        names.append(act.name)
    return tuple(names)
