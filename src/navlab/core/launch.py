"""YAML launch files in the shape of ROS 2's YAML launch format.

```yaml
launch:
- arg: {name: world, default: room, description: "world file or shipped name"}
- let: {name: scan, value: /mybot/laser/scan}
- include: {file: "$(find-pkg-share navlab)/launch/sim.launch.yaml", arg: [{name: world, value: "$(var world)"}]}
- node:
    if: "$(var localize)"      # ROS 2 launch's if/unless attributes
    pkg: navlab
    exec: amcl
    name: amcl
    namespace: ""
    param: [{from: "$(find-pkg-share navlab)/params/amcl.yaml"}, {name: use_map_topic, value: true}]
    remap: [{from: scan, to: "$(var scan)"}]
```

Substitutions: ``$(var NAME)``, ``$(env NAME [default])``, ``$(find-pkg-share PKG)`` (``navlab`` is
the package's ``resources`` folder), and navlab's ``$(robot KEY)``: ``base_frame``, ``scan_topic`` or
``odom_frame`` from the plugin tags of the robot named by the ``robot`` argument. ``exec`` names a
node in ``navlab.nodes.NODES`` or, for user code, ``module:Class``.
"""

from __future__ import annotations

import importlib
import os
import re
from collections.abc import Callable, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

from navlab.core.errors import LaunchError, ParameterError
from navlab.core.executor import Executor
from navlab.core.launch_session import NodeSpec, Session, located, start_node
from navlab.core.node import flatten_params
from navlab.core.params import load_params, merge_params, parse_yaml, read_yaml
from navlab.errors import NavlabError, did_you_mean

_SUBST = re.compile(r"\$\((\S+)(?:\s+([^)]*))?\)")


def resources_dir() -> Path:
    """The package's shipped resources (robots/, worlds/, params/, launch/)."""
    return Path(str(resources.files("navlab") / "resources"))


def find_launch_file(name_or_path: str) -> Path:
    """A launch file path, or a shipped launch by name (``mapping`` → resources/launch/mapping.launch.yaml)."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    shipped = resources_dir() / "launch"
    for cand in (shipped / name_or_path, shipped / f"{name_or_path}.launch.yaml"):
        if cand.is_file():
            return cand
    names = sorted(f.name.removesuffix(".launch.yaml") for f in shipped.glob("*.launch.yaml"))
    raise LaunchError(f"no launch file {name_or_path!r} (shipped launches: {', '.join(names) or 'none'})")


class _Context:
    def __init__(self, file: Path, args: dict[str, str]) -> None:
        self.file = file
        self.vars: dict[str, str] = dict(args)
        self.robot_values: dict[str, dict[str, str]] = {}  # robot -> its $(robot KEY) values

    def robot_value(self, key: str, where: str) -> str:
        """``$(robot KEY)`` (navlab): ``base_frame``, ``scan_topic`` or ``odom_frame`` from the plugin tags
        of the launch's ``robot`` argument, through the function ``navlab.nodes.ROBOT_LAUNCH_VALUES`` names."""
        from navlab.nodes import ROBOT_LAUNCH_VALUES

        robot = self.vars.get("robot", "mybot")
        if robot not in self.robot_values:
            module, func = ROBOT_LAUNCH_VALUES.split(":", 1)
            self.robot_values[robot] = getattr(importlib.import_module(module), func)(robot)
        values = self.robot_values[robot]
        note = values.get(f"{key}_note")
        if note:  # said once per launch, when the value is used
            import logging

            logging.getLogger("navlab.launch").warning(note)
            values.pop(f"{key}_note")
        if key not in values or key.endswith("_note"):
            raise LaunchError(f"{self.file}: {where}: $(robot {key}): expected one of {', '.join(sorted(values))}")
        return values[key]

    def subst(self, value: Any, where: str) -> Any:
        if isinstance(value, list):
            return [self.subst(v, where) for v in value]
        if isinstance(value, dict):
            return {k: self.subst(v, where) for k, v in value.items()}
        if not isinstance(value, str):
            return value

        def repl(kind: str, arg: str) -> str:
            if kind == "var":
                if arg not in self.vars:
                    known = ", ".join(self.vars) or "none"
                    raise LaunchError(f"{self.file}: {where}: $(var {arg}) is not defined (args: {known})")
                return self.vars[arg]
            if kind == "env":
                name, sep, default = arg.partition(" ")
                if name not in os.environ and not sep:  # ROS 2: an unset variable without a default is an error
                    raise LaunchError(
                        f"{self.file}: {where}: environment variable {name!r} is not set and "
                        f"$(env {name}) gives no default (write $(env {name} DEFAULT))"
                    )
                return os.environ.get(name, default.strip("'\""))
            if kind == "find-pkg-share":
                if arg == "navlab":
                    return str(resources_dir())
                raise LaunchError(f"{self.file}: {where}: unknown package {arg!r} in $(find-pkg-share)")
            if kind == "robot":
                return self.robot_value(arg, where)
            if kind == "eval":  # ROS 2's PythonExpression, in navlab's sandbox
                from navlab.core.roslaunch_config import EVAL_BUILTINS
                from navlab.core.safe_eval import ExpressionError, safe_eval

                try:
                    return str(safe_eval(arg, {"true": True, "false": False}, functions=EVAL_BUILTINS))
                except ExpressionError as exc:
                    raise LaunchError(f"{self.file}: {where}: $(eval {arg}): {exc}") from None
            raise LaunchError(f"{self.file}: {where}: unknown substitution $({kind})")

        out = _expand(value, repl, f"{self.file}: {where}")
        return _typed(out) if out != value else value


