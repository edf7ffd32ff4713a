"""xacro → URDF text, with ``$(find pkg)`` resolved through a :class:`PackageIndex`, in a sandbox.

Uses the xacro processor that ``xacrodoc`` ships. xacro keeps its look-up function and file stack in
module globals; they are swapped in for the duration of one expansion and restored afterwards.

A robot description is data, not code: while navlab expands one, ``${...}`` and ``$(eval ...)``
expressions are checked before they are evaluated (no names or attributes starting with ``_``, no
``vars``/``type``/``format``/``mro``/``open``/..., no ``__`` in strings) and see no Python builtins
beyond xacro's arithmetic helpers; ``xacro:include`` and ``xacro.load_yaml`` read only files inside the
described package (the folder with the description's ``package.xml``, else its own folder) or a
package that ``$(find pkg)`` resolved, never a file that includes itself; DOCTYPE/ENTITY declarations
are refused, and every file read is a regular UTF-8 file of bounded size.
"""

from __future__ import annotations

import ast
import contextlib
import io
import os
import xml.parsers.expat
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import xacro
from xacro import substitution_args

from navlab.description.errors import DescriptionError
from navlab.description.packages import PackageIndex
from navlab.io.errors import IoError
from navlab.io.files import read_text_checked

#: names an expression may not use, as a name, an attribute or a string (reflection, I/O, evaluation)
_BLOCKED = frozenset({"vars", "type", "format", "format_map", "mro", "getattr", "setattr", "delattr", "eval", "exec",
                      "compile", "open", "globals", "locals", "breakpoint", "input", "memoryview", "object", "super",
                      "dir", "help", "subclasses", "system", "popen"})
MAX_INCLUDE_DEPTH = 32
MAX_DESCRIPTION_BYTES = 16 << 20


def check_expression(expr: str) -> ast.Expression:
    """Parse a xacro expression and refuse what could escape the sandbox; raises ``xacro.XacroException``."""
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError:
        raise xacro.XacroException(f"invalid expression: {expr}") from None
    for node in ast.walk(tree):
        name = node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else None
        if name is not None and (name.startswith("_") or name in _BLOCKED):
            raise xacro.XacroException(f"expression ${{{expr.strip()}}} uses {name!r}, which a robot description "
                                       "may not use (descriptions are data, not code)")
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and (
                "__" in node.value or node.value in _BLOCKED):
            raise xacro.XacroException(f"expression ${{{expr.strip()}}}: the string {node.value!r} is not allowed "
                                       "in a robot description")
    return tree


def _safe_eval(expr: str, symbols: Any, local_symbols: Any = None) -> Any:
    """xacro's ``safe_eval`` with the expression checked first and no builtins."""
    code = compile(check_expression(expr), "<expression>", "eval")
    symbols.update(__builtins__={})
    return eval(code, symbols, local_symbols)


def _sandboxed_symbols(symbols: dict[str, Any]) -> dict[str, Any]:
    """A copy of xacro's global symbols without the reflective helpers (``vars``, ``type``, ...)."""
    out = {k: v for k, v in symbols.items() if k not in _BLOCKED}
    for key, value in out.items():
        if isinstance(value, xacro.NameSpace) and any(k in _BLOCKED for k in value):
            ns = xacro.NameSpace()
            dict.update(ns, {k: v for k, v in value.items() if k not in _BLOCKED})
            out[key] = ns
    return out


def _package_root(path: Path) -> Path:
    """The folder holding ``package.xml`` above ``path``, else ``path``'s own folder."""
    for folder in path.resolve().parents:
        if (folder / "package.xml").is_file():
            return folder
    return path.resolve().parent


def _inside(path: Path, roots: list[Path]) -> bool:
    return any(path == r or r in path.parents for r in roots)


