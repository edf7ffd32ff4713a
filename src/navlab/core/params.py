"""ROS-layout parameter files.

Two layouts are read:

- ROS 1 private-parameter files (``rosparam load``), as the move_base family ships them: a mapping
  of parameter names, possibly nested in namespaces (``TrajectoryPlannerROS: {max_vel_x: 0.5}``).
- Nav2's ``node_name: {ros__parameters: {...}}``; ``load_params(path, node="amcl")`` picks one node.
"""

from __future__ import annotations

import dataclasses
import difflib
import logging
import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from operator import ge, gt, le
from pathlib import Path
from typing import Any, TypeVar

import yaml

from navlab.core.errors import ParameterError
from navlab.errors import NavlabError, did_you_mean
from navlab.io import IoError, read_text_checked

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
    warnings.warn(
        ParameterWarning(f"unknown {what} parameter '{key}' ignored (ROS ignores what it does not read)", key),
        stacklevel=3,
    )


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
                    None,
                    None,
                    f"aliases (*name) expand to more than {MAX_YAML_NODES} values (an alias bomb?)",
                    node.start_mark,
                )
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
        raise ParameterError(
            f"{source}:{line}:{col}: malformed YAML: character #x{exc.character:04x} is not allowed in YAML"
        ) from None
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
    return isinstance(data, dict) and any(isinstance(v, dict) and "ros__parameters" in v for v in data.values())


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


@dataclass(frozen=True)
class ParamSpec:
    """How a ROS parameter dict becomes a settings dataclass (``read_params``), declared once per class as
    its ``PARAMS`` class attribute.

    - ``what``: the name in messages (the ROS plugin or node, ``TrajectoryPlannerROS``); ``error``: the
      package's error class every refusal raises.
    - ``aliases``: another accepted spelling (an older or Nav2 name) -> field name; both spellings with
      different values is an error. ``ignored``: keys accepted and dropped (runtime or view-only settings).
    - ``at_least`` / ``above`` / ``at_most``: field -> bound, refused below (``>=``) / at or below (``>``) /
      above (``<=``) it; ``choices``: field -> the values allowed.
    - ``clamp_at_least``: field -> bound; a value below it is set to the bound with a warning, as ROS does
      (``vy_samples: 0`` in TurtleBot3's DWA files).
    - ``prepare``: a function from the raw dict to the dict read (one key that sets two fields, nested
      sections parsed by their own reader).
    - ``strict``: every unknown key is refused (naming the known ones), not only a likely typo
      (``check_unknown_key``): for a short, closed set of keys such as a PID's gains.

    After reading, a class's own ``validate()`` (if it has one) checks what spans several fields.
    """

    what: str
    error: type[Exception] = ParameterError
    aliases: Mapping[str, str] = field(default_factory=dict)
    ignored: frozenset[str] = frozenset()
    at_least: Mapping[str, float] = field(default_factory=dict)
    above: Mapping[str, float] = field(default_factory=dict)
    at_most: Mapping[str, float] = field(default_factory=dict)
    choices: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    clamp_at_least: Mapping[str, float] = field(default_factory=dict)
    prepare: Callable[[dict[str, Any]], dict[str, Any]] | None = None
    strict: bool = False


def param_error(what: str, key: str, value: Any, expected: str, error: type[Exception] = ParameterError) -> Exception:
    """The one-line refusal of a parameter ``key`` = ``value`` that is not ``expected``."""
    return error(f"{what + ' ' if what else ''}parameter {key}: expected {expected}, got {value!r}")


_EXPECTED = {
    bool: "true or false",
    int: "an integer",
    float: "a number",
    str: "a string",
    list: "a list",
    tuple: "a list",
    dict: "a mapping",
}


def typed_value(
    kind: type, key: str, val: Any, *, what: str = "", error: type[Exception] = ParameterError, finite: bool = True
) -> Any:
    """``val`` as the type ``kind`` of the parameter's default, refusing what ROS's typed parameters would (a
    string for a number, 2.5 for an integer, "yes" for a boolean, null, NaN; inf too unless ``finite`` is
    False). The one type rule of settings dataclasses and node parameters."""
    if isinstance(val, float) and (math.isnan(val) or (finite and kind is float and math.isinf(val))):
        raise param_error(what, key, val, "a finite number" if finite else "a number", error)
    if kind is bool:
        ok = isinstance(val, bool) or (isinstance(val, int) and val in (0, 1))
    elif kind is int:
        ok = (
            not isinstance(val, bool)
            and isinstance(val, int | float)
            and math.isfinite(val)
            and float(val).is_integer()
        )
    elif kind is float:
        ok = not isinstance(val, bool) and isinstance(val, int | float)
    elif kind in (list, tuple):
        ok = isinstance(val, list | tuple)
    elif kind is dict:
        ok = isinstance(val, Mapping)
    else:
        ok = isinstance(val, kind)
    if not ok:
        raise param_error(what, key, val, _EXPECTED.get(kind, kind.__name__), error)
    return kind(val) if kind in _EXPECTED else val


