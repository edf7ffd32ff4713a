"""Models to spawn at run time: primitives (box, cylinder, sphere), SDF models, and the CLI's spec strings.

A spec string is ``KIND:key=value,...``, e.g. ``box:name=crate,x=2,y=1,size=0.5`` or
``cylinder:x=1,radius=0.2,length=1,static=false`` or ``sdf:file=model.sdf,x=1``. Keys: ``name``,
``x``, ``y``, ``z`` (m; default: resting on the floor), ``yaw`` (rad), ``static`` (default true),
``mass`` (kg, dynamic models), ``size`` (box edge, or ``sx``/``sy``/``sz``), ``radius``, ``length``,
``t`` (simulated seconds at which to spawn, CLI only).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from navlab.description.model import Geometry, Inertial, Link, Shape, is_geometry_kind
from navlab.sim.errors import SimError
from navlab.world.model import ModelSpec

KINDS = ("box", "cylinder", "sphere", "sdf")
_KEYS = {"name", "x", "y", "z", "yaw", "static", "mass", "size", "sx", "sy", "sz", "radius", "length", "t",
         "file", "rgba"}


def _inertial(kind: str, dims: tuple[float, ...], mass: float) -> Inertial:
    if kind == "box":
        sx, sy, sz = dims
        return Inertial(mass, ixx=mass * (sy * sy + sz * sz) / 12, iyy=mass * (sx * sx + sz * sz) / 12,
                        izz=mass * (sx * sx + sy * sy) / 12)
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
    link = Link("link", inertial=None if static else _inertial(kind, dims, mass), collisions=[shape],
                visuals=[shape])
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
            import difflib

            close = difflib.get_close_matches(key, sorted(_KEYS), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SimError(f"spawn spec {text!r}: unknown key {key!r}{hint}")
        opts[key] = value

    def num(key: str, default: float | None = None) -> Any:
        if key not in opts:
            return default
        try:
            return float(opts[key])
        except ValueError:
            raise SimError(f"spawn spec {text!r}: {key}={opts[key]!r} is not a number") from None

    name = opts.get("name") or default_name or kind
    place = {"x": num("x", 0.0), "y": num("y", 0.0), "z": num("z"), "yaw": num("yaw", 0.0)}
    static = _bool("static", opts["static"]) if "static" in opts else True
    t = num("t", 0.0)
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
    path: Path, *, name: str | None = None, x: float = 0.0, y: float = 0.0, z: float | None = None,
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
