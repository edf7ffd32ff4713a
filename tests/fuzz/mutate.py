"""Malformed variants of a seed: text, YAML-structure, XML, launch, CARMEN and PGM mutations.

Every mutation returns a :class:`Case` saying whether the change made the input invalid *by
construction* (a NaN where a number is needed, a negative mass, min > max, an alias bomb, ...): a
loader that accepts such a case accepted an invalid value. Mutations that may or may not leave a
valid file (truncation, a deleted key) are neutral: only a traceback, a hang or a crash counts.
"""

from __future__ import annotations

import copy
import difflib
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

from navlab.core.params import TYPO_CUTOFF

from .seeds import Seed

FIFO = b"\x00navlab-fuzz:fifo"  # written as a named pipe instead of a file
LINK_PREFIX = b"\x00navlab-fuzz:link:"  # written as a symbolic link to the path that follows


@dataclass
class Case:
    """One fuzz input: files to write, the file the loader gets, and what the mutation did."""

    fmt: str
    mutation: str
    invalid: bool
    files: dict[str, bytes]
    main: str
    expect: dict[str, Any] = field(default_factory=dict)


# --- value rules: which numbers must be positive / non-negative (anything numeric must be finite) -----

POS, NONNEG = "pos", "nonneg"
RULES: dict[str, dict[str, str]] = {
    "amcl": {
        **dict.fromkeys(
            (
                "min_particles",
                "max_particles",
                "kld_err",
                "kld_z",
                "resample_interval",
                "laser_max_beams",
                "laser_sigma_hit",
                "laser_lambda_short",
                "laser_likelihood_max_dist",
            ),
            POS,
        ),
        **dict.fromkeys(
            (
                "update_min_d",
                "update_min_a",
                "recovery_alpha_slow",
                "recovery_alpha_fast",
                "initial_cov_xx",
                "initial_cov_yy",
                "initial_cov_aa",
                "laser_z_hit",
                "laser_z_short",
                "laser_z_max",
                "laser_z_rand",
                "odom_alpha1",
                "odom_alpha2",
                "odom_alpha3",
                "odom_alpha4",
                "odom_alpha5",
                "transform_tolerance",
            ),
            NONNEG,
        ),
    },
    "gmapping": {
        **dict.fromkeys(
            (
                "transform_publish_period",
                "throttle_scans",
                "maxUrange",
                "sigma",
                "lstep",
                "astep",
                "lsigma",
                "ogain",
                "particles",
                "delta",
                "llsamplerange",
                "llsamplestep",
                "lasamplerange",
                "lasamplestep",
                "occ_thresh",
                "resampleThreshold",
            ),
            POS,
        ),
        **dict.fromkeys(
            (
                "map_update_interval",
                "maxRange",
                "kernelSize",
                "iterations",
                "lskip",
                "minimumScore",
                "srr",
                "srt",
                "str",
                "stt",
                "linearUpdate",
                "angularUpdate",
            ),
            NONNEG,
        ),
    },
    "move_base": {
        **dict.fromkeys(
            (
                "max_vel_x",
                "max_vel_theta",
                "acc_lim_x",
                "acc_lim_theta",
                "robot_radius",
                "width",
                "height",
                "resolution",
                "controller_frequency",
                "vx_max",
                "wz_max",
                "vx_std",
                "prune_distance",
            ),
            POS,
        ),
        **dict.fromkeys(
            (
                "xy_goal_tolerance",
                "yaw_goal_tolerance",
                "inflation_radius",
                "cost_scaling_factor",
                "update_frequency",
                "publish_frequency",
                "transform_tolerance",
                "planner_frequency",
                "planner_patience",
                "controller_patience",
                "oscillation_timeout",
                "oscillation_distance",
                "conservative_reset_dist",
                "occdist_scale",
                "min_in_place_vel_theta",
                "obstacle_range",
                "raytrace_range",
                "acc_lim_y",
            ),
            NONNEG,
        ),  # ROS: 0 range = mark nothing
    },
    "map": {"resolution": POS},
    "route": {"duration": POS},
    "scenario": {"time_limit": POS, "trials": POS, "seed": NONNEG, "t": NONNEG},
    "launch": {"rate": POS},
    # XML: element text by tag, attributes as element@attribute
    "urdf": {
        **dict.fromkeys(
            (
                "mass@value",
                "box@size",
                "cylinder@radius",
                "cylinder@length",
                "sphere@radius",
                "samples",
                "wheelSeparation",
                "wheelDiameter",
            ),
            POS,
        ),
        **dict.fromkeys(
            (
                "inertia@ixx",
                "inertia@iyy",
                "inertia@izz",
                "mu1",
                "mu2",
                "kp",
                "kd",
                "wheelTorque",
                "limit@effort",
                "limit@velocity",
            ),
            NONNEG,
        ),  # Gazebo: update rates <= 0 mean "every step"
    },
    "world": {
        **dict.fromkeys(("size", "radius", "length", "mass", "max_step_size"), POS),
        **dict.fromkeys(("mu", "mu2", "real_time_update_rate", "real_time_factor", "ixx", "iyy", "izz"), NONNEG),
    },
}
RULES["robot"] = RULES["urdf"]

