"""The whole MuJoCo scene: world models (static welded to the world body, dynamic as free bodies,
concave meshes as convex parts), scenery (ground, light, floor texture) and :func:`build_spec`.

See :mod:`navlab.sim.builder` for the conventions (geom groups, contact bits, friction) and the robot.
"""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np

from navlab.description import Origin, RobotModel, Shape
from navlab.sim.builder import (
    DEFAULT_MU,
    DEFAULT_STEP,
    GROUP_RAY_MESH,
    GROUP_WORLD,
    GROUP_WORLD_HULL,
    MAX_STEP,
    MIN_STEP,
    VISUAL_PROPS,
    BuildInfo,
    Geoms,
    add_robot,
    contact_props,
    set_inertial,
    set_pose,
)
from navlab.sim.errors import SimError
from navlab.sim.mjtimers import profiling_timers_off
from navlab.world import ModelSpec, WorldModel


def add_world_model(spec: mujoco.MjSpec, model: ModelSpec, info: BuildInfo) -> list[str]:
    """Add one SDF model; returns the names of what was added (geoms for static models, bodies otherwise).

    Static models' geoms are welded straight onto the world body (few bodies keep MuJoCo's broad
    phase and kinematics cheap); each dynamic link becomes a free body.
    """
    if model.name in info.world_parts or model.name == info.robot_name:
        raise SimError(f"a model named {model.name!r} already exists in the world")
    geoms = Geoms(spec, info)
    x, y, z, roll, pitch, yaw = model.pose
    model_pose = Origin(xyz=(x, y, z), rpy=(roll, pitch, yaw))
    kind = "static" if model.static else "dynamic"
    props = contact_props(kind, GROUP_WORLD)
    bodies: list[str] = []
    geom_names: list[str] = []
    for link in model.links:
        where = f"model {model.name!r} link {link.name!r}"
        scoped = f"{model.name}::{link.name}"
        link_pose = model_pose.then(model.link_origins.get(link.name, Origin()))
        # static: geoms sit on the world body, so shapes move by the link pose; dynamic: the body carries it
        offset = link_pose if model.static else None
        if model.static:
            body = spec.worldbody
        else:
            body = spec.worldbody.add_body(name=scoped)
            set_pose(body, link_pose)
            body.add_freejoint(name=f"{scoped}::free")
            if link.inertial is not None:
                set_inertial(body, link, True, info, where)
            bodies.append(scoped)

        def place(shape: Shape, _offset: Origin | None = offset) -> Shape:
            return shape if _offset is None else replace(shape, origin=_offset.then(shape.origin))

        mu = DEFAULT_MU if link.mu1 is None else float(link.mu1)
        friction = np.array([mu, 0.005, 0.0001])
        for i, shape in enumerate(link.collisions):
            cwhere = f"{where} collision {i}"
            extra: dict[str, object] = {"friction": friction, "name": f"{scoped}::collision{i}"}
            if not model.static and link.inertial is None:
                extra["mass"] = 1.0 / len(link.collisions)  # Gazebo's default link mass: 1 kg
            if shape.geometry.kind == "mesh":
                # the true triangles for rays; the hull (or, if concave, convex parts) for contacts
                geoms.add(
                    body,
                    place(shape),
                    cwhere,
                    contype=0,
                    conaffinity=0,
                    group=GROUP_RAY_MESH,
                    mass=0.0,
                    name=f"{scoped}::ray{i}",
                )
                geom_names.append(f"{scoped}::ray{i}")
                hull_props = {**props, "group": GROUP_WORLD_HULL}
                if getattr(shape.geometry, "convex", None) is False:
                    from navlab.sim.decompose import local_cut

                    cut = local_cut(place(shape).origin if model.static else None, info.decompose_reach)
                    _add_convex_parts(
                        spec, body, place(shape), cwhere, f"{scoped}::collision{i}", hull_props, extra, geom_names, cut
                    )
                    continue
                geoms.add(body, place(shape), cwhere, **hull_props, **extra)
            else:
                geoms.add(body, place(shape), cwhere, **props, **extra)
            geom_names.append(f"{scoped}::collision{i}")
        if not info.visuals:
            continue
        for i, shape in enumerate(link.visuals or link.collisions):
            try:
                g = geoms.add(body, place(shape), f"{where} visual {i}", **VISUAL_PROPS, name=f"{scoped}::visual{i}")
            except SimError as exc:
                info.warnings.append(f"{exc}; visual skipped")
                continue
            g.rgba = np.array(shape.rgba if shape.rgba is not None else (0.75, 0.72, 0.68, 1.0))
            geom_names.append(f"{scoped}::visual{i}")
    info.world_parts[model.name] = (bodies, [] if bodies else geom_names)
    info.model_poses[model.name] = model.pose
    return bodies or geom_names


def _add_convex_parts(
    spec: mujoco.MjSpec,
    body: mujoco.MjsBody,
    shape: Shape,
    where: str,
    name: str,
    props: dict[str, object],
    extra: dict[str, object],
    names: list[str],
    cut: float | None = None,
) -> None:
    """Collide a concave mesh as its convex parts, decomposed below ``cut`` (m in the mesh's frame;
    None: whole) only (see navlab.sim.decompose)."""
    from navlab.sim.decompose import convex_parts

    g = shape.geometry
    assert g.mesh_path is not None
    parts = convex_parts(g.mesh_path, g.mesh_scale, cut=cut)
    extra = dict(extra)
    mass = extra.get("mass")
    if isinstance(mass, float):
        extra["mass"] = mass / len(parts)
    for k, (verts, faces) in enumerate(parts):
        part = f"{name}::part{k}"
        spec.add_mesh(name=part, uservert=verts.ravel().tolist(), userface=faces.ravel().tolist())
        geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=part)
        set_pose(geom, shape.origin)
        for key, value in {**props, **extra, "name": part}.items():
            setattr(geom, key, value)
        names.append(part)


