"""ROS 1 XML launch files (``.launch``) read with roslaunch's semantics, into a :class:`RosConfig`.

What roslaunch builds before it starts anything: the parameter server's contents (absolute names,
dicts flattened to their leaves, as ``rosparam load`` sets them) and the nodes with their
namespace, remappings, arguments and environment. :mod:`navlab.core.roslaunch_nodes` turns the
nodes navlab knows into :class:`navlab.core.launch.NodeSpec` (the one runtime description every
launch format ends in) and the others into processes.

Tags: ``<launch> <arg> <param> <rosparam> <include> <group> <remap> <node> <env>`` (and ``<machine>``,
``<test>``, ``<master>``, which are reported and skipped); ``if``/``unless`` on each. Substitutions:
``$(find PKG) $(arg NAME) $(env VAR) $(optenv VAR [DEFAULT]) $(eval EXPR) $(dirname) $(anon NAME)``.
``$(eval)`` runs in navlab's expression sandbox (:mod:`navlab.core.safe_eval`), never Python's ``eval``.
A launch file is data: nothing runs unless a ``<node>`` or a ``command=`` names a process.
"""

from __future__ import annotations

import os
import re
import shlex
import socket
import xml.etree.ElementTree as ET
import zlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.core.errors import LaunchError, ParameterError
from navlab.core.params import parse_yaml
from navlab.core.roslaunch_config import (
    EVAL_BUILTINS,
    FIND_PACKAGE,
    XACRO_TEXT,
    RosConfig,
    RosNode,
    boolean,
    call,
    convert_value,
    declared_names,
    name_attr,
    ns_join,
    number,
    parse_launch,
    push_ns,
    read_text,
)
from navlab.errors import did_you_mean

__all__ = ["FIND_PACKAGE", "RosConfig", "RosNode", "call", "declared_args", "is_xml_launch", "load", "ns_join"]

_SUB = re.compile(r"\$\(([a-z]+)((?:\s+[^()]*)?)\)")
_IGNORED_TAGS = ("machine", "test", "master")
MAX_INCLUDE_DEPTH = 20


@dataclass
class _Scope:
    """What a tag sees: its file, the file's args, the namespace, and the remaps/env set around it."""

    file: Path
    args: dict[str, str]
    ns: str = "/"
    remaps: list[tuple[str, str]] = field(default_factory=list)
    env: dict[str, str] = field(default_factory=dict)
    node: str = ""  # inside <node>: its absolute name, for ~private names
    unset: set[str] = field(default_factory=set)  # args declared without a value: an error when used

    def child(self, **changes: Any) -> _Scope:
        """A nested scope (group, node, include): the same args; remaps and env copied."""
        return _Scope(
            self.file,
            self.args,
            changes.get("ns", self.ns),
            list(self.remaps),
            dict(changes.get("env", self.env)),
            changes.get("node", self.node),
            self.unset,
        )


