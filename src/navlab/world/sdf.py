"""``load_world``: a Gazebo-classic SDF ``.world`` (SDF 1.4–1.7) → :class:`WorldModel`.

Reads the ground plane, gravity, ``<physics><max_step_size>``, ``<model>`` elements (static or
dynamic, nested models flattened to ``parent::child`` link names) with box/cylinder/sphere/mesh
collisions and visuals, ``<include><uri>model://name</uri>`` through a model path, and a saved
``<state>``'s model poses. Lights, scenes, GUI settings are ignored; plugins, actors, joints and
unsupported geometry are reported in ``WorldModel.warnings``.
"""

from __future__ import annotations

import collections
import contextlib
import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Iterator
from pathlib import Path

from navlab import resources
from navlab.description import (
    DescriptionError,
    Geometry,
    Inertial,
    Link,
    NotFoundError,
    Origin,
    PackageIndex,
    Shape,
    gazebo_material,
    is_convex,
    prepare_mesh,
    read_mesh,
    up_axis_warning,
)
from navlab.geometry import compose6
from navlab.world.errors import WorldError
from navlab.world.model import ModelSpec, Pose6, WorldModel
from navlab.world.sdf_xml import flag, floats, num, parse_xml, pose_of, vec3

SUPPORTED_VERSIONS = ("1.4", "1.5", "1.6", "1.7")
_IGNORED_WORLD_TAGS = (
    "light",
    "scene",
    "gui",
    "audio",
    "wind",
    "atmosphere",
    "spherical_coordinates",
    "magnetic_field",
    "physics",
    "gravity",
    "state",
    "road",
    "frame",
)


MAX_NESTING = 32  # models and includes inside each other (xacro's include depth too)


