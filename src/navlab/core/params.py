"""ROS-layout parameter files.

Two layouts are read:

- ROS 1 private-parameter files (``rosparam load``), as the move_base family ships them: a mapping
  of parameter names, possibly nested in namespaces (``TrajectoryPlannerROS: {max_vel_x: 0.5}``).
- Nav2's ``node_name: {ros__parameters: {...}}``; ``load_params(path, node="amcl")`` picks one node.
"""

from __future__ import annotations

import difflib
from dataclasses import fields, is_dataclass
from pathlib import Path
from typing import Any, TypeVar

import yaml

from navlab.core.errors import ParameterError

T = TypeVar("T")


def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file; a syntax error names the file, line and column."""
    p = Path(path)
    try:
        text = p.read_text()
    except OSError as exc:
        raise ParameterError(f"{p}: cannot read ({exc.strerror})") from None
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f":{mark.line + 1}:{mark.column + 1}" if mark else ""
        raise ParameterError(f"{p}{where}: malformed YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise ParameterError(f"{p}: malformed YAML: {exc}") from None


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

    An unknown name raises ``error``: "unknown WHAT parameter 'key'; did you mean 'closest'?".
    """
    if not is_dataclass(cls):
        raise TypeError(f"dataclass_from_dict needs a dataclass, got {cls!r}")
    names = [f.name for f in fields(cls)]
    out = cls()
    for key, val in (values or {}).items():
        if key not in names:
            close = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise error(f"unknown {what} parameter '{key}'{hint}")
        setattr(out, key, type(getattr(out, key))(val))
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
