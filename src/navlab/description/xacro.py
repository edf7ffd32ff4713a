"""xacro → URDF text, with ``$(find pkg)`` resolved through a :class:`PackageIndex`, in a sandbox.

Uses the xacro processor that ``xacrodoc`` ships. xacro keeps its look-up function and file stack in
module globals; they are swapped in for the duration of one expansion and restored afterwards.

A robot description is data, not code: while navlab expands one, ``${...}`` and ``$(eval ...)``
expressions are evaluated by :func:`navlab.core.safe_eval.safe_eval` (an interpreter of what xacro
documents, never Python's ``eval``) over xacro's symbols without ``python.type``/``python.vars``;
``xacro:include`` and ``xacro.load_yaml`` read only files inside the
described package (the folder with the description's ``package.xml``, else its own folder) or a
package that ``$(find pkg)`` resolved, never a file that includes itself; DOCTYPE/ENTITY declarations
are refused, and every file read is a regular UTF-8 file of bounded size.
"""

from __future__ import annotations

import contextlib
import io
import os
import xml.parsers.expat
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import xacro
from xacro import substitution_args

from navlab.core import MATH_NAMES, ExpressionError, safe_eval
from navlab.description.errors import DescriptionError
from navlab.description.packages import PackageIndex
from navlab.io import IoError, read_bytes_checked, read_text_checked

MAX_INCLUDE_DEPTH = 32
MAX_DESCRIPTION_BYTES = 16 << 20
#: builtins xacro exposes in its ``python`` namespace that a description may not have (reflection)
_REFLECTION = frozenset({"type", "vars"})


class _Sandbox:
    """xacro's global symbols without reflection, and the callables in them (the only ones an expression
    may call); ``xacro.load_yaml`` reads only regular files of bounded size."""

    def __init__(self, original: Mapping[str, Any]) -> None:
        self.original_load_yaml = xacro.load_yaml
        self.symbols: dict[str, Any] = {}
        for key, value in original.items():
            if isinstance(value, xacro.NameSpace):
                ns = xacro.NameSpace()
                dict.update(ns, {k: self.checked(v) for k, v in value.items() if k not in _REFLECTION})
                value = ns
            if key not in _REFLECTION:
                self.symbols[key] = self.checked(value)
        self.functions: dict[str, Any] = {}  # "sin", "math.sin", "xacro.load_yaml", ...
        for key, value in self.symbols.items():
            members = value.items() if isinstance(value, xacro.NameSpace) else [("", value)]
            self.functions.update({f"{key}.{k}".rstrip("."): fn for k, fn in members if callable(fn)})

    def checked(self, value: Any) -> Any:
        return self.load_yaml if value is xacro.load_yaml else value

    def load_yaml(self, filename: str) -> Any:
        read_bytes_checked(xacro.abs_filename_spec(filename), what="YAML file", max_bytes=MAX_DESCRIPTION_BYTES)
        return self.original_load_yaml(filename)

    def eval(self, expr: str, symbols: Mapping[str, Any]) -> Any:
        """xacro's ``safe_eval(expr, symbols)``, by navlab's interpreter instead of Python's ``eval``."""
        return safe_eval(expr, symbols, functions=self.functions)


class _EvalNames(Mapping[str, Any]):
    """The names of a ``$(eval ...)`` (roslaunch's): ``true``/``false``, then the args as typed values."""

    def __init__(self, args: Mapping[str, str], functions: Mapping[str, Any]) -> None:
        self.args = args
        self.functions = functions

    def __getitem__(self, key: str) -> Any:
        if key in ("true", "True", "false", "False"):
            return key in ("true", "True")
        if key in self.functions:
            raise KeyError(key)
        return substitution_args.convert_value(self.args[key], "auto")

    def __iter__(self) -> Iterator[str]:
        return iter(self.args)

    def __len__(self) -> int:
        return len(self.args)


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
            raise xacro.XacroException(
                f"{filename_spec} is outside the robot's package(s) "
                f"({', '.join(map(str, roots))}); descriptions may only read their own files"
            )
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
            raise xacro.XacroException(
                f"{filename or 'description'}: DOCTYPE/ENTITY declarations are not allowed in a robot description"
            )
        return original_parse(inp, filename)

    def eval_extension(s: str, context: dict[str, Any]) -> str:  # roslaunch's $(eval ...), by the safe interpreter
        context.setdefault("arg", {})
        functions: dict[str, Any] = {
            "arg": lambda name: substitution_args.convert_value(
                substitution_args._eval_arg(name, args=context["arg"]), "auto"
            ),
            "find": find,
            "env": substitution_args._eval_env,
            "optenv": substitution_args._eval_optenv,
            **MATH_NAMES,
            "list": list,
            "dict": dict,
            "map": map,
            "str": str,
            "float": float,
            "int": int,
        }
        return str(safe_eval(s, _EvalNames(context["arg"], functions), functions=functions))

    saved = {name: getattr(xacro, name) for name in ("safe_eval", "abs_filename_spec", "parse", "_global_symbols")}
    saved_fn = substitution_args._eval_find
    saved_dict = substitution_args._eval_dict.get("find")
    saved_eval = substitution_args._eval
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    substitution_args._eval = eval_extension
    sandbox = _Sandbox(saved["_global_symbols"])
    xacro.safe_eval = sandbox.eval
    xacro.abs_filename_spec = abs_filename_spec
    xacro.parse = parse
    xacro._global_symbols = sandbox.symbols
    try:
        yield
    finally:
        substitution_args._eval_find = saved_fn
        substitution_args._eval_dict["find"] = saved_dict
        substitution_args._eval = saved_eval
        for name, value in saved.items():
            setattr(xacro, name, value)


def _xacro_message(exc: xacro.XacroException) -> str:
    """One line: the expression error inside xacro's wrapping if there is one, else xacro's message."""
    inner: BaseException | None = exc
    while isinstance(inner, xacro.XacroException):
        inner = inner.exc
    text = str(inner if isinstance(inner, ExpressionError) else exc)
    return "; ".join(line.strip() for line in text.splitlines() if line.strip())


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
        raise DescriptionError(f"{_current_file(path)}: xacro error: {_xacro_message(exc)}") from None
    except substitution_args.ArgException as exc:
        raise DescriptionError(
            f"{_current_file(path)}: xacro error: $(arg {exc}) is not set and has no default "
            "(pass it in args / name:=value)"
        ) from None
    except Exception as exc:  # xacro raises NameError, KeyError, ... from evaluated expressions
        raise DescriptionError(f"{_current_file(path)}: xacro error: {type(exc).__name__}: {exc}") from None
    finally:
        xacro.filestack = None
        xacro.all_includes = []  # xacro's module-level include log would grow with every load
    warnings = [
        f"xacro: {line.strip()}"
        for line in stderr.getvalue().splitlines()
        if line.strip() and not line.startswith(("when processing file", "in file", "included from"))
    ]
    return text, warnings
