"""Models to spawn at run time: primitives (box, cylinder, sphere), SDF models, and the CLI's spec strings;
and the check that a robot's start pose is free (:func:`check_start_pose`).

A spec string is ``KIND:key=value,...``, e.g. ``box:name=crate,x=2,y=1,size=0.5`` or
``cylinder:x=1,radius=0.2,length=1,static=false`` or ``sdf:file=model.sdf,x=1``. Keys: ``name``,
``x``, ``y``, ``z`` (m; default: resting on the floor), ``yaw`` (rad), ``static`` (default true),
``mass`` (kg, dynamic models), ``size`` (box edge, or ``sx``/``sy``/``sz``), ``radius``, ``length``,
``t`` (simulated seconds at which to spawn, CLI only).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from navlab.core import ceilings
from navlab.description import Geometry, Inertial, Link, RobotModel, Shape, is_geometry_kind
from navlab.errors import did_you_mean
from navlab.sim.errors import SimError
from navlab.world import ModelSpec, WorldModel

KINDS = ("box", "cylinder", "sphere", "sdf")
_SIZES = frozenset({"size", "sx", "sy", "sz", "radius", "length", "mass"})
_KEYS = {
    "name",
    "x",
    "y",
    "z",
    "yaw",
    "static",
    "mass",
    "size",
    "sx",
    "sy",
    "sz",
    "radius",
    "length",
    "t",
    "file",
    "rgba",
}


def _inertial(kind: str, dims: tuple[float, ...], mass: float) -> Inertial:
    if kind == "box":
        sx, sy, sz = dims
        return Inertial(
            mass,
            ixx=mass * (sy * sy + sz * sz) / 12,
            iyy=mass * (sx * sx + sz * sz) / 12,
            izz=mass * (sx * sx + sy * sy) / 12,
        )
    if kind == "cylinder":
        r, h = dims
        side = mass * (3 * r * r + h * h) / 12
        return Inertial(mass, ixx=side, iyy=side, izz=mass * r * r / 2)
    r = dims[0]
    return Inertial(mass, ixx=0.4 * mass * r * r, iyy=0.4 * mass * r * r, izz=0.4 * mass * r * r)


def primitive_model(
    kind: str,
    name: str,
    dims: tuple[float, ...],
    *,
    x: float = 0.0,
    y: float = 0.0,
    z: float | None = None,
    yaw: float = 0.0,
    static: bool = True,
    mass: float = 1.0,
    rgba: tuple[float, float, float, float] = (0.55, 0.55, 0.6, 1.0),
) -> ModelSpec:
    """A one-link model. ``dims``: box (sx, sy, sz), cylinder (radius, length), sphere (radius,), in m.

    ``z`` defaults to resting on the floor (half the height).
    """
    expected = {"box": 3, "cylinder": 2, "sphere": 1}
    if not is_geometry_kind(kind) or kind not in expected:
        raise SimError(f"cannot spawn a {kind!r}; expected one of {', '.join(expected)} (or an SDF model)")
    if len(dims) != expected[kind] or min(dims) <= 0:
        raise SimError(f"spawn {kind} {name!r}: needs {expected[kind]} positive size values, got {dims}")
    if not static and mass <= 0:
        raise SimError(f"spawn {kind} {name!r}: mass must be positive, got {mass}")
    height = {"box": lambda: dims[2], "cylinder": lambda: dims[1], "sphere": lambda: 2 * dims[0]}[kind]()
    shape = Shape(Geometry(kind, tuple(float(d) for d in dims)), rgba=rgba)
    link = Link("link", inertial=None if static else _inertial(kind, dims, mass), collisions=[shape], visuals=[shape])
    pose = (float(x), float(y), height / 2 if z is None else float(z), 0.0, 0.0, float(yaw))
    return ModelSpec(name=name, pose=pose, static=static, links=[link])


def _bool(key: str, value: str) -> bool:
    if value.lower() in ("1", "true", "yes", "on"):
        return True
    if value.lower() in ("0", "false", "no", "off"):
        return False
    raise SimError(f"spawn spec: {key}={value!r} is not a boolean (true/false)")


def parse_spawn_spec(text: str, *, default_name: str = "") -> tuple[ModelSpec, float]:
    """A model from a ``KIND:key=value,...`` string (see the module docstring); returns (model, spawn time s)."""
    kind, _, rest = text.partition(":")
    kind = kind.strip().lower()
    if kind not in KINDS:
        raise SimError(f"spawn spec {text!r}: kind {kind!r} is not one of {', '.join(KINDS)}")
    opts: dict[str, str] = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, sep, value = item.partition("=")
        if not sep:
            raise SimError(f"spawn spec {text!r}: {item!r} is not key=value")
        if key not in _KEYS:
            hint = did_you_mean(key, sorted(_KEYS), template=" (did you mean {!r}?)")
            raise SimError(f"spawn spec {text!r}: unknown key {key!r}{hint}")
        opts[key] = value

    def num(key: str, default: float | None = None) -> Any:
        if key not in opts:
            return default
        try:
            value = float(opts[key])
        except ValueError:
            raise SimError(f"spawn spec {text!r}: {key}={opts[key]!r} is not a number") from None
        ceiling = ceilings()["model_m" if key in _SIZES else "coordinate_m"]
        if not abs(value) <= ceiling.limit:  # NaN and inf fail too
            raise SimError(
                f"spawn spec {text!r}: {key}={opts[key]}: expected a finite number within "
                f"±{ceiling.limit:g} {ceiling.unit} ({ceiling.why})"
            )
        return value

    name = opts.get("name") or default_name or kind
    place = {"x": num("x", 0.0), "y": num("y", 0.0), "z": num("z"), "yaw": num("yaw", 0.0)}
    static = _bool("static", opts["static"]) if "static" in opts else True
    t = num("t", 0.0)
    if t < 0:
        raise SimError(f"spawn spec {text!r}: t={opts['t']}: expected a time >= 0 s")
    if kind == "sdf":
        if "file" not in opts:
            raise SimError(f"spawn spec {text!r}: sdf needs file=PATH")
        return load_sdf_model(Path(opts["file"]), name=opts.get("name"), **place), t
    size = num("size")
    if kind == "box":
        edge = 0.5 if size is None else size
        dims: tuple[float, ...] = (num("sx", edge), num("sy", edge), num("sz", edge))
    elif kind == "cylinder":
        dims = (num("radius", 0.2), num("length", 1.0))
    else:
        dims = (num("radius", 0.25 if size is None else size / 2),)
    model = primitive_model(kind, name, dims, static=static, mass=num("mass", 1.0), **place)
    return model, t


def load_sdf_model(
    path: Path,
    *,
    name: str | None = None,
    x: float = 0.0,
    y: float = 0.0,
    z: float | None = None,
    yaw: float = 0.0,
) -> ModelSpec:
    """An SDF model file (``model.sdf`` or a model directory) placed at (x, y, z, yaw) in the world."""
    try:
        from navlab.world import load_model
    except ImportError:
        raise SimError("loading SDF models needs navlab.world.load_model, which is not available") from None
    model: ModelSpec = load_model(path)
    if name:
        model.name = name
    mz = model.pose[2] if z is None else z
    model.pose = (x, y, mz, model.pose[3], model.pose[4], yaw)
    return model


# ------------------------------------------------------------------------------------- start poses
def robot_outline(robot: RobotModel) -> tuple[np.ndarray, float, float]:
    """The robot's collision geometry at zero joint angles in its root link's frame: xy points (k, 2)
    whose convex hull covers it, and its lowest and highest z (m)."""
    parent_joint = {j.child: j for j in robot.joints}

    def root_T_link(name: str) -> np.ndarray:
        m = np.eye(4)
        while name in parent_joint:
            joint = parent_joint[name]
            m = joint.origin.matrix() @ m
            name = joint.parent
        return m

    pts = [
        _corners(shape, root_T_link(link.name) @ shape.origin.matrix())
        for link in robot.links.values()
        for shape in link.collisions
    ]
    if not pts:
        return np.zeros((1, 2)), 0.0, 0.0
    allp = np.vstack(pts)
    return allp[:, :2], float(allp[:, 2].min()), float(allp[:, 2].max())


def _corners(shape: Shape, root_T_shape: np.ndarray) -> np.ndarray:
    """Points (k, 3) in the root frame whose convex hull covers the shape (boxes around round shapes)."""
    g = shape.geometry
    if g.kind == "mesh" and g.mesh_path is not None:
        from navlab.description import read_mesh

        local = read_mesh(g.mesh_path)[0] * np.asarray(g.mesh_scale)
    else:
        if g.kind == "box":
            half = np.asarray(g.size, dtype=float) / 2
        elif g.kind == "cylinder":
            half = np.array([g.size[0], g.size[0], g.size[1] / 2])
        else:
            half = np.full(3, g.size[0] if g.size else 0.0)
        local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    return local @ root_T_shape[:3, :3].T + root_T_shape[:3, 3]


def check_start_pose(
    robot: RobotModel,
    world: WorldModel,
    pose: tuple[float, float, float],
    *,
    margin: float = 0.02,
    resolution: float = 0.02,
) -> None:
    """Refuse a start pose (x, y, yaw: m, m, rad, the root link in the world) at which the robot's
    collision outline (its convex hull seen from above, shrunk by ``margin`` m so that touching is
    allowed) overlaps a world model within the robot's height, or that is not a finite pose within the
    ``coordinate_m`` ceiling. SimError names the world file and the models; started there, the contact
    solver would throw the robot metres away."""
    x, y, yaw = pose
    limit = ceilings()["coordinate_m"].limit
    if not all(abs(v) <= limit for v in pose):  # NaN fails too
        raise SimError(f"start pose x={x:g} y={y:g} yaw={yaw:g}: expected finite numbers within ±{limit:g}")
    names = _overlapping(robot, world, pose, margin=margin, resolution=resolution)
    if names:
        shown = ", ".join(map(repr, names[:5])) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
        where = f"{world.source}: " if world.source is not None else ""
        raise SimError(
            f"{where}start pose x={x:g} y={y:g} yaw={yaw:g} puts robot {robot.name!r} inside {shown} "
            f"of world {world.name!r}; started there, the contact solver would throw it away. Pick a "
            "free pose (--x/--y/--yaw, or x:= y:= yaw:=)"
        )


def check_spawn_clear(robot: RobotModel, robot_pose: tuple[float, float, float], model: ModelSpec) -> None:
    """Refuse to spawn ``model`` where it would overlap the robot at ``robot_pose`` (x, y, yaw of the root
    link; the contact solver would throw the robot away, or make the simulation unstable)."""
    if _overlapping(robot, WorldModel(name="spawn", models=[model]), robot_pose):
        x, y = model.pose[:2]
        raise SimError(
            f"spawn {model.name!r} at x={x:g} y={y:g}: it would overlap robot {robot.name!r} at "
            f"x={robot_pose[0]:.3f} y={robot_pose[1]:.3f}; spawn it where the robot is not"
        )


def _overlapping(
    robot: RobotModel,
    world: WorldModel,
    pose: tuple[float, float, float],
    *,
    margin: float = 0.02,
    resolution: float = 0.02,
) -> list[str]:
    """The models of ``world`` that the robot's outline at ``pose`` overlaps ("an obstacle" if unnamed)."""
    from navlab.world import occupancy, shape_footprints

    xy, z_lo, z_hi = robot_outline(robot)
    x, y, yaw = pose
    c, s = np.cos(yaw), np.sin(yaw)
    world_xy = xy @ np.array([[c, s], [-s, c]]) + np.array([x, y])
    height = max(z_hi - z_lo, 0.05)
    band = (margin, height - margin) if height > 3 * margin else (0.0, height)  # above the floor contact
    lo, hi = world_xy.min(axis=0) - resolution, world_xy.max(axis=0) + resolution
    bounds = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    occ = occupancy(world, resolution, bounds, z_min=band[0], z_max=band[1])
    if not occ.any():
        return []
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(world_xy)
        eq = hull.equations  # a x + b y + c <= 0 inside
    except (QhullError, ValueError):  # a degenerate outline: a disc around its centre
        centre = world_xy.mean(axis=0)
        r = float(np.linalg.norm(world_xy - centre, axis=1).max())
        eq = None
    iy, ix = np.nonzero(occ)
    cells = np.column_stack([bounds[0] + (ix + 0.5) * resolution, bounds[1] + (iy + 0.5) * resolution])
    if eq is not None:
        inside = (cells @ eq[:, :2].T + eq[:, 2] <= -margin).all(axis=1)
    else:
        inside = np.linalg.norm(cells - centre, axis=1) <= r - margin
    if not inside.any():
        return []
    hit = cells[inside]
    names = sorted(
        {
            fp.name.split("::")[0]
            for fp in shape_footprints(world, z_min=band[0], z_max=band[1])
            if _overlaps(fp.bounds(), hit)
        }
    )
    return names or ["an obstacle"]


def _overlaps(bounds: tuple[float, float, float, float], pts: np.ndarray) -> bool:
    x0, y0, x1, y1 = bounds
    return bool(((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)).any())