@contextlib.contextmanager
def _find_through(index: PackageIndex, top: Path) -> Iterator[None]:
    """Make xacro's ``$(find pkg)`` and ``${find('pkg')}`` use ``index``, and sandbox xacro, while the block runs."""
    roots = [_package_root(top)]
    original_abs = xacro.abs_filename_spec
    original_parse = xacro.parse

    def find(pkg: str) -> str:
        found = index.find(pkg)
        roots.append(found.resolve())
        return str(found)

    def abs_filename_spec(filename_spec: str) -> str:
        name = original_abs(filename_spec)
        real = Path(os.path.realpath(name))
        if not _inside(real, roots):
            raise xacro.XacroException(f"{filename_spec} is outside the robot's package(s) "
                                       f"({', '.join(map(str, roots))}); descriptions may only read their own files")
        stack = [Path(os.path.realpath(f)) for f in (xacro.filestack or []) if f]
        if real in stack:
            raise xacro.XacroException(f"{filename_spec} includes itself (include loop)")
        if len(stack) >= MAX_INCLUDE_DEPTH:
            raise xacro.XacroException(f"includes nest deeper than {MAX_INCLUDE_DEPTH} files")
        return name

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            try:
                inp = read_text_checked(filename, what="robot description", max_bytes=MAX_DESCRIPTION_BYTES)
            except IoError as exc:
                raise xacro.XacroException(str(exc)) from None
        if isinstance(inp, str) and ("<!DOCTYPE" in inp or "<!ENTITY" in inp):
            raise xacro.XacroException(f"{filename or 'description'}: DOCTYPE/ENTITY declarations are not allowed "
                                       "in a robot description")
        return original_parse(inp, filename)

    def eval_extension(s: str, context: dict[str, Any]) -> str:  # $(eval ...) without builtins
        context.setdefault("arg", {})
        functions = {"arg": lambda name: substitution_args.convert_value(
            substitution_args._eval_arg(name, args=context["arg"]), "auto"), "find": find}
        functions.update({k: v for k, v in substitution_args._eval_dict.items() if not k.startswith("_")})
        code = compile(check_expression(s), "<eval>", "eval")
        return str(eval(code, {"__builtins__": {}}, substitution_args._DictWrapper(context["arg"], functions)))

    saved = {name: getattr(xacro, name) for name in ("safe_eval", "abs_filename_spec", "parse", "_global_symbols")}
    saved_fn = substitution_args._eval_find
    saved_dict = substitution_args._eval_dict.get("find")
    saved_eval = substitution_args._eval
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    substitution_args._eval = eval_extension
    xacro.safe_eval = _safe_eval
    xacro.abs_filename_spec = abs_filename_spec
    xacro.parse = parse
    xacro._global_symbols = _sandboxed_symbols(saved["_global_symbols"])
    try:
        yield
    finally:
        substitution_args._eval_find = saved_fn
        substitution_args._eval_dict["find"] = saved_dict
        substitution_args._eval = saved_eval
        for name, value in saved.items():
            setattr(xacro, name, value)


def _current_file(default: Path) -> str:
    """The file xacro was reading when it failed (its file stack), else ``default``."""
    stack = [f for f in (xacro.filestack or []) if f]
    return str(stack[-1]) if stack else str(default)


def expand(path: Path, index: PackageIndex, args: Mapping[str, str] | None = None) -> tuple[str, list[str]]:
    """Expand the xacro (or plain URDF) file ``path``; return the URDF text and xacro's warnings.

    ``args`` are ``<xacro:arg>`` values (``name:=value`` on the ROS command line). Errors become a
    DescriptionError naming the file being read and xacro's message.
    """
    path = Path(path)
    if path.is_dir():
        raise DescriptionError(f"{path}: is a directory; expected a .xacro or .urdf file")
    if not path.is_file():
        raise DescriptionError(f"{path}: robot description file not found")
    mappings = {str(k): str(v) for k, v in (args or {}).items()}
    stderr = io.StringIO()
    try:
        with _find_through(index, path), contextlib.redirect_stderr(stderr):
            doc = xacro.process_file(str(path), mappings=mappings)
            text = doc.toprettyxml(indent="  ")
    except DescriptionError as exc:
        raise DescriptionError(f"{_current_file(path)}: {exc}") from None
    except xml.parsers.expat.ExpatError as exc:
        raise DescriptionError(f"{_current_file(path)}: malformed XML: {exc}") from None
    except xacro.XacroException as exc:
        raise DescriptionError(f"{_current_file(path)}: xacro error: {exc}") from None
    except substitution_args.ArgException as exc:
        raise DescriptionError(
            f"{_current_file(path)}: xacro error: $(arg {exc}) is not set and has no default "
            "(pass it in args / name:=value)"
        ) from None
    except Exception as exc:  # xacro raises NameError, KeyError, ... from evaluated expressions
        raise DescriptionError(
            f"{_current_file(path)}: xacro error: {type(exc).__name__}: {exc}"
        ) from None
    finally:
        xacro.filestack = None
        xacro.all_includes = []  # xacro's module-level include log would grow with every load
    warnings = [
        f"xacro: {line.strip()}"
        for line in stderr.getvalue().splitlines()
        if line.strip() and not line.startswith(("when processing file", "in file", "included from"))
    ]
    return text, warnings