def _expand(text: str, resolve: Callable[[str, str], str], where: str) -> str:
    """``text`` with each ``$(KIND ARG)`` replaced by ``resolve(KIND, ARG)``, innermost first (as ROS 2 launch
    nests substitutions: ``$(eval '$(var a)' == 'x')``)."""
    out: list[str] = []
    i = 0
    while (j := text.find("$(", i)) >= 0:
        out.append(text[i:j])
        depth, k = 0, j + 1
        while k < len(text):
            depth += {"(": 1, ")": -1}.get(text[k], 0)
            if depth == 0:
                break
            k += 1
        if k >= len(text):
            raise LaunchError(f"{where}: unterminated substitution in {text!r}")
        kind, _, arg = _expand(text[j + 2 : k], resolve, where).strip().partition(" ")
        out.append(resolve(kind, arg.strip()))
        i = k + 1
    out.append(text[i:])
    return "".join(out)


def _typed(text: str) -> Any:
    """Substituted text as YAML would read it (numbers, booleans) so parameters keep their type."""
    try:
        return parse_yaml(text, "<substitution>") if text.strip() else text
    except ParameterError:
        return text


def _entries(file: Path) -> list[dict[str, Any]]:
    data = read_yaml(file)
    if not isinstance(data, dict) or not isinstance(data.get("launch"), list):
        raise LaunchError(f"{file}: expected a top-level 'launch:' list of arg/let/include/node entries")
    return data["launch"]


def _items(ctx: _Context, spec: dict[str, Any], key: str, where: str, needs: tuple[str, ...]) -> list[dict[str, Any]]:
    """The list ``spec[key]`` (param, remap, arg of an include), each item a mapping with the ``needs`` keys."""
    items = spec.get(key) or []
    if not isinstance(items, list):
        raise LaunchError(f"{ctx.file}: {where}: '{key}' must be a list of mappings, got {items!r}")
    for k, item in enumerate(items):
        missing = [n for n in needs if not isinstance(item, dict) or n not in item]
        if missing:
            raise LaunchError(f"{ctx.file}: {where}: {key}[{k}] needs {' and '.join(map(repr, needs))}, got {item!r}")
    return items


def _text(ctx: _Context, spec: dict[str, Any], key: str, where: str) -> str:
    """``spec[key]`` (required) substituted, as a non-empty string."""
    if key not in spec:
        raise LaunchError(f"{ctx.file}: {where}: missing '{key}'")
    value = ctx.subst(spec[key], where)
    if not isinstance(value, str | int | float) or isinstance(value, bool) or str(value) == "":
        raise LaunchError(f"{ctx.file}: {where}: '{key}' must be a non-empty string, got {value!r}")
    return str(value)


def _node_params(ctx: _Context, spec: dict[str, Any], where: str) -> tuple[dict[str, Any], dict[str, set[str]]]:
    """The node's parameters and the files they came from (file name -> every key name in it, at any depth)."""
    params: dict[str, Any] = {}
    files: dict[str, set[str]] = {}
    for item in _items(ctx, spec, "param", where, ()):
        if isinstance(item, dict) and not _condition(ctx, item, where):  # a param entry's if/unless
            continue
        item = ctx.subst(
            {k: v for k, v in item.items() if k not in ("if", "unless")} if isinstance(item, dict) else item, where
        )
        if not isinstance(item, dict):
            raise LaunchError(f"{ctx.file}: {where}: a param entry must be a mapping, got {item!r}")
        if "from" in item:
            path = Path(str(item["from"]))
            if not path.is_absolute():
                path = ctx.file.parent / path
            loaded = load_params(path, node=str(spec.get("name") or "") or None)
            files.setdefault(path.name, set()).update(k.rsplit(".", 1)[-1] for k in flatten_params(loaded))
            ns = str(item.get("ns") or "").strip("/")
            for part in reversed(ns.split("/") if ns else []):  # rosparam load's ns=: nest under it
                loaded = {part: loaded}
            params = merge_params(params, loaded)
        elif "name" in item:
            params = merge_params(params, {str(item["name"]): item.get("value")})
        else:
            raise LaunchError(f"{ctx.file}: {where}: a param entry needs 'name'+'value' or 'from'")
    return params, files