class _Loader:
    """Reads launch files into one :class:`RosConfig`."""

    def __init__(self, config: RosConfig, anon_seed: int) -> None:
        self.config = config
        self.anon: dict[str, str] = {}
        self.anon_seed = anon_seed

    # --- substitution args ----------------------------------------------------------------------

    def find(self, pkg: str, where: str) -> str:
        try:
            return str(call(FIND_PACKAGE, pkg))
        except Exception as exc:  # the description layer's NotFound / DescriptionError
            raise LaunchError(f"{where}: $(find {pkg}): {exc}") from None

    def anon_name(self, name: str) -> str:
        """``$(anon NAME)``: a name unique to this launch, the same for each use of NAME in it."""
        if name not in self.anon:
            tag = zlib.crc32(f"{self.anon_seed}:{name}".encode()) % 10**9
            host = re.sub(r"\W", "_", socket.gethostname())
            self.anon[name] = f"{name}_{host}_{os.getpid()}_{tag}"
        return self.anon[name]

    def functions(self, scope: _Scope, where: str) -> dict[str, Callable[..., str]]:
        def arg(name: str) -> str:
            if name in scope.unset:
                raise LaunchError(f"{where}: arg {name!r} is not set; pass {name}:=VALUE")
            if name not in scope.args:
                raise LaunchError(f"{where}: arg {name!r} is not defined")
            return scope.args[name]

        def env(name: str) -> str:
            if name not in os.environ:
                raise LaunchError(f"{where}: environment variable {name!r} is not set")
            return os.environ[name]

        return {
            "arg": arg,
            "env": env,
            "optenv": lambda name, default="": os.environ.get(name) or default,
            "find": lambda pkg: self.find(pkg, where),
            "anon": self.anon_name,
            "dirname": lambda: str(scope.file.parent),
        }

    def subst(self, text: str, scope: _Scope, where: str) -> str:
        """Resolve every ``$(...)`` in ``text`` as roslaunch's ``resolve_args`` does."""
        if "$(" not in text:
            return text
        stripped = text.strip()
        if stripped.startswith("$(eval ") and stripped.endswith(")"):
            return self.eval(stripped[len("$(eval ") : -1], scope, where)
        if "$(eval " in text:
            raise LaunchError(f"{where}: $(eval ...) must be the whole attribute value, got {text!r}")
        funcs = self.functions(scope, where)

        def repl(m: re.Match[str]) -> str:
            kind, words = m.group(1), m.group(2).split()
            if kind == "optenv" and words:
                return os.environ.get(words[0], " ".join(words[1:]))
            need = {"arg": 1, "env": 1, "find": 1, "anon": 1, "dirname": 0}
            if kind not in need:
                raise LaunchError(
                    f"{where}: unknown substitution $({kind}) (roslaunch has arg, env, optenv, "
                    "find, anon, dirname, eval)"
                )
            if len(words) != need[kind]:
                raise LaunchError(f"{where}: $({kind}) takes {need[kind]} argument(s), got {m.group(0)!r}")
            return str(funcs[kind](*words))

        return _SUB.sub(repl, text)

    def eval(self, expr: str, scope: _Scope, where: str) -> str:
        """``$(eval EXPR)``: args are names, ``arg()``/``env()``/``optenv()``/``find()``/``anon()``/
        ``dirname()`` and Python's ``int float str bool abs min max round len`` are functions, evaluated in
        navlab's expression sandbox (never Python's ``eval``); the result as text."""
        from navlab.core.safe_eval import ExpressionError, safe_eval

        names: dict[str, Any] = {"true": True, "false": False, "True": True, "False": False, **scope.args}
        functions: dict[str, Callable[..., Any]] = {**EVAL_BUILTINS, **self.functions(scope, where)}
        try:
            value = safe_eval(expr, names, functions=functions)
        except ExpressionError as exc:
            raise LaunchError(f"{where}: $(eval {expr}): {exc}") from None
        return str(value)

    # --- attributes -----------------------------------------------------------------------------

    def attr(
        self, el: ET.Element, key: str, scope: _Scope, where: str, *, required: bool = False, default: str | None = None
    ) -> str | None:
        raw = el.get(key)
        if raw is None:
            if required:
                raise LaunchError(f"{where}: <{el.tag}> needs a {key!r} attribute")
            return default
        return self.subst(raw, scope, where)

    def flag(self, el: ET.Element, key: str, scope: _Scope, where: str, default: bool = False) -> bool:
        value = self.attr(el, key, scope, where)
        return default if value is None else boolean(value, f"{where}: {key}")

    def active(self, el: ET.Element, scope: _Scope, where: str) -> bool:
        """roslaunch's ``if``/``unless`` (true/1, false/0, any case; both at once is an error)."""
        if "if" in el.attrib and "unless" in el.attrib:
            raise LaunchError(f"{where}: <{el.tag}> has both 'if' and 'unless'")
        if "if" in el.attrib:
            return self.flag(el, "if", scope, where)
        if "unless" in el.attrib:
            return not self.flag(el, "unless", scope, where)
        return True

    # --- files ----------------------------------------------------------------------------------

    def block(self, parent: ET.Element, scope: _Scope, given: dict[str, str], depth: int) -> None:
        """The tags of ``<launch>`` or ``<group>`` in order; ``given`` are args passed in from outside."""
        for el in parent:
            if not isinstance(el.tag, str):  # a comment
                continue
            where = f"{scope.file}: <{el.tag}{name_attr(el)}>"
            if el.tag == "arg":  # arg's if/unless are read with the args set so far
                if self.active(el, scope, where):
                    self.arg(el, scope, given, where)
                continue
            if not self.active(el, scope, where):
                continue
            if el.tag == "group":
                ns = self.attr(el, "ns", scope, where)
                inner = scope.child(ns=push_ns(scope.ns, ns) if ns else scope.ns)
                if self.flag(el, "clear_params", scope, where) and ns:
                    self.config.delete_param(inner.ns)
                self.block(el, inner, given, depth)  # args are file-wide, even inside a group (shared dict)
            elif self.common(el, scope, where, scope.remaps, scope.env):
                pass
            elif el.tag == "include":
                self.include(el, scope, where, depth)
            elif el.tag == "node":
                self.node(el, scope, where)
            elif el.tag in _IGNORED_TAGS:
                self.config.notes.append(f"{where}: <{el.tag}> is not used by navlab (skipped)")
            else:
                hint = did_you_mean(
                    el.tag,
                    ["arg", "param", "rosparam", "include", "group", "remap", "node", "env", "machine", "test"],
                    template="; did you mean <{}>?",
                )
                raise LaunchError(f"{where}: unknown tag <{el.tag}>{hint}")

    def children(self, el: ET.Element, scope: _Scope, where: str) -> Iterator[tuple[ET.Element, str]]:
        """The child elements of ``el`` whose if/unless hold, each with its place for messages."""
        for child in el:
            if isinstance(child.tag, str):
                cwhere = f"{where}: <{child.tag}{name_attr(child)}>"
                if self.active(child, scope, cwhere):
                    yield child, cwhere

    def common(
        self, el: ET.Element, scope: _Scope, where: str, remaps: list[tuple[str, str]], env: dict[str, str]
    ) -> bool:
        """``<param>``, ``<rosparam>``, ``<remap>`` and ``<env>``, which launch, group and node share (remaps
        and env go to the lists given); False for any other tag."""
        if el.tag == "param":
            self.param(el, scope, where)
        elif el.tag == "rosparam":
            self.rosparam(el, scope, where)
        elif el.tag == "remap":
            remaps.append(self.remap(el, scope, where))
        elif el.tag == "env":
            env[str(self.attr(el, "name", scope, where, required=True))] = str(
                self.attr(el, "value", scope, where, required=True)
            )
        else:
            return False
        return True

    def arg(self, el: ET.Element, scope: _Scope, given: dict[str, str], where: str) -> None:
        name = el.get("name")
        if not name:
            raise LaunchError(f"{where}: <arg> needs a 'name' attribute")
        if name in scope.args or name in scope.unset:
            raise LaunchError(f"{where}: arg {name!r} has already been declared")
        if "value" in el.attrib:
            if name in given:
                raise LaunchError(
                    f"{where}: cannot override arg {name!r}, which has a fixed value= "
                    "(roslaunch: only a default= can be overridden)"
                )
            scope.args[name] = str(self.attr(el, "value", scope, where))
        elif name in given:
            scope.args[name] = given[name]
        elif "default" in el.attrib:
            scope.args[name] = str(self.attr(el, "default", scope, where))
        else:
            scope.unset.add(name)

    def remap(self, el: ET.Element, scope: _Scope, where: str) -> tuple[str, str]:
        src = self.attr(el, "from", scope, where, required=True)
        dst = self.attr(el, "to", scope, where, required=True)
        return str(src), str(dst)

    def param_name(self, name: str, scope: _Scope, where: str) -> str:
        if name.startswith("~"):
            if not scope.node:
                raise LaunchError(f"{where}: private parameter {name!r} outside a <node>")
            return ns_join(scope.node + "/", name[1:])
        return ns_join(scope.node + "/" if scope.node else scope.ns, name)

    def param(self, el: ET.Element, scope: _Scope, where: str) -> None:
        name = self.param_name(str(self.attr(el, "name", scope, where, required=True)), scope, where)
        kind = self.attr(el, "type", scope, where, default="auto") or "auto"
        sources = [k for k in ("value", "textfile", "binfile", "command") if k in el.attrib]
        if len(sources) != 1:
            raise LaunchError(
                f"{where}: <param> needs exactly one of value, textfile, binfile, command "
                f"(got {', '.join(sources) or 'none'})"
            )
        origin = str(scope.file)
        if "value" in el.attrib:
            value: Any = convert_value(str(self.attr(el, "value", scope, where)), kind, where)
        elif "textfile" in el.attrib:
            path = Path(str(self.attr(el, "textfile", scope, where)))
            value = read_text(path, where)
            self.config.sources[name] = (path, {})
        elif "binfile" in el.attrib:
            raise LaunchError(f"{where}: binfile= parameters are not supported by navlab")
        else:
            value = self.command(str(self.attr(el, "command", scope, where)), name, where)
            if kind != "auto":
                value = convert_value(value, kind, where)
        self.config.set_param(name, value, origin)

    def command(self, cmd: str, name: str, where: str) -> str:
        """``command=``: xacro runs inside navlab; any other program only with the ROS bridge on."""
        try:
            words = shlex.split(cmd)
        except ValueError as exc:
            raise LaunchError(f"{where}: command {cmd!r}: {exc}") from None
        if words and Path(words[0]).name in ("xacro", "xacro.py"):
            files = [w for w in words[1:] if ":=" not in w and not w.startswith("-")]
            if len(files) != 1:
                raise LaunchError(f"{where}: command {cmd!r}: expected one xacro file")
            xargs = dict(w.split(":=", 1) for w in words[1:] if ":=" in w and not w.startswith("__"))
            path = Path(files[0])
            try:
                text = str(call(XACRO_TEXT, path, xargs))
            except LaunchError:
                raise
            except Exception as exc:  # DescriptionError and friends, already naming the file and element
                raise LaunchError(f"{where}: {exc}") from None
            self.config.sources[name] = (path, xargs)
            return text
        if not self.config.allow_commands:
            raise LaunchError(
                f"{where}: command {cmd!r} runs a program; navlab runs programs named by a launch "
                "file only with the ROS bridge on (ros:=true); xacro commands run inside navlab"
            )
        import subprocess

        try:
            done = subprocess.run(words, capture_output=True, text=True, timeout=60, check=False)
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise LaunchError(f"{where}: command {cmd!r}: {exc}") from None
        if done.returncode != 0:
            raise LaunchError(f"{where}: command {cmd!r} exited with {done.returncode}: {done.stderr.strip()[:300]}")
        return done.stdout

    def rosparam(self, el: ET.Element, scope: _Scope, where: str) -> None:
        cmd = self.attr(el, "command", scope, where, default="load") or "load"
        ns = self.attr(el, "ns", scope, where, default="") or ""
        pname = self.attr(el, "param", scope, where, default="") or ""
        base = self.param_name(ns, scope, where) if ns else (scope.node or scope.ns)
        target = ns_join(base.rstrip("/") + "/", pname) if pname else base
        if cmd == "delete":
            self.config.delete_param(target)
            return
        if cmd == "dump":
            self.config.notes.append(f"{where}: rosparam dump is not done by navlab (skipped)")
            return
        if cmd != "load":
            raise LaunchError(f"{where}: rosparam command {cmd!r}: expected load, delete or dump")
        file = self.attr(el, "file", scope, where)
        text = read_text(Path(file), where) if file else (el.text or "")
        source = file or str(scope.file)
        if self.flag(el, "subst_value", scope, where):
            text = self.subst(text, scope, where)
        if not text.strip():
            return
        try:
            data = parse_yaml(text, source)
        except ParameterError as exc:
            raise LaunchError(f"{where}: {exc}") from None
        if not isinstance(data, dict) and not pname:
            raise LaunchError(f"{where}: {source}: a non-mapping value needs a param= name")
        self.config.set_param(target, data if data is not None else {}, source)

    def include(self, el: ET.Element, scope: _Scope, where: str, depth: int) -> None:
        path = Path(str(self.attr(el, "file", scope, where, required=True)))
        if not path.is_absolute():
            path = scope.file.parent / path
        if not path.is_file():
            raise LaunchError(f"{where}: included file {path} does not exist")
        ns = self.attr(el, "ns", scope, where)
        inner_ns = push_ns(scope.ns, ns) if ns else scope.ns
        if self.flag(el, "clear_params", scope, where) and ns:
            self.config.delete_param(inner_ns)
        pass_all = self.flag(el, "pass_all_args", scope, where)
        passed: dict[str, str] = dict(scope.args) if pass_all else {}
        env = dict(scope.env)
        for child, cwhere in self.children(el, scope, where):
            if child.tag == "arg":
                name = str(self.attr(child, "name", scope, cwhere, required=True))
                key = "value" if "value" in child.attrib else "default"
                passed[name] = str(self.attr(child, key, scope, cwhere, required=True))
            elif child.tag != "env" or not self.common(child, scope, cwhere, [], env):
                raise LaunchError(f"{cwhere}: <include> takes only <arg> and <env> children")
        self.load_file_in(path, passed, scope.child(ns=inner_ns, env=env), depth + 1, pass_all)

    def load_file_in(self, path: Path, passed: dict[str, str], outer: _Scope, depth: int, pass_all: bool) -> None:
        """An included file: its own args, the includer's namespace, remaps and env."""
        if depth > MAX_INCLUDE_DEPTH:
            raise LaunchError(f"{path}: includes nest deeper than {MAX_INCLUDE_DEPTH} levels (an include loop?)")
        root = parse_launch(path)
        declared = declared_names(root)
        unused = sorted(set(passed) - declared)
        if unused and not pass_all:
            raise LaunchError(
                f"{outer.file}: unused args [{', '.join(unused)}] for include of [{path}] "
                f"(it declares: {', '.join(sorted(declared)) or 'none'})"
            )
        scope = _Scope(path, {}, outer.ns, list(outer.remaps), dict(outer.env))
        self.block(root, scope, {k: v for k, v in passed.items() if k in declared}, depth)

    def node(self, el: ET.Element, scope: _Scope, where: str) -> None:
        pkg = str(self.attr(el, "pkg", scope, where, required=True))
        typ = str(self.attr(el, "type", scope, where, required=True))
        name = str(self.attr(el, "name", scope, where, required=True))
        if "/" in name or not name:
            raise LaunchError(f"{where}: node name {name!r} must be a base name (use ns= for namespaces)")
        ns_attr = self.attr(el, "ns", scope, where)
        ns = push_ns(scope.ns, ns_attr) if ns_attr else scope.ns
        node = RosNode(
            pkg,
            typ,
            name,
            ns,
            args=self.attr(el, "args", scope, where, default="") or "",
            remaps=list(scope.remaps),
            env=dict(scope.env),
            respawn=self.flag(el, "respawn", scope, where),
            respawn_delay=number(self.attr(el, "respawn_delay", scope, where, default="0"), where),
            required=self.flag(el, "required", scope, where),
            output=self.attr(el, "output", scope, where, default="log") or "log",
            cwd=self.attr(el, "cwd", scope, where, default="") or "",
            launch_prefix=self.attr(el, "launch-prefix", scope, where, default="") or "",
            where=where,
        )
        if self.flag(el, "clear_params", scope, where):
            self.config.delete_param(node.fqn)
        inner = scope.child(ns=ns, node=node.fqn)
        for child, cwhere in self.children(el, scope, where):
            if not self.common(child, inner, cwhere, node.remaps, node.env):
                raise LaunchError(f"{cwhere}: <node> takes <param>, <rosparam>, <remap> and <env> children")
        if any(n.fqn == node.fqn for n in self.config.nodes):
            raise LaunchError(
                f"{where}: a node named {node.fqn!r} is already in this launch (roslaunch refuses duplicate node names)"
            )
        self.config.nodes.append(node)


