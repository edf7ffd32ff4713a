"""Meshes: check and prepare STL/OBJ/DAE files for the simulator, read their triangles.

MuJoCo reads STL and OBJ only, so a COLLADA ``.dae`` file is converted once to an OBJ in a cache
directory (``$NAVLAB_CACHE`` or ``~/.cache/navlab``, under ``meshes/``). The COLLADA node transforms
are applied to the vertices; the ``<unit meter=...>`` scale is returned so callers fold it into the
mesh scale (the model's ``mesh_scale`` then includes it). ``<up_axis>`` is ignored, as Gazebo classic
ignores it (TurtleBot3's world meshes declare ``Y_UP`` but are modelled Z-up);
:func:`collada_up_axis` lets ``navlab check`` warn about files that declare another axis than Z.
"""

from __future__ import annotations

import hashlib
import os
import struct
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from navlab.description.errors import DescriptionError, NotFoundError
from navlab.io import IoError, check_regular_file, read_bytes_checked, write_text_atomic

MESH_SUFFIXES = (".stl", ".obj", ".dae")
_DAE_VERSION = "2"  # bump when the conversion changes (v2: <up_axis> ignored, as in Gazebo classic)


def cache_dir() -> Path:
    """Directory for converted meshes: ``$NAVLAB_CACHE/meshes`` or ``~/.cache/navlab/meshes``, falling
    back to the system temporary directory when that is not writable."""
    base = os.environ.get("NAVLAB_CACHE") or Path.home() / ".cache" / "navlab"
    d = Path(base) / "meshes"
    try:
        d.mkdir(parents=True, exist_ok=True)
        if os.access(d, os.W_OK):
            return d
    except OSError:
        pass
    return Path(tempfile.gettempdir()) / f"navlab-{os.getuid()}" / "meshes"


# ---------------------------------------------------------------------------------------- reading
MAX_MESH_BYTES = 256 << 20  # the largest mesh file navlab reads


def read_stl(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) and triangle indices (m, 3) of a binary or ASCII STL file."""
    try:
        data = read_bytes_checked(path, what="STL mesh", max_bytes=MAX_MESH_BYTES)
    except IoError as exc:
        raise DescriptionError(str(exc)) from None
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * count == len(data):
            rec = np.frombuffer(
                data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=count, offset=84
            )
            verts = rec["v"].reshape(-1, 3).astype(float)
            return verts, np.arange(len(verts)).reshape(-1, 3)
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().startswith("solid"):
        raise DescriptionError(f"{path}: not a binary or ASCII STL file")
    coords = [line.split()[1:4] for line in text.splitlines() if line.strip().startswith("vertex")]
    try:
        verts = np.array(coords, dtype=float).reshape(-1, 3)
    except ValueError:
        raise DescriptionError(f"{path}: malformed ASCII STL 'vertex' line") from None
    if len(verts) % 3:
        raise DescriptionError(f"{path}: ASCII STL has {len(verts)} vertices, not a multiple of 3")
    return verts, np.arange(len(verts)).reshape(-1, 3)


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles (polygons fan-triangulated) of a Wavefront OBJ file."""
    verts: list[list[float]] = []
    faces: list[list[int]] = []
    for lineno, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        try:
            if parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
        except ValueError:
            raise DescriptionError(f"{path}:{lineno}: malformed OBJ line {line.strip()!r}") from None
    return np.array(verts, dtype=float).reshape(-1, 3), np.array(faces, dtype=int).reshape(-1, 3)