def _truthy(ctx: _Context, value: Any, key: str, where: str) -> bool:
    """A condition's value: true/false/1/0 (any case) as ROS 2 launch accepts them; anything else is an error."""
    text = str(value).strip().lower() if isinstance(value, str | bool | int) else None
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise LaunchError(f"{ctx.file}: {where}: '{key}' is {value!r}; expected true or false (or 1/0)")


def _condition(ctx: _Context, spec: Any, where: str) -> bool:
    """ROS 2 launch's ``if:`` / ``unless:`` attributes."""
    if not isinstance(spec, dict):
        raise LaunchError(f"{ctx.file}: {where}: expected a mapping of attributes")
    if "if" in spec and not _truthy(ctx, ctx.subst(spec["if"], where), "if", where):
        return False
    return not ("unless" in spec and _truthy(ctx, ctx.subst(spec["unless"], where), "unless", where))


def _run_entries(ctx: _Context, session: Session, depth: int) -> None:
    if depth > 20:
        raise LaunchError(f"{ctx.file}: includes nest deeper than 20 levels (an include loop?)")
    for i, entry in enumerate(_entries(ctx.file)):
        if not isinstance(entry, dict) or len(entry) != 1:
            raise LaunchError(f"{ctx.file}: entry {i + 1}: expected one of arg/let/include/node")
        kind, spec = next(iter(entry.items()))
        where = f"entry {i + 1} ({kind})"
        if not _condition(ctx, spec, where):
            continue
        if kind == "arg":
            name = spec.get("name")
            if not name or not isinstance(name, str):
                raise LaunchError(f"{ctx.file}: {where}: an arg needs a 'name' (a string)")
            if name not in ctx.vars:
                if "default" not in spec:
                    raise LaunchError(f"{ctx.file}: argument {name!r} has no default; pass {name}:=VALUE")
                ctx.vars[name] = str(ctx.subst(spec["default"], where))
        elif kind == "let":
            name = _text(ctx, spec, "name", where)
            if "value" not in spec:
                raise LaunchError(f"{ctx.file}: {where}: a let needs a 'value'")
            ctx.vars[name] = str(ctx.subst(spec["value"], where))
        elif kind == "include":
            path = Path(_text(ctx, spec, "file", where))
            if not path.is_absolute():
                path = ctx.file.parent / path
            if not path.is_file():
                raise LaunchError(f"{ctx.file}: {where}: included file {path} does not exist")
            sub_args = {
                str(a["name"]): str(ctx.subst(a["value"], where))
                for a in _items(ctx, spec, "arg", where, ("name", "value"))
            }
            _run_entries(_Context(path, sub_args), session, depth + 1)
        elif kind == "node":
            exec_name = spec.get("exec")
            if not exec_name or not isinstance(exec_name, str):
                raise LaunchError(f"{ctx.file}: {where}: a node needs 'exec' (a node name or module:Class)")
            remaps = {
                str(ctx.subst(r["from"], where)): _text(ctx, r, "to", where)
                for r in _items(ctx, spec, "remap", where, ("from", "to"))
            }
            params, files = _node_params(ctx, spec, where)
            node_name = _text(ctx, spec, "name", where) if "name" in spec else ""
            namespace = _text(ctx, spec, "namespace", where) if spec.get("namespace") else ""
            source = f" (parameters from {', '.join(files)})" if files else ""
            start_node(
                session,
                NodeSpec(
                    exec_name,
                    node_name,
                    namespace,
                    params,
                    remaps,
                    f"{ctx.file}: {where} {node_name or exec_name!r}{source}",
                    files,
                ),
            )
        else:
            raise LaunchError(f"{ctx.file}: {where}: unknown entry {kind!r} (expected arg, let, include or node)")


def _check_args(files: list[Path], args: dict[str, Any]) -> None:
    """Refuse arguments no file declares or uses (a typo like ``wrold:=room`` would be ignored)."""
    known: set[str] = set()
    for file in files:
        entries = [e for e in _entries(file) if isinstance(e, dict) and isinstance(e.get("arg"), dict)]
        known |= {str(e["arg"].get("name")) for e in entries}
        known |= {m.group(2).strip() for m in _SUBST.finditer(file.read_text()) if m.group(1) == "var" and m.group(2)}
    for name in args:
        if name not in known:
            hint = did_you_mean(name, sorted(known), template="did you mean {!r}? ")
            where = ", ".join(map(str, files))
            raise LaunchError(
                f"{where}: unknown launch argument {name!r} ({hint}arguments: {', '.join(sorted(known))})"
            )


