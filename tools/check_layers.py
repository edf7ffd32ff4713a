#!/usr/bin/env python3
"""Import-layer check for navlab (DESIGN.md, "Layers"): imports only go down or sideways, never up,
and no two packages import each other.

Layers, bottom to top::

    0 leaves       errors msgs geometry grid gridline io resources nodes plugins lazy deprecation pcg64
    1 core
    2 description world ros1
    3 sim mapping localization
    4 navigation
    5 drivers
    6 experiments viz
    7 top          cli bench (packages: the ``navlab`` command's verbs, the benchmarks), demo, navlab/__init__.py

Every import statement counts: module level, inside functions, under ``if TYPE_CHECKING``. Strings
(the lazy names of ``navlab/__init__.py``, the ``module:Class`` strings of the registries) are not
imports. Nothing below imports cli or bench: they are each package's only outside faces.

Each package's ``__init__`` is its only public entry: from outside a package, import what its ``__init__``
exports (``from navlab.io import write_text_atomic``), not its modules (``from navlab.io.files import ...``,
``from navlab.sim import decompose``). A lazy export (:func:`navlab.lazy.lazy_exports`) keeps such an import
as cheap as the deep one. ``DEEP_ALLOWED`` lists the few deep imports that start-up time still needs.

Usage: ``python tools/check_layers.py [SRC_NAVLAB_DIR]`` (default: ``src/navlab`` of this checkout).
Prints each violation as ``file:line: a -> b (why)`` and exits 1 if there is any, 0 otherwise.
"""

from __future__ import annotations

import argparse
import ast
import sys
from dataclasses import dataclass
from pathlib import Path

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "leaves",
        (
            "errors",
            "msgs",
            "geometry",
            "grid",
            "gridline",
            "io",
            "resources",
            "nodes",
            "plugins",
            "lazy",
            "deprecation",
            "pcg64",
        ),
    ),
    ("core", ("core",)),
    ("description/world/ros1", ("description", "world", "ros1")),
    ("sim/mapping/localization", ("sim", "mapping", "localization")),
    ("navigation", ("navigation",)),
    ("drivers", ("drivers",)),
    ("experiments/viz", ("experiments", "viz")),
    ("top", ("cli", "bench", "demo", "__main__")),
)
LAYER_OF: dict[str, int] = {pkg: i for i, (_, pkgs) in enumerate(LAYERS) for pkg in pkgs}
# (importing module, imported module) -> why the import may reach past the package's __init__. Only for
# laziness: where loading the package's __init__ would load what the importer must not (say why).
DEEP_ALLOWED: dict[tuple[str, str], str] = {}
TOP = len(LAYERS) - 1
ROOT = "navlab"


@dataclass(frozen=True)
class Unit:
    """A node of the layer graph: a package (``mapping``) or a top-level module (``msgs``); ``layer`` is None
    for a package that is in no layer."""

    name: str
    layer: int | None


@dataclass(frozen=True)
class Edge:
    """One import: ``source`` (dotted module name under navlab) imports ``target`` at ``path:line``."""

    path: Path
    line: int
    source: str
    target: str
    src_unit: Unit
    dst_unit: Unit


def unit_of(parts: tuple[str, ...], src: Path) -> Unit:
    """The layer-graph node of module ``navlab.<parts>``; ``parts == ()`` is navlab/__init__.py."""
    if not parts:
        return Unit(ROOT, TOP)
    head = parts[0]
    return Unit(head, LAYER_OF.get(head))


def module_parts(path: Path, src: Path) -> tuple[str, ...]:
    """``src/navlab/io/carmen.py`` -> ``("io", "carmen")``; a package ``__init__.py`` -> its package."""
    rel = path.relative_to(src).with_suffix("")
    parts = rel.parts
    if parts and parts[-1] == "__init__":
        parts = parts[:-1]
    return tuple(parts)


def _exists(src: Path, parts: tuple[str, ...]) -> bool:
    base = src.joinpath(*parts) if parts else src
    return base.is_dir() or base.with_suffix(".py").is_file()


def from_base(node: ast.ImportFrom, parts: tuple[str, ...], is_package: bool) -> tuple[str, ...] | None:
    """The module under navlab (as parts) that ``from X import ...`` names as X; None when X is not navlab's."""
    if node.level:  # relative: resolve against this module's package
        package = list(parts if is_package else parts[:-1])
        if node.level - 1 > len(package):
            return None
        return (*package[: len(package) - (node.level - 1)], *(node.module.split(".") if node.module else []))
    dotted = node.module.split(".") if node.module else []
    return tuple(dotted[1:]) if dotted and dotted[0] == ROOT else None


def imported_targets(node: ast.Import | ast.ImportFrom, parts: tuple[str, ...], is_package: bool,
                     src: Path) -> list[tuple[str, ...]]:
    """Module paths under navlab (as parts) that one import statement loads; others are dropped."""
    if isinstance(node, ast.Import):
        names = [alias.name.split(".") for alias in node.names]
        return [tuple(n[1:]) for n in names if n[0] == ROOT]
    base = from_base(node, parts, is_package)
    if base is None:
        return []
    targets = []
    for alias in node.names:
        candidate = (*base, alias.name)
        # ``from navlab import msgs`` loads the module navlab.msgs; ``from navlab.core import Node`` a name
        targets.append(candidate if alias.name != "*" and _exists(src, candidate) else tuple(base))
    return targets


