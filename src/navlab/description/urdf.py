"""URDF text → links and joints of a :class:`RobotModel` (plugins are read by ``gazebo.py``).

Every malformed element raises a DescriptionError naming the file and the element, e.g.
``mybot.xacro: <link name="left_wheel">/<inertial>/<mass>: attribute value: expected a number, got 'x'``.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Container
from pathlib import Path

from navlab.description.errors import DescriptionError, NotFoundError
from navlab.description.model import (
    Geometry,
    Inertial,
    Joint,
    Link,
    Origin,
    Shape,
    Vec3,
    is_geometry_kind,
    is_joint_type,
)

JOINT_TYPES = ("fixed", "continuous", "revolute", "prismatic", "floating", "planar")

#: resolves a mesh ``filename`` attribute (and the element naming it, for errors) to
#: (simulator-readable STL/OBJ path, unit scale factor, the file the attribute named)
MeshResolver = Callable[[str, str], tuple[Path, float, Path]]


def floats(text: str | None, n: int | None, where: str, what: str) -> tuple[float, ...]:
    """Parse whitespace-separated numbers; DescriptionError naming ``where``/``what`` if malformed."""
    parts = (text or "").split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise DescriptionError(f"{where}: {what}: expected numbers, got {text!r}") from None
    if n is not None and len(values) != n:
        raise DescriptionError(f"{where}: {what}: expected {n} numbers, got {text!r}")
    if not all(math.isfinite(v) for v in values):
        raise DescriptionError(f"{where}: {what}: numbers must be finite, got {text!r}")
    return values


def _attr_float(el: ET.Element, key: str, where: str, default: float | None = None) -> float:
    raw = el.get(key)
    if raw is None:
        if default is None:
            raise DescriptionError(f"{where}: missing attribute {key!r}")
        return default
    return floats(raw, 1, where, f"attribute {key}")[0]


def parse_origin(el: ET.Element | None, where: str) -> Origin:
    """An ``<origin xyz rpy>`` element (absent → identity)."""
    if el is None:
        return Origin()
    xyz = floats(el.get("xyz", "0 0 0"), 3, where + "/<origin>", "attribute xyz")
    rpy = floats(el.get("rpy", "0 0 0"), 3, where + "/<origin>", "attribute rpy")
    return Origin(xyz=(xyz[0], xyz[1], xyz[2]), rpy=(rpy[0], rpy[1], rpy[2]))


def parse_geometry(el: ET.Element | None, where: str, resolve_mesh: MeshResolver) -> Geometry:
    """A ``<geometry>`` with one of box/cylinder/sphere/mesh."""
    where = where + "/<geometry>"
    if el is None:
        raise DescriptionError(f"{where}: missing (expected <box>, <cylinder>, <sphere> or <mesh>)")
    shapes = [c for c in el if isinstance(c.tag, str)]
    if len(shapes) != 1:
        raise DescriptionError(
            f"{where}: expected exactly one of <box>, <cylinder>, <sphere>, <mesh>; found {[c.tag for c in shapes]}"
        )
    s = shapes[0]
    w = f"{where}/<{s.tag}>"
    if s.tag == "box":
        size = floats(s.get("size"), 3, w, "attribute size")
    elif s.tag == "cylinder":
        size = (_attr_float(s, "radius", w), _attr_float(s, "length", w))
    elif s.tag == "sphere":
        size = (_attr_float(s, "radius", w),)
    elif s.tag == "mesh":
        filename = s.get("filename")
        if not filename:
            raise DescriptionError(f"{w}: missing attribute 'filename'")
        sc = floats(s.get("scale", "1 1 1"), 3, w, "attribute scale")
        path, unit, named = resolve_mesh(filename, w)
        return Geometry(
            "mesh", mesh_path=path, mesh_scale=(sc[0] * unit, sc[1] * unit, sc[2] * unit), mesh_source=named
        )
    else:
        raise DescriptionError(f"{w}: unknown geometry (expected box, cylinder, sphere or mesh)")
    if any(v <= 0 for v in size):
        raise DescriptionError(f"{w}: sizes must be positive, got {size}")
    kind = s.tag
    assert is_geometry_kind(kind)  # box, cylinder or sphere: anything else returned or raised above
    return Geometry(kind, size=size)


def _rgba(
    visual: ET.Element, materials: dict[str, tuple[float, float, float, float]], where: str
) -> tuple[float, float, float, float] | None:
    mat = visual.find("material")
    if mat is None:
        return None
    color = mat.find("color")
    if color is not None and color.get("rgba"):
        r = floats(color.get("rgba"), 4, where + "/<material>/<color>", "attribute rgba")
        return (r[0], r[1], r[2], r[3])
    return materials.get(mat.get("name", ""))


def parse_inertial(el: ET.Element, where: str) -> Inertial:
    """An ``<inertial>``: mass (kg, ≥ 0), COM origin, inertia tensor."""
    where = where + "/<inertial>"
    mass_el = el.find("mass")
    if mass_el is None:
        raise DescriptionError(f"{where}: missing <mass value=...>")
    mass = _attr_float(mass_el, "value", where + "/<mass>")
    if mass < 0:
        raise DescriptionError(f"{where}/<mass>: mass must be >= 0 kg, got {mass}")
    inertia = el.find("inertia")
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    vals = {k: 0.0 for k in keys}
    if inertia is not None:
        vals = {k: _attr_float(inertia, k, where + "/<inertia>", 0.0) for k in keys}
        for k in ("ixx", "iyy", "izz"):
            if vals[k] < 0:
                raise DescriptionError(f"{where}/<inertia>: {k} must be >= 0 kg m^2, got {vals[k]}")
    return Inertial(mass=mass, origin=parse_origin(el.find("origin"), where), **vals)


def _shapes(
    link_el: ET.Element,
    tag: str,
    where: str,
    resolve_mesh: MeshResolver,
    materials: dict[str, tuple[float, float, float, float]],
    warnings: list[str] | None,
) -> list[Shape]:
    """The link's ``<collision>`` or ``<visual>`` elements. A visual whose mesh file is missing is
    skipped with a warning when ``warnings`` is given (Gazebo loads the robot without it)."""
    out = []
    for i, el in enumerate(link_el.findall(tag)):
        w = f"{where}/<{tag}{' name=' + repr(el.get('name')) if el.get('name') else ''}>[{i}]"
        try:
            geometry = parse_geometry(el.find("geometry"), w, resolve_mesh)
        except NotFoundError as exc:
            if tag != "visual" or warnings is None:
                raise
            warnings.append(f"{exc}; visual skipped (Gazebo shows the link without it)")
            continue
        out.append(
            Shape(
                geometry=geometry,
                origin=parse_origin(el.find("origin"), w),
                rgba=_rgba(el, materials, w) if tag == "visual" else None,
                name=el.get("name", ""),
            )
        )
    return out


def parse_link(
    el: ET.Element,
    where: str,
    resolve_mesh: MeshResolver,
    materials: dict[str, tuple[float, float, float, float]],
    warnings: list[str] | None = None,
) -> Link:
    """One ``<link>`` (``warnings``: where skipped visuals are reported; None: a missing visual mesh is an error)."""
    inertial_el = el.find("inertial")
    return Link(
        name=el.get("name", ""),
        inertial=parse_inertial(inertial_el, where) if inertial_el is not None else None,
        collisions=_shapes(el, "collision", where, resolve_mesh, materials, warnings),
        visuals=_shapes(el, "visual", where, resolve_mesh, materials, warnings),
    )


def parse_joint(el: ET.Element, where: str) -> Joint:
    """One ``<joint>``; revolute and prismatic joints need a ``<limit>``, as in urdfdom."""
    jtype = el.get("type", "")
    if not is_joint_type(jtype):
        raise DescriptionError(
            f"{where}: type {jtype!r} is not a URDF joint type (expected one of {', '.join(JOINT_TYPES)})"
        )
    links = {}
    for tag in ("parent", "child"):
        sub = el.find(tag)
        if sub is None or not sub.get("link"):
            raise DescriptionError(f"{where}: missing <{tag} link=...>")
        links[tag] = sub.get("link", "")
    axis: Vec3 = (1.0, 0.0, 0.0)
    axis_el = el.find("axis")
    if axis_el is not None:
        a = floats(axis_el.get("xyz", "1 0 0"), 3, where + "/<axis>", "attribute xyz")
        norm = math.sqrt(sum(v * v for v in a))
        if norm < 1e-9 and jtype not in ("fixed", "floating"):
            raise DescriptionError(f"{where}/<axis>: axis must be a non-zero vector, got {a}")
        axis = (a[0] / norm, a[1] / norm, a[2] / norm) if norm >= 1e-9 else axis
    lower = upper = effort = velocity = None
    limit = el.find("limit")
    if limit is not None:
        w = where + "/<limit>"
        lower = _attr_float(limit, "lower", w, 0.0)
        upper = _attr_float(limit, "upper", w, 0.0)
        effort = _attr_float(limit, "effort", w, 0.0) if limit.get("effort") is not None else None
        velocity = _attr_float(limit, "velocity", w, 0.0) if limit.get("velocity") is not None else None
        for name, value in (("effort", effort), ("velocity", velocity)):
            if value is not None and value < 0:
                raise DescriptionError(f"{w}: {name} must be >= 0, got {value}")
        if jtype == "continuous":
            lower = upper = None
    elif jtype in ("revolute", "prismatic"):
        raise DescriptionError(f"{where}: a {jtype} joint needs <limit lower upper effort velocity>")
    damping = friction = 0.0
    dyn = el.find("dynamics")
    if dyn is not None:
        damping = _attr_float(dyn, "damping", where + "/<dynamics>", 0.0)
        friction = _attr_float(dyn, "friction", where + "/<dynamics>", 0.0)
    return Joint(
        name=el.get("name", ""),
        type=jtype,
        parent=links["parent"],
        child=links["child"],
        origin=parse_origin(el.find("origin"), where),
        axis=axis,
        lower=lower,
        upper=upper,
        effort=effort,
        velocity=velocity,
        damping=damping,
        friction=friction,
    )


def _element_name(el: ET.Element, source: str, seen: Container[str]) -> tuple[str, str]:
    """(name, where for messages) of a ``<link>`` or ``<joint>``, refusing a missing or repeated name."""
    tag, name = el.tag, el.get("name")
    if not name:
        raise DescriptionError(f"{source}: a <{tag}> has no name attribute")
    where = f'{source}: <{tag} name="{name}">'
    if name in seen:
        raise DescriptionError(f"{where}: duplicate {tag} name")
    return name, where


def parse_urdf(
    root: ET.Element, source: str, resolve_mesh: MeshResolver, *, warnings: list[str] | None = None
) -> tuple[str, dict[str, Link], list[Joint], str]:
    """Parse a ``<robot>`` element; return (robot name, links, joints, root link).

    ``warnings``: a list that collects what loads with a warning (a visual whose mesh is missing is
    skipped); without it every missing mesh is an error.
    Checks that names are unique, joints name existing links, and the links form one tree.
    """
    if root.tag != "robot":
        raise DescriptionError(f"{source}: top element is <{root.tag}>, expected <robot>")
    name = root.get("name") or ""
    if not name:
        raise DescriptionError(f"{source}: <robot> has no name attribute")
    materials: dict[str, tuple[float, float, float, float]] = {}
    for m in root.findall("material"):
        color = m.find("color")
        if m.get("name") and color is not None and color.get("rgba"):
            r = floats(color.get("rgba"), 4, f'{source}: <material name="{m.get("name")}">', "rgba")
            materials[m.get("name", "")] = (r[0], r[1], r[2], r[3])
    links: dict[str, Link] = {}
    for el in root.findall("link"):
        lname, where = _element_name(el, source, links)
        links[lname] = parse_link(el, where, resolve_mesh, materials, warnings)
    if not links:
        raise DescriptionError(f'{source}: <robot name="{name}"> has no <link>')
    joints: list[Joint] = []
    seen: set[str] = set()
    parent_of: dict[str, str] = {}
    for el in root.findall("joint"):
        jname, where = _element_name(el, source, seen)
        seen.add(jname)
        joint = parse_joint(el, where)
        for role, lname in (("parent", joint.parent), ("child", joint.child)):
            if lname not in links:
                raise DescriptionError(f"{where}/<{role}>: link {lname!r} is not defined")
        if joint.child in parent_of:
            raise DescriptionError(
                f"{where}: link {joint.child!r} already has parent joint to "
                f"{parent_of[joint.child]!r} (a URDF is a tree)"
            )
        parent_of[joint.child] = joint.parent
        joints.append(joint)
    roots = [n for n in links if n not in parent_of]
    if len(roots) != 1:
        raise DescriptionError(
            f"{source}: the links must form one tree with one root; roots found: {roots or 'none (a joint cycle)'}"
        )
    for lname in links:  # detect cycles
        seen_chain = {lname}
        cur = lname
        while cur in parent_of:
            cur = parent_of[cur]
            if cur in seen_chain:
                raise DescriptionError(f"{source}: joint cycle through link {cur!r}")
            seen_chain.add(cur)
    return name, links, joints, roots[0]