def _from_cwd(value: Any) -> Any:
    """A launch argument given by the caller (the command line, Python) that names an existing file or folder
    relative to the current folder, as an absolute path: ROS resolves command-line paths against the current
    folder, and a path inside a launch file against that file's folder (``from:``/``file:``), so
    ``params:=my_params`` must not be looked for beside the shipped launch file."""
    text = str(value) if isinstance(value, str | os.PathLike) else ""
    if text and not os.path.isabs(text) and "$(" not in text and os.path.exists(text):
        return os.path.abspath(text)
    return value


def declared_args(name_or_path: str) -> list[dict[str, Any]]:
    """The ``arg`` entries of a launch file (for ``--help``-like listings); a ROS 1 .launch's ``<arg>``
    elements with ``doc`` as the description and ``value=`` ones (fixed) left out."""
    file = find_launch_file(name_or_path)
    from navlab.core.roslaunch import declared_args as xml_args
    from navlab.core.roslaunch import is_xml_launch

    if is_xml_launch(file):
        return xml_args(file)
    return [e["arg"] for e in _entries(file) if isinstance(e, dict) and "arg" in e]


def start(
    name_or_path: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    *,
    executor: Executor | None = None,
    seed: int = 0,
    rate: float = 0.0,
    launch_args: dict[str, Any] | None = None,
    overrides: dict[str, dict[str, Any]] | None = None,
    ros: bool = False,
    pace: float | None = None,
    **args: Any,
) -> Session:
    """Start a launch (shipped name or file, or several files as ``roslaunch a.launch b.launch``) with
    arguments; returns the session.

    Arguments come as keywords (``start("mapping", world="room")``) or, for names that clash with
    this function's own (``seed``, ``rate``), in ``launch_args``. ``rate`` is the executor's pace
    (0 = as fast as possible, 1 = real time; ``pace``, its old name, is deprecated: a launch argument called
    ``rate`` goes in ``launch_args``). ``overrides`` maps a node name to parameters applied after the launch
    file's own (``{"amcl": {"laser_max_beams": 60}}``); a name no node has is refused.
    ROS 1 XML files (``.launch``) are read with roslaunch's semantics (:mod:`navlab.core.roslaunch`);
    ``ros`` (or the argument ``ros:=true``) starts the nodes navlab does not implement as processes,
    as roslaunch does, for the ROS bridge. Call :meth:`Session.shutdown` when done.
    """
    from navlab.deprecation import renamed

    rate = renamed(rate, pace, old="pace", new="rate", where="navlab.launch")
    names = [name_or_path] if isinstance(name_or_path, str | os.PathLike) else list(name_or_path)
    if not names:
        raise LaunchError("no launch file given")
    files = [find_launch_file(str(n)) for n in names]
    all_args = {k: str(_from_cwd(v)) for k, v in {**(launch_args or {}), **args}.items()}
    from navlab.core.roslaunch import is_xml_launch

    xml = [is_xml_launch(f) for f in files]
    if any(xml) and not all(xml):
        raise LaunchError(
            f"{', '.join(map(str, files))}: ROS 1 .launch (XML) and YAML launch files cannot be "
            "started together; start them in one format"
        )
    session = Session(
        executor or Executor(seed=seed, rate=rate),
        args=all_args,
        overrides={k.lstrip("/"): dict(v) for k, v in (overrides or {}).items()},
    )
    if all(xml):
        if "ros" in all_args:
            ros = _truthy(_Context(files[0], {}), all_args.pop("ros"), "ros", "argument ros:=")
        from navlab.core.roslaunch_nodes import start_xml

        start_xml(session, files, all_args, ros=ros, seed=seed)
    else:
        _check_args(files, all_args)
        for file in files:
            ctx = _Context(file, all_args)
            _run_entries(ctx, session, 0)
            session.args = {**session.args, **ctx.vars}
    for name, node in session.nodes.items():  # unknown parameters, named with the file that set them
        try:
            node.check_parameters()
        except NavlabError as exc:
            session.shutdown()
            raise located(exc, session.origins.get(name, str(files[0]))) from None
    started = {name.rsplit("/", 1)[-1] for name in session.nodes}
    unknown = sorted(set(session.overrides) - started)
    if unknown:
        session.shutdown()
        raise LaunchError(
            f"{', '.join(map(str, files))}: parameters given for {', '.join(map(repr, unknown))}, but "
            f"the launch starts no such node (nodes: {', '.join(sorted(started))})"
        )
    return session