def public_names(src: Path, package: str) -> set[str]:
    """Names a package's ``__init__`` offers: what it binds (imports, also under ``if TYPE_CHECKING``, defs,
    assignments) and the strings of its ``__all__``."""
    tree = ast.parse((src / package / "__init__.py").read_text(encoding="utf-8"))
    names: set[str] = set()
    body = list(tree.body)
    while body:
        node = body.pop()
        if isinstance(node, ast.If):
            body.extend(node.body + node.orelse)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(n.id for target in targets for n in ast.walk(target) if isinstance(n, ast.Name))
            if any(isinstance(n, ast.Name) and n.id == "__all__" for n in targets) and node.value is not None:
                names.update(c.value for c in ast.walk(node.value) if isinstance(c, ast.Constant))
    return names


def deep_imports(src: Path) -> list[str]:
    """``file:line: a -> b (deep: ...)`` for each import of a module inside another package (past its
    ``__init__``), but those in ``DEEP_ALLOWED``. navlab/__init__.py, the facade over every package, is exempt."""
    out = []
    exported: dict[str, set[str]] = {}
    for path in sorted(src.rglob("*.py")):
        parts = module_parts(path, src)
        if not parts:
            continue
        source = ".".join(parts)
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            is_package = path.name == "__init__.py"
            base = from_base(node, parts, is_package) if isinstance(node, ast.ImportFrom) else None
            for target in imported_targets(node, parts, is_package, src):
                package = target[0] if target else ""
                if len(target) < 2 or package == parts[0] or not (src / package / "__init__.py").is_file():
                    continue
                if base == (package,):  # ``from navlab.world import occupancy``: a name the package may export
                    if package not in exported:
                        exported[package] = public_names(src, package)
                    if target[1] in exported[package]:
                        continue
                dotted = ".".join(target)
                if (source, dotted) in DEEP_ALLOWED:
                    continue
                out.append(f"{_shown(path)}:{node.lineno}: {source} -> {dotted} (deep: import it from "
                           f"navlab.{package}, which exports it in {package}/__init__.py)")
    return sorted(set(out))


def collect_edges(src: Path) -> list[Edge]:
    """Every import from one navlab module to another, with its file and line."""
    edges = []
    for path in sorted(src.rglob("*.py")):
        parts = module_parts(path, src)
        src_unit = unit_of(parts, src)
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            for target in imported_targets(node, parts, path.name == "__init__.py", src):
                dst_unit = unit_of(target, src)
                if dst_unit.name == src_unit.name:
                    continue
                edges.append(Edge(path, node.lineno, ".".join(parts) or ROOT, ".".join(target) or ROOT,
                                  src_unit, dst_unit))
    return edges


def _shown(path: Path) -> str:
    """The path relative to the current directory when it is below it, else as given."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _layer_name(layer: int) -> str:
    return f"layer {layer} {LAYERS[layer][0]}"


def violations(src: Path) -> list[str]:
    """``file:line: a -> b (why)`` for each upward import, each import between two packages that import
    each other, each import on a longer cycle within one layer, and each package that is in no layer."""
    edges = collect_edges(src)
    out: list[tuple[str, int, str]] = []

    def report(edge: Edge, why: str) -> None:
        out.append((_shown(edge.path), edge.line, f"{edge.source} -> {edge.target} ({why})"))

    unknown_seen: set[str] = set()
    for edge in edges:
        for unit in (edge.src_unit, edge.dst_unit):
            if unit.layer is None and unit.name not in unknown_seen:
                unknown_seen.add(unit.name)
                report(edge, f"package {unit.name!r} is in no layer of DESIGN.md; add it to LAYERS in "
                             "tools/check_layers.py")
        s, d = edge.src_unit.layer, edge.dst_unit.layer
        if s is not None and d is not None and d > s:
            report(edge, f"upward: {edge.src_unit.name} is {_layer_name(s)}, "
                         f"{edge.dst_unit.name} is {_layer_name(d)}")

    graph: dict[str, set[str]] = {}
    sideways: dict[str, set[str]] = {}  # edges within one layer: a longer cycle can only run along these
    for edge in edges:
        a, b = edge.src_unit.name, edge.dst_unit.name
        graph.setdefault(a, set()).add(b)
        if edge.src_unit.layer == edge.dst_unit.layer:
            sideways.setdefault(a, set()).add(b)
    component = _components(sideways)
    for edge in edges:
        a, b = edge.src_unit.name, edge.dst_unit.name
        if a in graph.get(b, set()):
            report(edge, f"circle: {a} and {b} import each other")
        elif a in component and component[a] == component.get(b):
            cycle = ", ".join(sorted(n for n, c in component.items() if c == component[a]))
            report(edge, f"circle: import cycle among {cycle}")
    return [f"{path}:{line}: {text}" for path, line, text in sorted(set(out))] + deep_imports(src)


def _components(graph: dict[str, set[str]]) -> dict[str, int]:
    """Strongly connected components (Tarjan) with more than one node: node -> component id."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    result: dict[str, int] = {}
    counter = [0, 0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            members = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                members.append(w)
                if w == v:
                    break
            if len(members) > 1:
                for w in members:
                    result[w] = counter[1]
                counter[1] += 1

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return result


def main(argv: list[str] | None = None) -> int:
    default = Path(__file__).resolve().parent.parent / "src" / ROOT
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("src", nargs="?", type=Path, default=default,
                        help=f"the navlab package directory to check (default: {default})")
    args = parser.parse_args(argv)
    if not (args.src / "__init__.py").is_file():
        print(f"check_layers: {args.src} is not a package directory (no __init__.py)", file=sys.stderr)
        return 2
    found = violations(args.src)
    for line in found:
        print(line)
    if found:
        print(f"check_layers: {len(found)} import-layer violation(s); layers are in DESIGN.md", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
