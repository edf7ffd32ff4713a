"""ROS-layout parameter files.

Two layouts are read:

- ROS 1 private-parameter files (``rosparam load``), as the move_base family ships them: a mapping
  of parameter names, possibly nested in namespaces (``TrajectoryPlannerROS: {max_vel_x: 0.5}``).
- Nav2's ``node_name: {ros__parameters: {...}}``; ``load_params(path, node="amcl")`` picks one node.
"""

from __future__ import annotations

import difflib
import math
import warnings
from dataclasses import fields, is_dataclass
from pathlib import Path
from typing import Any, TypeVar

import yaml

from navlab.core.errors import ParameterError
from navlab.errors import NavlabError
from navlab.io.errors import IoError
from navlab.io.files import read_text_checked

T = TypeVar("T")

TYPO_CUTOFF = 0.85  # difflib ratio at or above which an unknown key is taken for a misspelling of a known one


class ParameterWarning(NavlabError, UserWarning):
    """An unknown parameter key that ROS would ignore (a warning, not raised): ``key`` is its name (the launch
    names its file)."""

    def __init__(self, message: str, key: str) -> None:
        super().__init__(message)
        self.key = key


def likely_typo(key: str, known: list[str]) -> list[str]:
    """The known name ``key`` misspells, as a one-item list (empty if none): difflib ratio >= ``TYPO_CUTOFF``,
    or the same letters swapped (``lsimga``: a short name's transposition rates under the cutoff)."""
    close = difflib.get_close_matches(key, known, n=1, cutoff=TYPO_CUTOFF)
    return close or [k for k in known if len(k) == len(key) and sorted(k) == sorted(key)][:1]


def check_unknown_key(key: str, known: list[str], *, what: str, error: type[Exception]) -> None:
    """The unknown-key policy, ROS's where it is safe: a ROS node reads the parameters it knows and ignores the
    rest of its namespace, so a key of another plugin or an older release (``meter_scoring`` in a costmap file)
    only warns (``ParameterWarning``: "unknown WHAT parameter 'key' ignored"). A key within a letter or two of
    a known one (difflib ratio >= ``TYPO_CUTOFF``: ``inflation_raduis``) is a misspelling whose value ROS
    would silently drop, leaving the default in force: that raises ``error`` with "did you mean"."""
    close = likely_typo(key, known)
    if close:
        raise error(f"unknown {what} parameter '{key}'; did you mean '{close[0]}'?")
    warnings.warn(ParameterWarning(f"unknown {what} parameter '{key}' ignored (ROS ignores what it does not "
                                   "read)", key), stacklevel=3)


MAX_YAML_BYTES = 16 << 20  # a parameter, launch, route or scenario file is never this large
MAX_YAML_DEPTH = 64  # nesting levels (ROS parameter files use a handful)
MAX_YAML_NODES = 200_000  # values after aliases are expanded (an alias bomb expands to billions)


class _BoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader with bounded nesting and bounded alias expansion (``&a``/``*a``, ``<<: *a``)."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self._depth >= MAX_YAML_DEPTH:
            mark = self.peek_event().start_mark
            raise yaml.composer.ComposerError(None, None, f"nested deeper than {MAX_YAML_DEPTH} levels", mark)
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def get_single_node(self) -> Any:
        node = super().get_single_node()
        if node is not None:
            sizes: dict[int, int] = {}

            def size(n: Any) -> int:  # values the document expands to, each shared node counted per use
                if id(n) not in sizes:
                    sizes[id(n)] = 1  # a recursive alias counts once instead of looping
                    if isinstance(n, yaml.SequenceNode):
                        sizes[id(n)] = 1 + sum(size(c) for c in n.value)
                    elif isinstance(n, yaml.MappingNode):
                        sizes[id(n)] = 1 + sum(size(k) + size(v) for k, v in n.value)
                return min(sizes[id(n)], MAX_YAML_NODES + 1)

            if size(node) > MAX_YAML_NODES:
                raise yaml.composer.ComposerError(
                    None, None, f"aliases (*name) expand to more than {MAX_YAML_NODES} values (an alias bomb?)",
                    node.start_mark)
        return node


