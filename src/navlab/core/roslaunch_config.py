"""What roslaunch builds from launch files before it starts anything (:class:`RosConfig`: the parameter
server's contents and the nodes), and the value rules of its XML (booleans, ``type=`` conversion,
namespaces). Read by :mod:`navlab.core.roslaunch`."""

from __future__ import annotations

import importlib
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.core.errors import LaunchError, ParameterError
from navlab.core.params import parse_yaml
from navlab.io import IoError, read_text_checked

#: ``$(find PKG)``: a function ``(package) -> directory`` (ROS_PACKAGE_PATH, then navlab's shipped
#: packages), and xacro's expansion ``(file, {arg: value}) -> URDF text``; strings, so core does not
#: import the description layer
FIND_PACKAGE = "navlab.description.packages:find_package"
XACRO_TEXT = "navlab.description.loader:xacro_text"

MAX_LAUNCH_BYTES = 4 << 20
#: what ``$(eval ...)`` may call besides a launch format's own functions (both launch formats)
EVAL_BUILTINS: dict[str, Callable[..., Any]] = {
    f.__name__: f for f in (int, float, str, bool, abs, min, max, round, len)
}


def call(target: str, *args: Any) -> Any:
    """Call a ``module:function`` named by a registry string."""
    module, func = target.split(":", 1)
    return getattr(importlib.import_module(module), func)(*args)


def ns_join(ns: str, name: str) -> str:
    """roslaunch's ``ns_join``: ``name`` under namespace ``ns`` (absolute names stay; ``~`` kept)."""
    if name.startswith(("/", "~")):
        return name
    return ns.rstrip("/") + "/" + name if name else ns


@dataclass
class RosNode:
    """A ``<node>`` as roslaunch holds it (names absolute)."""

    pkg: str
    type: str
    name: str
    namespace: str  # absolute, ends with "/"
    args: str = ""
    remaps: list[tuple[str, str]] = field(default_factory=list)
    env: dict[str, str] = field(default_factory=dict)
    respawn: bool = False
    respawn_delay: float = 0.0
    required: bool = False
    output: str = "log"
    cwd: str = ""
    launch_prefix: str = ""
    where: str = ""  # "FILE: <node name=...>"

    @property
    def fqn(self) -> str:
        """The node's absolute name (``/ns/name``)."""
        return self.namespace + self.name


@dataclass
class RosConfig:
    """What a set of launch files asks for: parameters, nodes, and what was skipped."""

    params: dict[str, Any] = field(default_factory=dict)  # absolute name -> value (leaves)
    param_origin: dict[str, str] = field(default_factory=dict)  # absolute name -> file it came from
    sources: dict[str, tuple[Path, dict[str, str]]] = field(default_factory=dict)  # param -> xacro/urdf file
    nodes: list[RosNode] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    declared: set[str] = field(default_factory=set)  # args the top-level files declare
    allow_commands: bool = False  # command= other than xacro runs only with the ROS bridge on

    def set_param(self, name: str, value: Any, origin: str) -> None:
        """Set ``name`` (absolute); a dict sets each leaf below it, as ``rosparam load`` does."""
        if isinstance(value, dict) and value:
            for key, sub in value.items():
                self.set_param(ns_join(name + "/", str(key)), sub, origin)
            return
        prefix = name.rstrip("/") + "/"
        for key in [k for k in self.params if k.startswith(prefix)]:  # a value replaces a namespace
            del self.params[key]
        self.params[name.rstrip("/") or "/"] = value
        self.param_origin[name] = origin

    def delete_param(self, name: str) -> None:
        """``rosparam delete``: the name and everything below it."""
        prefix = name.rstrip("/") + "/"
        for key in [k for k in self.params if k == name.rstrip("/") or k.startswith(prefix)]:
            del self.params[key]

    def files_under(self, ns: str) -> dict[str, set[str]]:
        """The files that set the parameters below ``ns``: file name -> the key names (leaves) it set."""
        prefix = ns.rstrip("/") + "/"
        out: dict[str, set[str]] = {}
        for key, origin in self.param_origin.items():
            if key.startswith(prefix) and key in self.params:
                out.setdefault(Path(origin).name, set()).add(key.rsplit("/", 1)[-1])
        return out

    def params_under(self, ns: str) -> dict[str, Any]:
        """The parameters below namespace ``ns`` (``/move_base``) as a nested dict."""
        prefix = ns.rstrip("/") + "/"
        out: dict[str, Any] = {}
        for key, value in self.params.items():
            if key.startswith(prefix):
                *parents, leaf = key[len(prefix) :].split("/")
                here = out
                for part in parents:
                    here = here.setdefault(part, {})
                here[leaf] = value
        return out


def name_attr(el: ET.Element) -> str:
    for key in ("name", "file", "ns"):
        if el.get(key):
            return f' {key}="{el.get(key)}"'
    return ""


def push_ns(ns: str, sub: str) -> str:
    """Namespace ``sub`` (relative or absolute) inside ``ns``; always ends with ``/``."""
    full = sub if sub.startswith("/") else ns.rstrip("/") + "/" + sub
    return "/" + "/".join(p for p in full.split("/") if p) + "/" if full.strip("/") else "/"


def boolean(value: str, where: str) -> bool:
    low = value.strip().lower()
    if low in ("true", "1"):
        return True
    if low in ("false", "0"):
        return False
    raise LaunchError(f"{where}: {value!r} is not a boolean (expected true/false or 1/0)")


def number(value: str | None, where: str) -> float:
    try:
        return float(value or 0)
    except ValueError:
        raise LaunchError(f"{where}: expected a number, got {value!r}") from None


def convert_value(value: str, kind: str, where: str) -> Any:
    """roslaunch's ``convert_value``: ``auto`` tries int, float, then true/false; else the text."""
    if kind == "auto":
        for cast in (int, float):
            try:
                return cast(value)
            except ValueError:
                pass
        low = value.strip().lower()
        return low == "true" if low in ("true", "false") else value
    if kind in ("str", "string"):
        return value
    if kind == "int":
        try:
            return int(value)
        except ValueError:
            raise LaunchError(f"{where}: {value!r} is not an int") from None
    if kind == "double":
        return number(value, where)
    if kind in ("bool", "boolean"):
        return boolean(value, where)
    if kind == "yaml":
        try:
            return parse_yaml(value, where)
        except ParameterError as exc:
            raise LaunchError(str(exc)) from None
    raise LaunchError(f"{where}: unknown param type {kind!r} (expected str, int, double, bool, yaml or auto)")


def read_text(path: Path, where: str) -> str:
    try:
        return read_text_checked(path, what="file", max_bytes=MAX_LAUNCH_BYTES)
    except IoError as exc:
        raise LaunchError(f"{where}: {exc}") from None


def parse_launch(file: Path) -> ET.Element:
    text = read_text(file, str(file))
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise LaunchError(f"{file}: malformed XML ({exc})") from None
    if root.tag != "launch":
        raise LaunchError(f"{file}: top element is <{root.tag}>, expected <launch>")
    return root


def declared_names(el: ET.Element) -> set[str]:
    """The args a file declares (``<arg>`` in ``<launch>`` and its groups, not those passed to includes)."""
    out: set[str] = set()
    for child in el:
        if child.tag == "arg" and child.get("name"):
            out.add(str(child.get("name")))
        elif child.tag == "group":
            out |= declared_names(child)
    return out