def read_mesh(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of an STL, OBJ or DAE file (DAE: with node transforms, in its own units)."""
    try:
        check_regular_file(path, what="mesh file")
    except IoError as exc:
        raise DescriptionError(str(exc)) from None
    suffix = path.suffix.lower()
    if suffix == ".stl":
        return read_stl(path)
    if suffix == ".obj":
        return read_obj(path)
    if suffix == ".dae":
        verts, faces, _ = read_dae(path)
        return verts, faces
    raise DescriptionError(f"{path}: unsupported mesh type {suffix!r} (expected .stl, .obj or .dae)")


# ---------------------------------------------------------------------------------------- COLLADA
def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _children(elem: ET.Element, name: str) -> list[ET.Element]:
    return [c for c in elem if _local(c.tag) == name]


def _child(elem: ET.Element, name: str) -> ET.Element | None:
    found = _children(elem, name)
    return found[0] if found else None


def _floats(elem: ET.Element | None) -> np.ndarray:
    return np.array((elem.text or "").split() if elem is not None else [], dtype=float)


def _rotation(axis: np.ndarray, angle_deg: float) -> np.ndarray:
    """4x4 homogeneous rotation about ``axis`` by ``angle_deg`` degrees (Rodrigues)."""
    a = axis / (np.linalg.norm(axis) or 1.0)
    t = np.radians(angle_deg)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * (k @ k)
    return m


def _node_matrix(node: ET.Element) -> np.ndarray:
    """The node's local transform: its <matrix>/<translate>/<rotate>/<scale> children in order."""
    m = np.eye(4)
    for c in node:
        name = _local(c.tag)
        v = _floats(c) if name in ("matrix", "translate", "rotate", "scale") else None
        if name == "matrix" and v is not None and v.size == 16:
            m = m @ v.reshape(4, 4)
        elif name == "translate" and v is not None and v.size == 3:
            t = np.eye(4)
            t[:3, 3] = v
            m = m @ t
        elif name == "rotate" and v is not None and v.size == 4:
            m = m @ _rotation(v[:3], v[3])
        elif name == "scale" and v is not None and v.size == 3:
            m = m @ np.diag([*v, 1.0])
    return m


def _geometry_triangles(geom: ET.Element, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Positions and triangles of one <geometry><mesh> (triangles, polylist, polygons)."""
    mesh = _child(geom, "mesh")
    if mesh is None:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=int)
    sources = {s.get("id"): s for s in _children(mesh, "source")}
    vertices = _child(mesh, "vertices")
    pos_id = None
    for inp in _children(vertices, "input") if vertices is not None else []:
        if inp.get("semantic") == "POSITION":
            pos_id = (inp.get("source") or "").lstrip("#")
    if pos_id not in sources:
        raise DescriptionError(f"{path}: <geometry id={geom.get('id')!r}> has no POSITION source")
    src = sources[pos_id]
    acc = next((e for e in src.iter() if _local(e.tag) == "accessor"), None)
    stride = max(int(acc.get("stride", "3")), 3) if acc is not None else 3
    positions = _floats(_child(src, "float_array"))
    positions = positions[: positions.size // stride * stride].reshape(-1, stride)[:, :3]
    faces: list[np.ndarray] = []
    for prim in mesh:
        kind = _local(prim.tag)
        if kind not in ("triangles", "polylist", "polygons"):
            continue
        inputs = _children(prim, "input")
        n_in = max(int(i.get("offset", "0")) for i in inputs) + 1 if inputs else 1
        v_off = next((int(i.get("offset", "0")) for i in inputs if i.get("semantic") == "VERTEX"), 0)
        polys: list[np.ndarray] = []
        if kind == "polygons":
            polys = [_floats(p).astype(int).reshape(-1, n_in)[:, v_off] for p in _children(prim, "p")]
        else:
            idx = np.concatenate([_floats(p).astype(int) for p in _children(prim, "p")] or [np.zeros(0, int)])
            idx = idx[: idx.size // n_in * n_in].reshape(-1, n_in)[:, v_off]
            if kind == "triangles":
                faces.append(idx[: idx.size // 3 * 3].reshape(-1, 3))
                continue
            counts = _floats(_child(prim, "vcount")).astype(int)
            starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
            polys = [idx[s : s + c] for s, c in zip(starts, counts, strict=True)]
        for poly in polys:
            if len(poly) >= 3:
                faces.append(np.stack([np.full(len(poly) - 2, poly[0]), poly[1:-1], poly[2:]], axis=1))
    tri = np.concatenate(faces) if faces else np.zeros((0, 3), dtype=int)
    if tri.size and (tri.max() >= len(positions) or tri.min() < 0):
        raise DescriptionError(f"{path}: <geometry id={geom.get('id')!r}> indexes a vertex out of range")
    return positions, tri


def collada_up_axis(path: Path) -> str | None:
    """The ``<asset><up_axis>`` a COLLADA file declares (``Y_UP``...), None if it declares none or is
    unreadable. Gazebo classic, and navlab, do not rotate by it."""
    try:
        for _event, elem in ET.iterparse(path, events=("end",)):
            name = _local(elem.tag)
            if name == "up_axis":
                return (elem.text or "").strip() or None
            if name == "asset":
                return None
    except (ET.ParseError, OSError):
        return None
    return None


def up_axis_warning(path: Path, where: str) -> str | None:
    """A warning for a COLLADA mesh that declares an up axis other than Z (None otherwise)."""
    if path.suffix.lower() != ".dae":
        return None
    up = collada_up_axis(path)
    if up is None or up.upper() == "Z_UP":
        return None
    return (
        f"{where}: mesh {path} declares <up_axis>{up}</up_axis>; Gazebo classic ignores it (and so "
        "does navlab): the vertices are used as Z-up. Re-export the mesh if it looks rotated"
    )


def read_dae(path: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """Vertices (node transforms applied, in the file's units; ``<up_axis>`` ignored as Gazebo classic
    does), triangles, and unit meters."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise DescriptionError(f"{path}: malformed COLLADA file ({exc})") from None
    asset = _child(root, "asset")
    unit = 1.0
    if asset is not None:
        u = _child(asset, "unit")
        if u is not None and u.get("meter"):
            try:
                unit = float(u.get("meter", "1"))
            except ValueError:
                raise DescriptionError(f"{path}: <unit meter={u.get('meter')!r}>: expected a number") from None
    geoms = {g.get("id"): g for lib in _children(root, "library_geometries") for g in _children(lib, "geometry")}
    lib_nodes = {n.get("id"): n for lib in _children(root, "library_nodes") for n in _children(lib, "node")}
    scenes = {
        s.get("id"): s for lib in _children(root, "library_visual_scenes") for s in _children(lib, "visual_scene")
    }
    instances: list[tuple[str | None, np.ndarray]] = []  # (geometry id, node_T_geometry)

    def visit(node: ET.Element, parent: np.ndarray, depth: int) -> None:
        if depth > 64:
            raise DescriptionError(f"{path}: COLLADA node hierarchy too deep (a cycle in <instance_node>?)")
        m = parent @ _node_matrix(node)
        for c in node:
            name = _local(c.tag)
            if name == "instance_geometry":
                instances.append(((c.get("url") or "").lstrip("#"), m))
            elif name == "instance_node" and (c.get("url") or "").lstrip("#") in lib_nodes:
                visit(lib_nodes[(c.get("url") or "").lstrip("#")], m, depth + 1)
            elif name == "node":
                visit(c, m, depth + 1)

    scene_el = _child(root, "scene")
    inst = _child(scene_el, "instance_visual_scene") if scene_el is not None else None
    scene = scenes.get((inst.get("url") or "").lstrip("#")) if inst is not None else None
    if scene is None and scenes:
        scene = next(iter(scenes.values()))
    if scene is not None:
        for node in _children(scene, "node"):
            visit(node, np.eye(4), 0)
    else:
        instances = [(gid, np.eye(4)) for gid in geoms]
    all_v, all_f, offset = [], [], 0
    for gid, m in instances:
        if gid not in geoms:
            raise DescriptionError(f"{path}: <instance_geometry url='#{gid}'> names no <geometry>")
        v, f = _geometry_triangles(geoms[gid], path)
        v = v @ m[:3, :3].T + m[:3, 3]
        all_v.append(v)
        all_f.append(f + offset)
        offset += len(v)
    verts = np.concatenate(all_v) if all_v else np.zeros((0, 3))
    faces = np.concatenate(all_f) if all_f else np.zeros((0, 3), dtype=int)
    if len(faces) == 0:
        raise DescriptionError(f"{path}: COLLADA file has no triangles")
    return verts, faces, unit


def dae_to_obj(path: Path) -> tuple[Path, float]:
    """Convert a COLLADA file to a cached OBJ (converted once per file version); return it and unit meters."""
    stat = path.stat()
    key = hashlib.sha1(f"{_DAE_VERSION}|{path.resolve()}|{stat.st_mtime_ns}|{stat.st_size}".encode()).hexdigest()[:16]
    verts, faces, unit = read_dae(path)
    out = cache_dir() / f"{path.stem}-{key}.obj"
    if not out.exists():
        lines = [f"# converted by navlab from {path}"]
        lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in verts]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
        write_text_atomic(out, "\n".join(lines) + "\n")
    return out, unit


def prepare_mesh(path: Path, where: str) -> tuple[Path, float]:
    """Check a mesh file and make it simulator-readable; return its path and a unit scale factor.

    ``where`` names the file and element for errors. DAE files come back as a cached OBJ with the
    COLLADA unit as the factor; STL/OBJ come back unchanged with factor 1.
    """
    if not path.is_file():
        raise NotFoundError(f"{where}: mesh file {path} not found")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise DescriptionError(f"{where}: mesh {path} has unsupported type {suffix!r} (expected .stl/.obj/.dae)")
    if suffix == ".dae":
        try:
            return dae_to_obj(path)
        except DescriptionError as exc:
            raise DescriptionError(f"{where}: {exc}") from None
    return path, 1.0


def is_convex(verts: np.ndarray, faces: np.ndarray | None = None, *, rel_tol: float = 1e-3) -> bool:
    """True if the mesh is its own convex hull (so a convex collision shape is exact).

    Closed meshes (every edge shared by two triangles): the enclosed volume equals the hull's volume
    within ``rel_tol``. Open meshes: every vertex lies on one side of every face plane. Without
    ``faces``: every vertex lies on the hull surface. Flat or degenerate meshes count as convex.
    """
    if len(verts) < 4:
        return True
    scale = float(np.ptp(verts, axis=0).max() or 1.0)
    tol = rel_tol * scale
    uverts, inverse = np.unique(np.round(verts / scale, 9), axis=0, return_inverse=True)
    uverts = uverts * scale
    from scipy.spatial import ConvexHull, QhullError  # scipy.spatial costs 0.25 s to import: only here

    try:
        hull = ConvexHull(uverts)
    except QhullError:
        return True
    if faces is None or not len(faces):
        depth = (uverts @ hull.equations[:, :3].T + hull.equations[:, 3]).max(axis=1)  # <= 0 inside
        return bool((depth >= -tol).all())
    f = inverse.reshape(-1)[faces]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    if len(counts) and (counts == 2).all():
        tri = uverts[f]
        volume = abs(float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()) / 6.0)
        return volume >= hull.volume * (1.0 - rel_tol)
    tri = uverts[f]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norms = np.linalg.norm(normals, axis=1)
    ok = norms > 1e-12 * scale * scale
    normals, origin = normals[ok] / norms[ok, None], tri[ok, 0]
    for start in range(0, len(normals), 256):
        n, o = normals[start : start + 256], origin[start : start + 256]
        d = uverts @ n.T - np.einsum("ij,ij->i", n, o)  # (V, chunk)
        if ((d.max(axis=0) > tol) & (d.min(axis=0) < -tol)).any():
            return False
    return True