def canonical_params(values: Mapping[str, Any], spec: ParamSpec, *, what: str | None = None) -> dict[str, Any]:
    """``values`` with ``spec``'s aliases renamed to field names and its ignored keys dropped; two spellings
    of one parameter with different values are refused."""
    what = what or spec.what
    out: dict[str, Any] = {}
    spelled: dict[str, str] = {}
    for key, val in values.items():
        if key in spec.ignored:
            continue
        name = spec.aliases.get(key, key)
        if name in out and out[name] != val:
            raise spec.error(
                f"{what} parameters {spelled[name]!r} and {key!r} are two spellings of one parameter "
                f"with different values ({out[name]!r} vs {val!r}): give one"
            )
        out[name], spelled[name] = val, key
    return out


def read_params(cls: type[T], values: Mapping[str, Any] | T | None, *, what: str | None = None) -> T:
    """An instance of the settings dataclass ``cls`` from a ROS parameter dict, as its ``PARAMS`` spec says
    (an instance of ``cls`` is checked and returned as is; None gives the defaults).

    Each value takes its default's type (``typed_value``); an unknown key follows ``check_unknown_key`` (a likely
    typo raises with "did you mean", any other key warns and is ignored); then the spec's ranges and
    clamps, then the class's ``validate()``. Every refusal is one line naming the key. A frozen class's
    fields are set as its own ``__init__`` sets them.
    """
    spec: ParamSpec = getattr(cls, "PARAMS", None) or ParamSpec(cls.__name__)
    what = what or spec.what
    frozen = getattr(getattr(cls, "__dataclass_params__", None), "frozen", False)
    setattr_ = object.__setattr__ if frozen else setattr
    if isinstance(values, cls):
        out = values
    else:
        if values is not None and not isinstance(values, Mapping):
            raise spec.error(f"{what} parameters: expected a dict of ROS parameters, got {type(values).__name__}")
        raw = dict(values or {})
        canon = canonical_params(spec.prepare(raw) if spec.prepare else raw, spec, what=what)
        out = cls()
        names = [f.name for f in fields(cls)]  # type: ignore[arg-type]
        for key, val in canon.items():
            if key not in names:
                if spec.strict:
                    hint = did_you_mean(key, names)
                    raise spec.error(f"unknown {what} parameter '{key}'{hint} (known: {', '.join(names)})")
                check_unknown_key(str(key), names, what=what, error=spec.error)
                continue
            setattr_(out, key, typed_value(type(getattr(out, key)), key, val, what=what, error=spec.error))
    for f in fields(out):  # type: ignore[arg-type]
        val = getattr(out, f.name)
        if isinstance(val, float) and not math.isfinite(val):
            raise param_error(what, f.name, val, "a finite number", spec.error)
    for key, low in spec.clamp_at_least.items():
        if getattr(out, key) < low:
            logging.getLogger("navlab.params").warning(
                f"{what}: {key} is {getattr(out, key)}; it is set to {low} (as ROS does)"
            )
            setattr_(out, key, type(getattr(out, key))(low))
    for bounds, within, sign in ((spec.at_least, ge, ">="), (spec.above, gt, ">"), (spec.at_most, le, "<=")):
        for key, bound in bounds.items():
            val = getattr(out, key)
            if not _within(within, val, bound):
                raise param_error(what, key, val, f"{sign} {bound}", spec.error)
    for key, allowed in spec.choices.items():
        if getattr(out, key) not in allowed:
            raise param_error(what, key, getattr(out, key), f"one of {', '.join(map(repr, allowed))}", spec.error)
    validate = getattr(out, "validate", None)
    if callable(validate):
        validate()
    return out


def _within(compare: Callable[[Any, Any], Any], value: Any, bound: Any) -> bool:
    """``compare(value, bound)``, False for a value that does not compare (a string set by code, not a file)."""
    try:
        return bool(compare(value, bound))
    except TypeError:
        return False


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


def flatten_params(params: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested parameter dicts to dotted names (``global_costmap.update_frequency``)."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten_params(value, name + "."))
        else:
            out[name] = value
    return out


def dataclass_parameters(cls: type, *, prefix: str = "") -> dict[str, Any]:
    """Parameter names and defaults from a parameters dataclass's fields (``prefix.name`` if a prefix is given).

    The dataclass is where a component writes its ROS names and defaults once; nodes declare from it.
    """
    if not dataclasses.is_dataclass(cls):
        raise ParameterError(f"{cls!r} is not a dataclass of parameters")
    out: dict[str, Any] = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            raise ParameterError(f"{cls.__name__}.{f.name}: a parameter needs a default")
        out[f"{prefix}.{f.name}" if prefix else f.name] = default
    return out