# XML numbers the loaders read (a NaN in a light's colour that nothing reads is not an accepted invalid value)
READ_XML: dict[str, frozenset[str]] = {
    "urdf": frozenset(
        {
            "origin@xyz",
            "origin@rpy",
            "mass@value",
            "inertia@ixx",
            "inertia@iyy",
            "inertia@izz",
            "inertia@ixy",
            "inertia@ixz",
            "inertia@iyz",
            "box@size",
            "cylinder@radius",
            "cylinder@length",
            "sphere@radius",
            "mesh@scale",
            "limit@lower",
            "limit@upper",
            "limit@effort",
            "limit@velocity",
            "axis@xyz",
            "mu1",
            "mu2",
            "updateRate",
            "update_rate",
            "samples",
            "min_angle",
            "max_angle",
            "min",
            "max",
            "wheelSeparation",
            "wheelDiameter",
            "wheelTorque",
            "wheelAcceleration",
            "pose",
        }
    ),
    "world": frozenset(
        {
            "pose",
            "size",
            "radius",
            "length",
            "mass",
            "mu",
            "mu2",
            "ixx",
            "iyy",
            "izz",
            "ixy",
            "ixz",
            "iyz",
            "max_step_size",
        }
    ),
}
READ_XML["robot"] = READ_XML["urdf"]

PAIRS: dict[str, list[tuple[str, str]]] = {
    "amcl": [("min_particles", "max_particles"), ("laser_min_range", "laser_max_range")],
    "gmapping": [("xmin", "xmax"), ("ymin", "ymax")],
    "move_base": [("min_vel_x", "max_vel_x"), ("vx_min", "vx_max")],
    "map": [("free_thresh", "occupied_thresh")],
}

YAML_FORMATS = ("amcl", "gmapping", "move_base", "map", "launch", "route", "scenario")
XML_FORMATS = ("robot", "urdf", "world")
STRICT_KEYS = ("amcl", "gmapping", "move_base", "scenario")  # formats whose unknown keys must be refused


def _pick_file(seed: Seed, rng: np.random.Generator, *, suffix: tuple[str, ...] = ()) -> str:
    names = [n for n in (seed.mutable or [seed.main]) if not suffix or n.endswith(suffix)]
    return names[int(rng.integers(len(names)))]


# --- text mutations (any format) -------------------------------------------------------------------