def is_xml_launch(path: str | os.PathLike[str]) -> bool:
    """Whether a file is a ROS 1 XML launch (by suffix ``.launch``/``.xml``, else by its first tag)."""
    p = Path(path)
    if p.suffix in (".launch", ".xml"):
        return True
    if p.suffix in (".yaml", ".yml") or not p.is_file():
        return False
    with p.open("rb") as fh:
        return fh.read(4096).lstrip().startswith((b"<?xml", b"<launch"))


def load(files: list[Path], args: Mapping[str, str], *, seed: int = 0, allow_commands: bool = False) -> RosConfig:
    """Read ``files`` (as ``roslaunch a.launch b.launch name:=value`` does) into one configuration.

    Every file gets the command-line ``args``; an arg that no file declares is refused (a typo would
    otherwise be ignored), as is one that a file declares without a default and nobody sets.
    """
    config = RosConfig(allow_commands=allow_commands)
    loader = _Loader(config, seed)
    for file in files:
        root = parse_launch(file)
        config.declared |= declared_names(root)
    for name in args:
        if name not in config.declared:
            hint = did_you_mean(name, sorted(config.declared), template="did you mean {!r}? ")
            raise LaunchError(
                f"{', '.join(map(str, files))}: unknown launch argument {name!r} ({hint}arguments: "
                f"{', '.join(sorted(config.declared)) or 'none'})"
            )
    for file in files:
        root = parse_launch(file)
        scope = _Scope(file, {})
        loader.block(root, scope, {k: v for k, v in args.items()}, 0)
    return config


def declared_args(file: Path) -> list[dict[str, str]]:
    """The overridable ``<arg>``s of a .launch file: name, description (``doc``) and default, if any."""
    out: list[dict[str, str]] = []
    root = parse_launch(file)
    for el in [e for e in root.iter("arg") if e.get("name") in declared_names(root)]:
        if el.get("name") and "value" not in el.attrib and el.get("name") not in [a["name"] for a in out]:
            row = {"name": str(el.get("name")), "description": el.get("doc", "")}
            if "default" in el.attrib:
                row["default"] = str(el.get("default"))
            out.append(row)
    return out