def parse_yaml(text: str, source: str | Path) -> Any:
    """Parse YAML ``text`` read from ``source`` with bounded nesting and alias expansion.

    Errors are ``ParameterError`` naming ``source``, line and column.
    """
    try:
        loader = _BoundedLoader(text)
    except yaml.reader.ReaderError as exc:  # a control character such as NUL, before parsing starts
        line = text[: exc.position].count("\n") + 1
        col = exc.position - (text.rfind("\n", 0, exc.position) + 1) + 1
        raise ParameterError(f"{source}:{line}:{col}: malformed YAML: character #x{exc.character:04x} is not "
                             "allowed in YAML") from None
    try:
        return loader.get_single_data()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f":{mark.line + 1}:{mark.column + 1}" if mark else ""
        raise ParameterError(f"{source}{where}: malformed YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise ParameterError(f"{source}: malformed YAML: {str(exc).splitlines()[0]}") from None
    except RecursionError:
        raise ParameterError(f"{source}: malformed YAML: nested too deeply") from None
    finally:
        loader.dispose()


def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file; a syntax error names the file, line and column.

    Only regular UTF-8 files up to ``MAX_YAML_BYTES`` are read; nesting deeper than ``MAX_YAML_DEPTH``
    and aliases that expand to more than ``MAX_YAML_NODES`` values are refused.
    """
    p = Path(path)
    try:
        text = read_text_checked(p, what="YAML file", max_bytes=MAX_YAML_BYTES)
    except IoError as exc:
        raise ParameterError(str(exc)) from None
    return parse_yaml(text, p)


def is_nav2_layout(data: Any) -> bool:
    """Whether a parsed file uses Nav2's ``node: ros__parameters:`` layout."""
    return isinstance(data, dict) and any(
        isinstance(v, dict) and "ros__parameters" in v for v in data.values()
    )


def _unwrap_nav2(data: dict[str, Any]) -> dict[str, Any]:
    """Strip every ``ros__parameters`` level, keeping the nesting of node names."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key == "ros__parameters" and isinstance(value, dict):
            out.update(_unwrap_nav2(value))
        elif isinstance(value, dict):
            out[key] = _unwrap_nav2(value)
        else:
            out[key] = value
    return out


def load_params(path: str | Path, *, node: str | None = None) -> dict[str, Any]:
    """Parameters from a ROS 1 or Nav2 YAML file as a nested dict.

    For a Nav2 file, ``node`` selects that node's parameters (``/``-prefixed names and ``/**`` work);
    without ``node`` every node's parameters are returned, keyed by node name.
    """
    data = read_yaml(path)
    if data is None:
        return {}
    if not isinstance(data, dict):
        kind = type(data).__name__
        raise ParameterError(f"{path}: expected a mapping of parameter names at the top level, got {kind}")
    if not is_nav2_layout(data):
        return data
    nodes = _unwrap_nav2(data)
    if node is None:
        return nodes
    for key in (node, "/" + node.lstrip("/"), node.lstrip("/"), "/**"):
        if key in nodes:
            return dict(nodes[key])
    raise ParameterError(f"{path}: no parameters for node {node!r} (nodes in file: {', '.join(nodes)})")


def dataclass_from_dict(cls: type[T], values: dict[str, Any] | None, *, what: str, error: type[Exception]) -> T:
    """An instance of dataclass ``cls`` with ``values`` overriding its defaults, each cast to its default's type.

    An unknown name follows ``check_unknown_key``: a likely typo raises ``error`` ("unknown WHAT parameter
    'key'; did you mean 'closest'?"), any other key warns and is ignored.
    """
    if not is_dataclass(cls):
        raise TypeError(f"dataclass_from_dict needs a dataclass, got {cls!r}")
    names = [f.name for f in fields(cls)]
    out = cls()
    for key, val in (values or {}).items():
        if key not in names:
            check_unknown_key(str(key), names, what=what, error=error)
            continue
        kind = type(getattr(out, key))
        try:
            scalar = kind in (int, float, str, bool)
            if val is None or (isinstance(val, bool) and kind is not bool) or (
                    scalar and isinstance(val, dict | list)):
                raise TypeError
            cast = kind(val)
        except (TypeError, ValueError):
            raise error(f"{what} parameter '{key}': expected {kind.__name__}, got {val!r}") from None
        if isinstance(cast, float) and not math.isfinite(cast):
            raise error(f"{what} parameter '{key}': expected a finite number, got {val!r}")
        setattr(out, key, cast)
    return out


def merge_params(*layers: dict[str, Any]) -> dict[str, Any]:
    """Deep-merge parameter dicts; later layers win."""
    out: dict[str, Any] = {}
    for layer in layers:
        for key, value in layer.items():
            if isinstance(value, dict) and isinstance(out.get(key), dict):
                out[key] = merge_params(out[key], value)
            else:
                out[key] = value
    return out