def _text(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    name = _pick_file(seed, rng)
    data = seed.files[name]
    binary_file = name.endswith(".pgm")
    kind = ["binary", "nul", "truncate", "empty", "dup_line", "drop_line", "crlf", "bom", "long_token"][
        int(rng.integers(9))
    ]
    pos = int(rng.integers(len(data) + 1))
    invalid = False
    if kind == "binary":
        junk = bytes(rng.integers(0, 256, int(rng.integers(4, 64)), dtype=np.uint8)) + b"\xff\xfe\xc3("
        data = data[:pos] + junk + data[pos:]
        invalid = not binary_file and fmt != "carmen"
    elif kind == "nul":
        data = data[:pos] + b"\x00" + data[pos:]
        invalid = not binary_file and fmt != "carmen"
    elif kind == "truncate":
        data = data[:pos]
    elif kind == "empty":
        data = b""
    elif kind in ("dup_line", "drop_line"):
        lines = data.split(b"\n")
        k = int(rng.integers(len(lines)))
        lines[k : k + 1] = [lines[k], lines[k]] if kind == "dup_line" else []
        data = b"\n".join(lines)
    elif kind == "crlf":
        data = data.replace(b"\n", b"\r\n")
    elif kind == "bom":
        data = b"\xef\xbb\xbf" + data
    else:
        data = data[:pos] + b"x" * 200_000 + data[pos:]
    return Case(fmt, f"text:{kind}", invalid, {**seed.files, name: data}, seed.main)


# --- YAML structure mutations ---------------------------------------------------------------------------


def _leaves(node: Any, path: tuple[Any, ...] = ()) -> list[tuple[tuple[Any, ...], Any]]:
    out: list[tuple[tuple[Any, ...], Any]] = []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _leaves(v, (*path, i))
    else:
        out.append((path, node))
    return out


def _set(doc: Any, path: tuple[Any, ...], value: Any) -> None:
    node = doc
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def _key_of(path: tuple[Any, ...]) -> str:
    for p in reversed(path):
        if isinstance(p, str):
            return p
    return ""


def _rule(fmt: str, path: tuple[Any, ...]) -> str | None:
    return RULES.get(fmt, {}).get(_key_of(path))


def _dump(doc: Any) -> bytes:
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=1000).encode()


def _numeric_leaves(doc: Any) -> list[tuple[tuple[Any, ...], Any]]:
    return [(p, v) for p, v in _leaves(doc) if isinstance(v, int | float) and not isinstance(v, bool)]