class _Loader:
    """One world load: model path, warnings, and whether a ground plane was seen."""

    def __init__(self, model_paths: list[Path]) -> None:
        self.model_paths = model_paths
        self.index = PackageIndex(use_env=True)
        self.warnings: list[str] = []
        self.ground_plane = False
        self.files: list[Path] = []  # the model files being included, outermost first (loops are refused)
        self.depth = 0  # models and includes nested so far

    @contextlib.contextmanager
    def _nested(self, where: str, file: Path | None = None) -> Iterator[None]:
        """One level deeper (a nested model, or an include of ``file``): refuse include loops and nesting
        beyond ``MAX_NESTING`` (either would recurse until Python's stack runs out)."""
        real = file.resolve() if file is not None else None
        if real is not None and real in self.files:
            chain = " -> ".join(p.name for p in [*self.files[self.files.index(real) :], real])
            raise WorldError(f"{where}: {file} includes itself (include loop {chain})")
        if self.depth >= MAX_NESTING:
            raise WorldError(f"{where}: models and includes nest deeper than {MAX_NESTING} levels")
        self.depth += 1
        if real is not None:
            self.files.append(real)
        try:
            yield
        finally:
            self.depth -= 1
            if real is not None:
                self.files.pop()

    # ------------------------------------------------------------------------------- includes
    def find_model_dir(self, uri: str, base_dir: Path, where: str) -> Path:
        """The directory of an included model (``model://name``, ``file://dir`` or a path)."""
        if uri.startswith("model://") or uri.startswith("package://"):
            try:
                if uri.startswith("package://"):
                    return self.index.resolve_uri(uri, base_dir=base_dir)
                return self.index.find_model(uri.rstrip("/"), self.model_paths)
            except DescriptionError as exc:
                raise WorldError(f"{where}: {exc}") from None
        path = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
        path = path if path.is_absolute() else base_dir / path
        if not path.exists():
            raise WorldError(f"{where}: included model {uri!r} not found (looked for {path})")
        return path

    def model_sdf_file(self, model_dir: Path, where: str) -> Path:
        """The SDF file a model directory's ``model.config`` names (highest version ≤ 1.7 preferred)."""
        if model_dir.is_file():
            return model_dir
        config = model_dir / "model.config"
        if config.is_file():
            root = parse_xml(config, "model.config")
            entries = [(e.get("version", "0"), (e.text or "").strip()) for e in root.findall("sdf")]
            entries = [e for e in entries if e[1]]

            def key(e: tuple[str, str]) -> tuple[bool, tuple[int, ...]]:
                try:
                    ver = tuple(int(x) for x in e[0].split("."))
                except ValueError:
                    ver = (0,)
                return (ver <= (1, 7), ver)

            if entries:
                return model_dir / max(entries, key=key)[1]
        for name in ("model.sdf", f"{model_dir.name}.sdf"):
            if (model_dir / name).is_file():
                return model_dir / name
        raise WorldError(
            f"{where}: model directory {model_dir} has no model.config naming an SDF file (nor a model.sdf)"
        )

    def include(self, el: ET.Element, base_dir: Path, where: str) -> list[ModelSpec]:
        """An ``<include>``: load the model file and apply the include's name, pose and static."""
        uri = (el.findtext("uri") or "").strip()
        if not uri:
            raise WorldError(f"{where}: <include> without <uri>")
        w = f"{where}/<include uri={uri!r}>"
        sdf_file = self.model_sdf_file(self.find_model_dir(uri, base_dir, w), w)
        with self._nested(w, sdf_file):
            return self._include_file(el, sdf_file, w)

    def _include_file(self, el: ET.Element, sdf_file: Path, w: str) -> list[ModelSpec]:
        root = parse_xml(sdf_file, "model SDF")
        model_el = root.find("model")
        if model_el is None:
            if root.find("light") is None and root.find("actor") is None:
                self.warnings.append(f"{w}: {sdf_file} holds no <model>; ignored")
            return []
        name = (el.findtext("name") or "").strip() or model_el.get("name", "")
        pose = pose_of(el, w) if el.find("pose") is not None else None
        static = flag(el, "static", flag(model_el, "static", False))
        return self.model(model_el, sdf_file, name=name, pose=pose, static=static)

    # ------------------------------------------------------------------------------- models
    def model(
        self,
        el: ET.Element,
        file: Path,
        *,
        name: str | None = None,
        pose: Pose6 | None = None,
        static: bool | None = None,
    ) -> list[ModelSpec]:
        """A ``<model>`` (nested models and includes flattened into it). Returns [] if it had only planes."""
        name = name or el.get("name") or ""
        where = f'{file}: <model name="{name}">'
        if not name:
            raise WorldError(f"{file}: a <model> has no name attribute")
        spec = ModelSpec(
            name=name,
            pose=pose if pose is not None else pose_of(el, where, self.warnings),
            static=static if static is not None else flag(el, "static", False),
        )
        self._fill(spec, el, file, where, prefix="", frame=(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
        return [spec] if spec.links else []

    def _fill(self, spec: ModelSpec, el: ET.Element, file: Path, where: str, prefix: str, frame: Pose6) -> None:
        """Add ``el``'s links to ``spec`` with names ``prefix + link`` at ``frame`` ∘ link pose."""
        for child in el:
            tag = child.tag
            if tag == "link":
                link, origin = self.link(child, file, f'{where}/<link name="{child.get("name")}">', spec.static)
                if link is None:
                    continue
                link.name = prefix + link.name
                if link.name in spec.link_origins:
                    raise WorldError(f'{where}: duplicate link name "{link.name}"')
                spec.links.append(link)
                spec.link_origins[link.name] = Origin.from_pose6(compose6(frame, origin))
            elif tag == "model":
                sub = child.get("name", "")
                w = f'{where}/<model name="{sub}">'
                with self._nested(w):
                    self._fill(spec, child, file, w, prefix + sub + "::", compose6(frame, pose_of(child, w)))
            elif tag == "include":
                for inc in self.include(child, file.parent, where):
                    for link in inc.links:
                        o = inc.link_origins[link.name]
                        link.name = f"{prefix}{inc.name}::{link.name}"
                        spec.links.append(link)
                        model_T_inc = compose6(frame, inc.pose)
                        spec.link_origins[link.name] = Origin.from_pose6(compose6(model_T_inc, o.as_pose6()))
            elif tag == "joint" and not spec.static:
                self.warnings.append(
                    f'{where}/<joint name="{child.get("name")}">: joints of world models are not '
                    "simulated; the links move freely"
                )
            elif tag == "plugin":
                self.warnings.append(
                    f'{where}/<plugin filename="{child.get("filename")}">: model plugins are not simulated; ignored'
                )

    def link(self, el: ET.Element, file: Path, where: str, static: bool) -> tuple[Link | None, Pose6]:
        """A ``<link>``: collisions, visuals, inertial (SDF default 1 kg, unit inertia)."""
        name = el.get("name") or ""
        if not name:
            raise WorldError(f"{where}: a <link> has no name attribute")
        link = Link(name=name)
        inertial = el.find("inertial")
        if inertial is not None or not static:
            iw = f"{where}/<inertial>"
            inertia = inertial.find("inertia") if inertial is not None else None
            mass = num(inertial, "mass", iw, 1.0)
            if mass <= 0:
                raise WorldError(f"{iw}/<mass>: must be > 0 kg, got {mass}")
            vals = {
                k: num(inertia, k, iw + "/<inertia>", 1.0 if k in ("ixx", "iyy", "izz") else 0.0)
                for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            }
            o = pose_of(inertial, iw) if inertial is not None else (0.0,) * 6
            link.inertial = Inertial(mass=mass, origin=Origin(xyz=o[:3], rpy=o[3:]), **vals)
        had_shapes = False
        for tag in ("collision", "visual"):
            for i, sel in enumerate(el.findall(tag)):
                had_shapes = True
                sw = f'{where}/<{tag} name="{sel.get("name", i)}">'
                shape = self.shape(sel, file, sw, tag == "collision")
                if shape is None:
                    continue
                (link.collisions if tag == "collision" else link.visuals).append(shape)
                if tag == "collision" and link.mu1 is None:
                    ode = sel.find("surface/friction/ode")
                    if ode is not None and ode.find("mu") is not None:
                        link.mu1 = num(ode, "mu", sw, 1.0)
                        link.mu2 = num(ode, "mu2", sw, link.mu1)
        if had_shapes and not link.collisions and not link.visuals:
            return None, (0.0,) * 6  # only planes: the ground
        return link, pose_of(el, where, self.warnings)

    def shape(self, el: ET.Element, file: Path, where: str, collision: bool) -> Shape | None:
        """A collision or visual; None for a plane (recorded as the ground) or unsupported geometry."""
        geo = el.find("geometry")
        if geo is None:
            raise WorldError(f"{where}: missing <geometry>")
        kinds = [c for c in geo if isinstance(c.tag, str)]
        if not kinds:
            if collision:
                self.warnings.append(f"{where}: empty <geometry>; ignored")
            return None
        g = kinds[0]
        gw = f"{where}/<geometry>/<{g.tag}>"
        if g.tag == "plane":
            normal = floats(g.findtext("normal") or "0 0 1", 3, gw + "/<normal>")
            if normal[2] > 0.99 and collision:
                self.ground_plane = True
            elif collision:
                self.warnings.append(f"{gw}: only a horizontal ground plane is supported; ignored")
            return None
        if g.tag == "box":
            size = floats(g.findtext("size"), 3, gw + "/<size>")
            geometry = Geometry("box", size=size)
        elif g.tag == "cylinder":
            geometry = Geometry("cylinder", size=(num(g, "radius", gw, 0.0), num(g, "length", gw, 0.0)))
        elif g.tag == "sphere":
            geometry = Geometry("sphere", size=(num(g, "radius", gw, 0.0),))
        elif g.tag == "mesh":
            mesh = self.mesh(g, file, gw, collision)
            if mesh is None:
                return None
            geometry = mesh
        else:
            self.warnings.append(
                f"{gw}: geometry <{g.tag}> is not supported (box, cylinder, sphere, mesh, plane); ignored"
            )
            return None
        if g.tag != "mesh" and any(v <= 0 for v in geometry.size):
            raise WorldError(f"{gw}: sizes must be positive, got {geometry.size}")
        p = pose_of(el, where, self.warnings)
        return Shape(
            geometry=geometry,
            origin=Origin(xyz=p[:3], rpy=p[3:]),
            name=el.get("name", ""),
            rgba=None if collision else self.rgba(el, where),
        )

    def mesh(self, g: ET.Element, file: Path, where: str, collision: bool) -> Geometry | None:
        """A ``<mesh><uri>`` resolved through the model path; DAE converted; convexity checked.
        None: a visual whose mesh is not found (skipped with a warning, as Gazebo does)."""
        uri = (g.findtext("uri") or "").strip()
        if not uri:
            raise WorldError(f"{where}: missing <uri>")
        if g.find("submesh") is not None:
            self.warnings.append(f"{where}: <submesh> not supported; the whole mesh is used")
        scale = floats(g.findtext("scale") or "1 1 1", 3, where + "/<scale>")
        try:
            named = self.index.resolve_uri(uri, base_dir=file.parent, model_paths=self.model_paths)
            sim_path, unit = prepare_mesh(named, where)
            convex = is_convex(*read_mesh(sim_path)) if collision else None
        except NotFoundError as exc:
            if collision:
                raise WorldError(str(exc) if str(exc).startswith(where) else f"{where}: {exc}") from None
            self.warnings.append(f"{where}: {exc}; visual skipped (Gazebo shows the model without it)")
            return None
        except DescriptionError as exc:
            raise WorldError(str(exc)) from None
        warning = up_axis_warning(named, where)
        if warning and warning not in self.warnings:
            self.warnings.append(warning)
        return Geometry(
            "mesh",
            mesh_path=sim_path,
            mesh_scale=(scale[0] * unit, scale[1] * unit, scale[2] * unit),
            mesh_source=named,
            convex=convex,
        )

    def rgba(self, el: ET.Element, where: str) -> tuple[float, float, float, float] | None:
        mat = el.find("material")
        if mat is None:
            return None
        for tag in ("diffuse", "ambient"):
            text = mat.findtext(tag)
            if text and len(text.split()) in (3, 4):
                v = floats(text, len(text.split()), f"{where}/<material>/<{tag}>")
                return (v[0], v[1], v[2], v[3] if len(v) == 4 else 1.0)
        return gazebo_material(mat.findtext("script/name") or "")


def default_model_paths(model_path: Iterable[str | os.PathLike[str]], world_file: Path) -> list[Path]:
    """Model search order: given paths, ``GAZEBO_MODEL_PATH``, ``models/`` beside the world, shipped models."""
    paths = [Path(p).expanduser() for p in model_path]
    paths += [Path(p) for p in os.environ.get("GAZEBO_MODEL_PATH", "").split(os.pathsep) if p]
    paths += [world_file.parent / "models", world_file.parent, resources.model_path()]
    return paths


def world_path(name_or_path: str | os.PathLike[str]) -> Path:
    """The world file a shipped name (``room``), a ``package://pkg/worlds/x.world`` URI (found through
    ``ROS_PACKAGE_PATH``), a ``file://`` URI or a path names."""
    text = str(name_or_path).strip()
    if text.startswith(("package://", "file://")):
        try:
            return PackageIndex().resolve_uri(text, base_dir=Path.cwd()).resolve()
        except DescriptionError as exc:
            raise WorldError(f"world {text!r}: {exc}") from None
    path = Path(text).expanduser()
    if not path.exists() and not path.suffix and "/" not in text:
        return resources.world(text)  # ResourceError lists the shipped worlds
    return path.resolve()


def load_world(path: str | os.PathLike[str], *, model_path: Iterable[str | os.PathLike[str]] = ()) -> WorldModel:
    """Load a Gazebo-classic ``.world`` SDF file.

    ``model_path``: directories holding Gazebo models for ``<include><uri>model://name``; searched
    before ``GAZEBO_MODEL_PATH``, a ``models/`` directory beside the world and navlab's shipped models
    (``ground_plane``, ``sun``). Raises WorldError naming the file and element on bad input.
    """
    file = world_path(path)
    root = parse_xml(file, "world file")
    if root.tag != "sdf":
        raise WorldError(f"{file}: top element is <{root.tag}>, expected <sdf>")
    version = root.get("version", "")
    world_el = root.find("world")
    if world_el is None:
        raise WorldError(f"{file}: <sdf> has no <world> (a model file? include it from a world)")
    name = world_el.get("name") or file.stem
    where = f'{file}: <world name="{name}">'
    loader = _Loader(default_model_paths(model_path, file))
    if version not in SUPPORTED_VERSIONS:
        loader.warnings.append(f"{file}: SDF version {version!r} (navlab reads Gazebo classic 1.4-1.7)")
    world = WorldModel(name=name, source=file)
    for child in world_el:
        if child.tag == "model":
            world.models += loader.model(child, file)
        elif child.tag == "include":
            world.models += loader.include(child, file.parent, where)
        elif child.tag in ("plugin", "actor", "population"):
            loader.warnings.append(f'{where}/<{child.tag} name="{child.get("name", "")}">: not simulated; ignored')
        elif isinstance(child.tag, str) and child.tag not in _IGNORED_WORLD_TAGS:
            loader.warnings.append(f"{where}/<{child.tag}>: unknown element ignored")
    physics = [p for p in world_el.findall("physics")]
    if physics:
        chosen = next((p for p in physics if p.get("default") in ("1", "true")), physics[0])
        pw = f"{where}/<physics>"
        world.max_step_size = num(chosen, "max_step_size", pw, 0.001)
        if world.max_step_size <= 0:
            raise WorldError(f"{pw}/<max_step_size>: must be > 0 s, got {world.max_step_size}")
        if chosen.find("gravity") is not None:  # SDF 1.4
            world.gravity = vec3(chosen.findtext("gravity"), pw + "/<gravity>")
    if world_el.find("gravity") is not None:
        world.gravity = vec3(world_el.findtext("gravity"), f"{where}/<gravity>")
    dup = {n for n, k in collections.Counter(m.name for m in world.models).items() if k > 1}  # linear: BARN worlds
    if dup:
        raise WorldError(f"{where}: duplicate model names {sorted(dup)}")
    state = world_el.find("state")
    if state is not None:  # a saved world: the state's model poses win
        by_name = {m.name: m for m in world.models}
        for m in state.findall("model"):
            sw = f'{where}/<state>/<model name="{m.get("name")}">'
            if m.get("name") in by_name and m.find("pose") is not None:
                by_name[m.get("name", "")].pose = pose_of(m, sw)
            scale = m.findtext("scale")
            if m.get("name") in by_name and scale and floats(scale, 3, sw + "/<scale>") != (1.0, 1.0, 1.0):
                world.warnings.append(
                    f"{sw}/<scale>: {scale.strip()} is not applied; the model keeps the "
                    "sizes in its <geometry> (resize it there)"
                )
    world.ground_plane = loader.ground_plane
    world.warnings = loader.warnings + world.warnings
    if not world.ground_plane:
        world.warnings.append(f"{file}: no ground plane (include model://ground_plane); things will fall")
    return world


def load_model(path: str | os.PathLike[str], *, model_path: Iterable[str | os.PathLike[str]] = ()) -> ModelSpec:
    """Load one SDF model: a ``model.sdf`` file, a Gazebo model directory (with ``model.config``) or
    a ``model://name`` URI found through the model path (for spawning at run time).

    The model keeps the pose written in its file; callers place it. Raises WorldError naming the file.
    """
    text = str(path)
    base = Path.cwd()
    loader = _Loader(default_model_paths(model_path, base / "_"))
    where = f"model {text!r}"
    target = loader.find_model_dir(text, base, where) if text.startswith("model://") else Path(text).expanduser()
    if not target.exists():
        raise WorldError(f"{target}: SDF model file or directory not found")
    sdf_file = loader.model_sdf_file(target.resolve(), where)
    root = parse_xml(sdf_file, "model SDF")
    model_el = root.find("model") if root.tag == "sdf" else (root if root.tag == "model" else None)
    if model_el is None:
        world_el = root.find("world")
        model_el = world_el.find("model") if world_el is not None else None
    if model_el is None:
        raise WorldError(f"{sdf_file}: no <model> element (expected <sdf><model name=...>)")
    models = loader.model(model_el, sdf_file)
    if not models:
        raise WorldError(f'{sdf_file}: <model name="{model_el.get("name")}"> has no links with shapes')
    models[0].warnings = loader.warnings
    return models[0]