def remove_world_model(spec: mujoco.MjSpec, name: str, info: BuildInfo) -> None:
    """Delete a model added by :func:`add_world_model` from the spec."""
    if name not in info.world_parts:
        raise SimError(f"no model named {name!r}; models: {sorted(info.world_parts)}")
    bodies, geoms = info.world_parts.pop(name)
    info.model_poses.pop(name, None)
    for body in bodies:
        spec.delete(spec.body(body))
    for geom in geoms:
        spec.delete(spec.geom(geom))
    for mesh in [m for m in spec.meshes if m.name.startswith(f"{name}::")]:  # its convex parts
        spec.delete(mesh)


def _add_scenery(spec: mujoco.MjSpec, world: WorldModel) -> None:
    spec.option.gravity = np.asarray(world.gravity, dtype=float)
    spec.visual.headlight.ambient = np.array([0.35, 0.35, 0.35])
    spec.add_texture(
        name="grid",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=np.array([0.62, 0.62, 0.62]),
        rgb2=np.array([0.55, 0.55, 0.55]),
        width=256,
        height=256,
    )
    mat = spec.add_material(name="grid", texrepeat=np.array([1.0, 1.0]), texuniform=True)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    spec.worldbody.add_light(
        name="sun",
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        pos=np.array([0.0, 0.0, 10.0]),
        dir=np.array([0.3, 0.2, -1.0]),
        diffuse=np.array([0.6, 0.6, 0.6]),
    )
    if world.ground_plane:
        spec.worldbody.add_geom(
            name="ground_plane",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=np.array([0.0, 0.0, 1.0]),
            **contact_props("ground", GROUP_WORLD),
            rgba=np.array([0.5, 0.5, 0.5, 1.0]),
        )  # mj_ray skips transparent geoms
        spec.worldbody.add_geom(
            name="ground_plane_visual",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=np.array([50.0, 50.0, 1.0]),
            material="grid",
            **VISUAL_PROPS,
        )


def build_spec(
    robot: RobotModel | None,
    world: WorldModel,
    *,
    timestep: float | None = None,
    robot_pose: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0),
    visuals: bool = True,
) -> tuple[mujoco.MjSpec, BuildInfo]:
    """The MuJoCo spec of ``world`` with ``robot`` at ``robot_pose`` (x, y, z, yaw), and its names.

    ``timestep`` (s) must lie in [0.5 ms, 2 ms]; by default the world's ``max_step_size`` raised to
    ``DEFAULT_STEP`` (2 ms);
    ``visuals=False`` leaves out the render-only geoms (faster stepping).
    """
    step = min(max(world.max_step_size, DEFAULT_STEP), MAX_STEP) if timestep is None else timestep
    if not MIN_STEP <= step <= MAX_STEP:
        raise SimError(f"physics timestep {step} s is outside [{MIN_STEP}, {MAX_STEP}] s (5 ms tips robots over)")
    spec = mujoco.MjSpec()
    spec.modelname = world.name or "world"
    spec.option.timestep = float(step)
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    # island discovery only pays off for many independent bodies; here it costs ~5 % of a step
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_ISLAND
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    # fixed links are merged into their moving parent at compile time (fewer bodies: ~12 % faster
    # steps); their frames live on as sites and as offsets (Simulation.link_pose)
    spec.compiler.fusestatic = True
    info = BuildInfo(visuals=visuals)
    _add_scenery(spec, world)
    if robot is not None:
        add_robot(spec, robot, info, robot_pose)
    from navlab.sim.decompose import decompose_world, robot_reach

    info.decompose_reach = robot_reach(robot)  # convex parts only where the robot can touch
    # uncached concave meshes: decomposed in parallel (progress bar), then cached
    decompose_world(world, reach=info.decompose_reach)
    for model in world.models:
        add_world_model(spec, model, info)
    return spec, info


def compile_spec(spec: mujoco.MjSpec, what: str = "model") -> mujoco.MjModel:
    """Compile, turning MuJoCo's compiler errors into a ``SimError``; MuJoCo's profiling timers go off (~12 % of a
    step, read by nobody: :mod:`navlab.sim.mjtimers`), and so do its spring and damper passes when the model has
    no spring or damper (:func:`no_passive_flags`; the spec keeps the flags for recompiles)."""
    profiling_timers_off()
    try:
        model = spec.compile()
    except ValueError as exc:
        raise SimError(f"MuJoCo could not compile the {what}: {exc}") from None
    bits = no_passive_flags(model)
    if bits:
        spec.option.disableflags |= bits
        model.opt.disableflags |= bits
    return model


def no_passive_flags(model: mujoco.MjModel) -> int:
    """``mjDSBL_SPRING`` / ``mjDSBL_DAMPER`` for a model with no joint stiffness / no joint damping and none of
    the other passive forces (tendons, flexes, gravity compensation, fluid, plugins, a passive callback): the
    passes then only add zeros, so skipping them changes no motion, bit for bit (~3 % of a step of navlab's
    robots). Models added at run time (``Simulation.spawn``) are free bodies: they add none either."""
    others = model.ntendon or model.nflex or model.ngravcomp or model.nplugin
    if others or model.opt.density or model.opt.viscosity or mujoco.get_mjcb_passive() is not None:
        return 0
    bits = 0
    if not model.jnt_stiffness.any():
        bits |= int(mujoco.mjtDisableBit.mjDSBL_SPRING)
    if not model.dof_damping.any():
        bits |= int(mujoco.mjtDisableBit.mjDSBL_DAMPER)
    return bits