def _yaml_value(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    name = _pick_file(seed, rng, suffix=(".yaml",))
    doc = yaml.safe_load(seed.files[name])
    nums = _numeric_leaves(doc)
    leaves = _leaves(doc)
    kind = ["nan", "inf", "ninf", "negative", "zero", "null", "string", "huge", "list", "bool"][int(rng.integers(10))]
    pool = nums if nums and kind != "null" else leaves
    if not pool:
        return _text(fmt, seed, rng)
    path, old = pool[int(rng.integers(len(pool)))]
    numeric = isinstance(old, int | float) and not isinstance(old, bool)
    rule = _rule(fmt, path)
    value: Any
    invalid = False
    if kind in ("nan", "inf", "ninf"):
        value = {"nan": float("nan"), "inf": float("inf"), "ninf": float("-inf")}[kind]
        invalid = numeric
    elif kind == "negative":
        value = -abs(old) - 1 if numeric else -1
        invalid = numeric and rule in (POS, NONNEG)
    elif kind == "zero":
        value = 0
        invalid = numeric and rule == POS
    elif kind == "huge":
        value = -1e308 if rule in (POS, NONNEG) else 1e308
        invalid = numeric and rule in (POS, NONNEG)
    elif kind == "null":
        value = None
        invalid = numeric and fmt in (*STRICT_KEYS, "route", "map")
    elif kind == "string":
        value = "not-a-number" if numeric else 12345
        invalid = numeric
    elif kind == "list":
        value = [old, old]
        invalid = numeric
    else:
        value = True
        invalid = numeric and fmt != "launch"
    if fmt == "scenario" and _key_of(path) == "t" and kind == "list":
        invalid = False  # an obstacle's time may be a [lo, hi] range drawn per trial
    if fmt == "map" and _key_of(path) == "negate" and kind == "bool":
        invalid = False  # navlab reads negate: true/false as 1/0 (documented leniency)
    if fmt == "move_base" and path and path[0] in ("DWAPlannerROS", "MPPIController"):
        invalid = False  # parameters of planners this configuration does not select are not read (as in ROS)
    _set(doc, path, value)
    label = f"yaml:{kind}" + (f"@{_key_of(path)}" if _key_of(path) else "")
    return Case(fmt, label, invalid, {**seed.files, name: _dump(doc)}, seed.main)


def _typo(key: str, rng: np.random.Generator) -> str:
    if len(key) < 3:
        return key + "_x"
    i = int(rng.integers(1, len(key) - 1))
    return key[:i] + key[i + 1] + key[i] + key[i + 2 :] if key[i] != key[i + 1] else key + "s"


def _yaml_structure(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    name = _pick_file(seed, rng, suffix=(".yaml",))
    text = seed.files[name]
    doc = yaml.safe_load(text)
    kind = ["unknown_key", "delete_key", "pair", "alias_bomb", "deep_nest", "top_list", "top_scalar"][
        int(rng.integers(7))
    ]
    if kind == "alias_bomb":
        lines = ["fuzz_a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
        for k in range(1, 10):
            lines.append(f"fuzz_a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]")
        if isinstance(doc, dict) and "launch" in doc:
            body = text + b"\n" + "\n".join(lines).encode() + b"\n"
        else:
            body = "\n".join(lines).encode() + b"\n" + text
        return Case(fmt, "yaml:alias_bomb", True, {**seed.files, name: body}, seed.main)
    if kind == "deep_nest":
        depth = int(rng.integers(500, 5000))
        body = text + f"\nfuzz_deep: {'[' * depth}1{']' * depth}\n".encode()
        return Case(fmt, "yaml:deep_nest", fmt in STRICT_KEYS, {**seed.files, name: body}, seed.main)
    if kind == "top_list":
        return Case(fmt, "yaml:top_list", True, {**seed.files, name: b"- 1\n- 2\n"}, seed.main)
    if kind == "top_scalar":
        return Case(fmt, "yaml:top_scalar", True, {**seed.files, name: b"just a string\n"}, seed.main)
    dicts: list[tuple[tuple[Any, ...], dict[str, Any]]] = []

    def walk(node: Any, path: tuple[Any, ...]) -> None:
        if isinstance(node, dict):
            dicts.append((path, node))
            for k, v in node.items():
                walk(v, (*path, k))
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, (*path, i))

    walk(doc, ())
    if kind == "pair":
        for lo, hi in PAIRS.get(fmt, []):
            for _path, d in dicts:
                if lo in d or hi in d:
                    d[lo], d[hi] = 5.0, 2.0
                    if fmt == "map":
                        d[lo], d[hi] = 0.7, 0.3
                    return Case(fmt, f"yaml:pair@{lo}>{hi}", True, {**seed.files, name: _dump(doc)}, seed.main)
        kind = "delete_key"
    dicts = [(p, d) for p, d in dicts if d]
    if not dicts:
        return _text(fmt, seed, rng)
    path, d = dicts[int(rng.integers(len(dicts)))]
    key = list(d)[int(rng.integers(len(d)))]
    if kind == "unknown_key" and isinstance(key, str):
        misspelt = _typo(key, rng)
        d[misspelt] = d[key]
        top = fmt in STRICT_KEYS and not (
            fmt == "move_base" and path and path[0] in ("laser_scan_sensor", "DWAPlannerROS", "MPPIController")
        )
        # a typo of a key that the format leaves open (plugin sub-namespaces) is not wrong by construction; nor,
        # in ROS parameter files, is a key too far from every known one to be its misspelling: ROS ignores it,
        # navlab warns (the unknown-key policy, navlab.core.params.check_unknown_key)
        typo = difflib.SequenceMatcher(None, misspelt, key).ratio() >= TYPO_CUTOFF
        return Case(
            fmt,
            f"yaml:unknown_key@{key}",
            (top and fmt != "scenario" and typo) or (fmt == "scenario" and not path),
            {**seed.files, name: _dump(doc)},
            seed.main,
        )
    del d[key]
    return Case(fmt, f"yaml:delete_key@{key}", False, {**seed.files, name: _dump(doc)}, seed.main)


# --- launch mutations -----------------------------------------------------------------------------------


def _launch(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    doc = yaml.safe_load(seed.files[seed.main])
    entries = doc["launch"]
    kind = [
        "let_no_name",
        "let_no_value",
        "include_no_file",
        "include_arg_no_value",
        "remap_no_to",
        "remap_no_from",
        "if_maybe",
        "if_number",
        "unless_list",
        "env_unset",
        "include_self",
        "rate_zero",
        "rate_negative",
        "rate_nan",
        "rate_text",
        "exec_function",
        "exec_missing",
        "entry_list",
        "param_no_from",
        "undefined_var",
        "arg_no_name",
        "include_missing",
    ][int(rng.integers(22))]
    invalid = True
    by_kind = {next(iter(e)): e[next(iter(e))] for e in entries if isinstance(e, dict)}
    node = next(e["node"] for e in entries if "node" in e)
    if kind == "let_no_name":
        del by_kind["let"]["name"]
    elif kind == "let_no_value":
        del by_kind["let"]["value"]
    elif kind == "include_no_file":
        del by_kind["include"]["file"]
    elif kind == "include_arg_no_value":
        del by_kind["include"]["arg"][0]["value"]
    elif kind == "remap_no_to":
        del node["remap"][0]["to"]
    elif kind == "remap_no_from":
        del node["remap"][0]["from"]
    elif kind == "if_maybe":
        node["if"] = "maybe"
    elif kind == "if_number":
        node["if"] = 2
    elif kind == "unless_list":
        node["unless"] = [1, 2]
    elif kind == "env_unset":
        by_kind["include"]["arg"][1]["value"] = "$(env NAVLAB_FUZZ_SURELY_UNSET)"
    elif kind == "include_self":
        by_kind["include"]["file"] = seed.main
    elif kind.startswith("rate_"):
        rate_arg = next(e["arg"] for e in entries if "arg" in e and e["arg"].get("name") == "rate")
        rate_arg["default"] = {"rate_zero": "0", "rate_negative": "-2.0", "rate_nan": ".nan", "rate_text": "fast"}[kind]
    elif kind == "exec_function":
        node["exec"] = "os:getcwd"
    elif kind == "exec_missing":
        node["exec"] = "navlab_fuzz_no_such_module:Node"
    elif kind == "entry_list":
        entries.append({"node": ["talker"]})
    elif kind == "param_no_from":
        node["param"].append({"ns": "x"})
    elif kind == "undefined_var":
        node["name"] = "$(var nowhere)"
    elif kind == "arg_no_name":
        del next(e["arg"] for e in entries if "arg" in e)["name"]
    else:
        by_kind["include"]["file"] = "missing.launch.yaml"
    return Case(fmt, f"launch:{kind}", invalid, {**seed.files, seed.main: _dump(doc)}, seed.main)


# --- XML mutations (robot descriptions, URDF, SDF worlds) -----------------------------------------------

_TEXT_NUM = re.compile(rb"<([A-Za-z_][\w]*)(\s[^>]*)?>(\s*[-+0-9.eE]+(?:\s+[-+0-9.eE]+)*\s*)</\1>")
_ATTR_NUM = re.compile(rb"\s([A-Za-z_][\w]*)=\"(\s*[-+0-9.eE]+(?:\s+[-+0-9.eE]+)*\s*)\"")


def _xml_numbers(data: bytes) -> list[tuple[int, int, str]]:
    """(start, end, rule key) of every numeric element text and attribute value."""
    out = [(m.start(3), m.end(3), m.group(1).decode()) for m in _TEXT_NUM.finditer(data)]
    for m in _ATTR_NUM.finditer(data):
        elem = re.findall(rb"<([A-Za-z_][\w:]*)", data[: m.start()])
        out.append((m.start(2), m.end(2), f"{elem[-1].decode() if elem else ''}@{m.group(1).decode()}"))
    return out


def _xml_value(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    names = [n for n in (seed.mutable or [seed.main]) if not n.endswith(".xacro")] or [seed.main]
    name = names[int(rng.integers(len(names)))]
    data = seed.files[name]
    spots = _xml_numbers(data)
    if not spots:
        return _text(fmt, seed, rng)
    start, end, key = spots[int(rng.integers(len(spots)))]
    tokens = data[start:end].split()
    t = int(rng.integers(len(tokens)))
    kind = ["nan", "inf", "negative", "zero", "word", "huge"][int(rng.integers(6))]
    rule = RULES[fmt].get(key)
    old = float(tokens[t]) if re.fullmatch(rb"[-+]?[0-9.]+(e[-+]?[0-9]+)?", tokens[t], re.I) else 1.0
    new = {
        "nan": b"nan",
        "inf": b"inf",
        "negative": repr(-abs(old) - 1.0).encode(),
        "zero": b"0",
        "word": b"abc",
        "huge": b"1e308",
    }[kind]
    invalid = key in READ_XML[fmt] and (
        kind in ("nan", "inf", "word")
        or (kind == "negative" and rule in (POS, NONNEG))
        or (kind == "zero" and rule == POS)
    )
    tokens[t] = new
    body = data[:start] + b" ".join(tokens) + data[end:]
    return Case(fmt, f"xml:{kind}@{key}", invalid, {**seed.files, name: body}, seed.main)


def _xml_structure(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    name = _pick_file(seed, rng)
    data = seed.files[name]
    kind = ["deep", "entity_bomb", "external_entity", "minmax", "drop_element", "unclosed"][int(rng.integers(6))]
    root_end = data.find(b">", data.find(b"<robot" if fmt != "world" else b"<world"))
    invalid = True
    if kind == "deep":
        depth = int(rng.integers(200, 20000))
        body = data[: root_end + 1] + b"<fuzz>" * depth + b"</fuzz>" * depth + data[root_end + 1 :]
        invalid = False
    elif kind in ("entity_bomb", "external_entity"):
        if kind == "entity_bomb":
            ents = ['<!ENTITY l0 "lol">'] + [f'<!ENTITY l{k} "{("&l" + str(k - 1) + ";") * 10}">' for k in range(1, 10)]
            use = b"&l9;"
        else:
            ents = ['<!ENTITY ext SYSTEM "file:///etc/passwd">']
            use = b"&ext;"
        tag = b"robot" if fmt != "world" else b"sdf"
        dtd = f"<!DOCTYPE {tag.decode()} [{''.join(ents)}]>\n".encode()
        decl_end = data.find(b"?>") + 2 if data.startswith(b"<?xml") else 0
        first = data.find(b"<" + tag)
        body = data[:decl_end] + b"\n" + dtd + data[decl_end:first]
        rest = data[first:]
        close = rest.find(b">")
        body += rest[: close + 1] + b"<!--" + b"-->" + use + rest[close + 1 :]
    elif kind == "minmax":
        m = re.search(rb"<min>\s*([-0-9.e]+)\s*</min>(\s*)<max>\s*([-0-9.e]+)\s*</max>", data)
        if m is None:
            return _xml_value(fmt, seed, rng)
        hi = float(m.group(3))
        body = (
            data[: m.start()]
            + f"<min>{hi + 1.0}</min>".encode()
            + m.group(2)
            + m.group(0)[m.group(0).find(b"<max>") :]
            + data[m.end() :]
        )
    elif kind == "drop_element":
        tags = [m for m in re.finditer(rb"<([A-Za-z_][\w]*)[^>/]*>[^<]*</\1>", data)]
        if not tags:
            return _text(fmt, seed, rng)
        m = tags[int(rng.integers(len(tags)))]
        body = data[: m.start()] + data[m.end() :]
        invalid = False
    else:
        body = data.replace(b"</robot>", b"").replace(b"</sdf>", b"")
    return Case(fmt, f"xml:{kind}", invalid, {**seed.files, name: body}, seed.main)


def _xacro(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    main = seed.main
    data = seed.files[main]
    close = data.rfind(b"</robot>")
    kind = [
        "code_import",
        "code_open",
        "code_subclass",
        "code_vars",
        "code_format",
        "load_yaml_outside",
        "include_outside",
        "self_include",
        "macro_recursion",
        "find_escape",
    ][int(rng.integers(10))]
    marker = "navlab_fuzz_escape_marker"
    snippets = {  # each evaluated where it stands (an unused xacro:property would never be evaluated)
        "code_import": f"<fuzz v=\"${{__import__('os').system('touch {marker}')}}\"/>",
        "code_open": f"<fuzz v=\"${{open('{marker}', 'w').write('x')}}\"/>",
        "code_subclass": (
            '<fuzz v="${[c for c in python.type(python.type).mro(python.type)[-1].'
            "__subclasses__() if c.__name__ == 'Popen'][0](['touch', '" + marker + "'])}\"/>"
        ),
        "code_vars": (
            "<fuzz v=\"${python.vars(python.type(python.vars(python.type(xacro.fatal))['__globals__']))"
            "['__get__'](python.vars(python.type(xacro.fatal))['__globals__'], xacro.fatal)['os']"
            f".system('touch {marker}')}}\"/>"
        ),
        "code_format": "<fuzz v=\"${'{0.__class__.__base__.__subclasses__}'.format(1)}\"/>",
        "load_yaml_outside": "<fuzz v=\"${xacro.load_yaml('/etc/passwd')}\"/>",
        "include_outside": '<xacro:include filename="/etc/hostname"/>',
        "self_include": f'<xacro:include filename="{main.rsplit("/", 1)[-1]}"/>',
        "macro_recursion": (
            '<xacro:macro name="fzr" params="n"><xacro:fzr n="${n+1}"/></xacro:macro><xacro:fzr n="0"/>'
        ),
        "find_escape": '<xacro:include filename="$(find navlab_tb3_burger_description)/../../../../etc/hostname"/>',
    }
    body = data[:close] + snippets[kind].encode() + b"\n" + data[close:]
    return Case(fmt, f"xacro:{kind}", True, {**seed.files, main: body}, main, {"marker": marker})


# --- CARMEN mutations --------------------------------------------------------------------------------------


def _carmen(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    lines = seed.files[seed.main].decode().split("\n")
    flaser = [i for i, ln in enumerate(lines) if ln.startswith("FLASER")]
    rl1 = [i for i, ln in enumerate(lines) if ln.startswith("ROBOTLASER1")]
    kind = [
        "count_minus",
        "count_plus",
        "rl1_count",
        "backwards",
        "huge_line",
        "nan_range",
        "word_field",
        "negative_count",
        "no_newline_giant",
    ][int(rng.integers(9))]
    i = flaser[int(rng.integers(len(flaser)))]
    tok = lines[i].split()
    if kind in ("count_minus", "count_plus"):
        tok[1] = str(int(tok[1]) + (-1 if kind == "count_minus" else 1))
    elif kind == "rl1_count":
        i = rl1[int(rng.integers(len(rl1)))]
        tok = lines[i].split()
        tok[8] = str(int(tok[8]) - 2)
    elif kind == "backwards":
        i = flaser[max(1, int(rng.integers(len(flaser))))]
        tok = lines[i].split()
        tok[-3] = tok[-1] = "50.0"
    elif kind == "huge_line":
        tok = ["FLASER", "2000000", *(["1.0"] * 2_000_000), *tok[-10:]]
    elif kind == "nan_range":
        tok[5] = "nan"
    elif kind == "word_field":
        tok[int(rng.integers(2, len(tok) - 3))] = "abc"
    elif kind == "negative_count":
        tok[1] = "-5"
    else:
        lines.append("FLASER 3 " + "1.0 " * 4_000_000)
        return Case(
            fmt, f"carmen:{kind}", True, {seed.main: "\n".join(lines).encode()}, seed.main, {"skipped_at_least": 1}
        )
    lines[i] = " ".join(tok)
    return Case(fmt, f"carmen:{kind}", True, {seed.main: "\n".join(lines).encode()}, seed.main, {"skipped_at_least": 1})


# --- map image mutations --------------------------------------------------------------------------------------


def _pgm(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    pgm = seed.files["map.pgm"]
    files = dict(seed.files)
    kind = [
        "p4",
        "bomb",
        "maxval_zero",
        "maxval_big",
        "truncated",
        "fifo",
        "dev_zero",
        "directory",
        "missing",
        "ascii_junk",
        "width_mismatch",
        "png_junk",
        "extra_data",
    ][int(rng.integers(13))]
    invalid = kind != "extra_data"
    head, _, _ = pgm.partition(b"255\n")
    body = pgm[len(head) + 4 :]
    if kind == "p4":
        files["map.pgm"] = b"P4" + pgm[2:]
    elif kind == "bomb":
        files["map.pgm"] = b"P5\n60000 60000\n255\n" + body
    elif kind == "maxval_zero":
        files["map.pgm"] = head + b"0\n" + body
    elif kind == "maxval_big":
        files["map.pgm"] = head + b"70000\n" + body
    elif kind == "truncated":
        files["map.pgm"] = pgm[: len(pgm) - int(rng.integers(1, len(body)))]
    elif kind == "fifo":
        files["map.pgm"] = FIFO
    elif kind == "dev_zero":
        files["map.pgm"] = LINK_PREFIX + b"/dev/zero"
    elif kind == "directory":
        files["map.yaml"] = files["map.yaml"].replace(b"image: map.pgm", b"image: .")
    elif kind == "missing":
        del files["map.pgm"]
    elif kind == "ascii_junk":
        files["map.pgm"] = b"P2\n3 2\n255\n1 2 x 4 5 6\n"
    elif kind == "width_mismatch":
        lines = head.split(b"\n")
        w, h = (int(v) for v in lines[-2].split())
        lines[-2] = f"{w + 1} {h}".encode()
        files["map.pgm"] = b"\n".join(lines) + b"255\n" + body
    elif kind == "png_junk":
        files["map.yaml"] = files["map.yaml"].replace(b"map.pgm", b"map.png")
        files["map.png"] = b"\x89PNG\r\n\x1a\n" + bytes(rng.integers(0, 256, 64, dtype=np.uint8))
    else:
        files["map.pgm"] = pgm + b"\x00" * 10
    return Case(fmt, f"pgm:{kind}", invalid, files, seed.main)


# --- the generator --------------------------------------------------------------------------------------------

Mutator = Callable[[str, Seed, np.random.Generator], Case]


def mutators(fmt: str) -> list[Mutator]:
    """The mutations that apply to ``fmt``, each drawn equally often."""
    out: list[Mutator] = [_text]
    if fmt in YAML_FORMATS:
        out += [_yaml_value, _yaml_value, _yaml_structure]
    if fmt == "launch":
        out += [_launch, _launch]
    if fmt in ("urdf", "world"):
        out += [_xml_value, _xml_value, _xml_structure]
    if fmt == "robot":
        out += [_xml_value, _xml_structure, _xacro, _xacro]
    if fmt == "carmen":
        out += [_carmen, _carmen]
    if fmt == "map":
        out += [_pgm, _pgm]
    from .mutate_nav import mutators_nav

    return mutators_nav(fmt) or out


def generate(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    """One malformed variant of ``seed`` (format ``fmt``), drawn with ``rng``."""
    options = mutators(fmt)
    case = options[int(rng.integers(len(options)))](fmt, copy.deepcopy(seed), rng)
    return case
