"""Malformed variants of the inputs that arrived with navigation and recording (issue 21): navigation parameters
(sizes that exhaust memory or time, per local planner), goals, start poses and spawns (as `navlab sim` and
`navlab navigate` arguments), rosbag2 recordings, BARN-size worlds (nesting, include cycles) and CARMEN logs
run through gmapping SLAM (wild and overflowing poses).

Each returns a :class:`Case`; ``invalid`` is True only when the input is wrong by construction.
"""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np
import yaml

from .mutate import (
    FIFO,
    LINK_PREFIX,
    NONNEG,
    POS,
    RULES,
    Case,
    _carmen,
    _dump,
    _text,
    _xml_structure,
    _xml_value,
    _yaml_value,
)
from .seeds import Seed

PLANNERS = {
    "trajectory": "base_local_planner/TrajectoryPlannerROS",
    "dwa": "dwa_local_planner/DWAPlannerROS",
    "mppi": "nav2_mppi_controller::MPPIController",
}
SECTION = {"trajectory": "TrajectoryPlannerROS", "dwa": "DWAPlannerROS", "mppi": "MPPIController"}
# (file, section or None, key, value, invalid): sizes that exhaust memory or time, and malformed shapes
_SIZES: list[tuple[str, str | None, str, object, bool]] = [
    ("local_costmap_params.yaml", "local_costmap", "width", 1e6, True),
    ("local_costmap_params.yaml", "local_costmap", "resolution", 1e-6, True),
    ("local_costmap_params.yaml", "local_costmap", "update_frequency", 1e9, True),
    ("global_costmap_params.yaml", "global_costmap", "publish_frequency", 1e9, True),
    ("costmap_common_params.yaml", None, "footprint", [[1e6, 1e6], [1e6, -1e6], [-1e6, 0.0]], True),
    ("costmap_common_params.yaml", None, "footprint", [[0.1, 0.1]], True),
    ("costmap_common_params.yaml", None, "footprint", "[[0.2, 0.2], [0.2, -0.2]", True),
    (
        "costmap_common_params.yaml",
        None,
        "footprint",
        [[float(0.3 * np.cos(a)), float(0.3 * np.sin(a))] for a in np.linspace(0, 6.28, 5000)],
        True,
    ),
    ("costmap_common_params.yaml", None, "robot_radius", 1e9, True),
    ("costmap_common_params.yaml", None, "inflation_radius", 1e6, False),  # large, but bounded by the grid
    ("costmap_common_params.yaml", None, "raytrace_range", 1e12, False),
    ("move_base_params.yaml", None, "controller_frequency", 1e9, True),
    ("move_base_params.yaml", None, "planner_frequency", 1e9, True),
]
_PLANNER_SIZES: dict[str, list[tuple[str, object]]] = {
    "trajectory": [("vx_samples", 10**9), ("vtheta_samples", 10**9), ("sim_granularity", 1e-12), ("sim_time", 1e9)],
    "dwa": [
        ("vx_samples", 10**9),
        ("vth_samples", 10**9),
        ("sim_granularity", 1e-12),
        ("angular_sim_granularity", 1e-12),
        ("sim_time", 1e9),
    ],
    "mppi": [("batch_size", 10**9), ("time_steps", 10**9), ("iteration_count", 10**9)],
}


def _select(files: dict[str, bytes], planner: str) -> None:
    doc = yaml.safe_load(files["params/move_base_params.yaml"])
    doc["base_local_planner"] = PLANNERS[planner]
    files["params/move_base_params.yaml"] = _dump(doc)


def _nav_size(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    planner = list(PLANNERS)[int(rng.integers(len(PLANNERS)))]
    files = dict(seed.files)
    _select(files, planner)
    options = _SIZES + [
        ("base_local_planner_params.yaml", SECTION[planner], k, v, True) for k, v in _PLANNER_SIZES[planner]
    ]
    name, section, key, value, invalid = options[int(rng.integers(len(options)))]
    path = f"params/{name}"
    doc = yaml.safe_load(files[path])
    (doc[section] if section else doc)[key] = value
    files[path] = _dump(doc)
    return Case(fmt, f"nav:{planner}:{key}={str(value)[:20]}", invalid, files, seed.main)


def _nav_planner(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    """A bad value inside the section of the local planner the case selects (so the planner reads it)."""
    planner = list(PLANNERS)[int(rng.integers(len(PLANNERS)))]
    files = dict(seed.files)
    _select(files, planner)
    path = "params/base_local_planner_params.yaml"
    doc = yaml.safe_load(files[path])
    section = doc[SECTION[planner]]
    keys = [k for k, v in section.items() if isinstance(v, int | float) and not isinstance(v, bool)]
    key = keys[int(rng.integers(len(keys)))]
    kind = ["nan", "inf", "negative", "zero", "string", "huge"][int(rng.integers(6))]
    rule = RULES["move_base"].get(key)
    section[key] = {
        "nan": float("nan"),
        "inf": float("inf"),
        "negative": -abs(section[key]) - 1.0,
        "zero": 0,
        "string": "fast",
        "huge": 1e308,
    }[kind]
    invalid = (
        kind in ("nan", "inf", "string")
        or (kind == "negative" and rule in (POS, NONNEG))
        or (kind == "zero" and rule == POS)
    )
    files[path] = _dump(doc)
    return Case(fmt, f"nav:{planner}:{kind}@{key}", invalid, files, seed.main)


# --- goals, start poses, spawns (command-line arguments) -------------------------------------------------

_BAD_NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "abc", ""]
_SIM = ["sim", "--duration", "0.2", "--quiet", "--json"]


def _goal(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    kind = ["start", "spawn_size", "spawn_place", "spawn_time", "spawn_on_robot", "goal", "goal_far"][
        int(rng.integers(7))
    ]
    bad = _BAD_NUMBERS[int(rng.integers(len(_BAD_NUMBERS)))]
    invalid = True
    names = []
    if kind == "start":
        opt = ["--x", "--y", "--yaw"][int(rng.integers(3))]
        argv, names = [*_SIM, opt, bad], [opt, opt.lstrip("-")]
    elif kind.startswith("spawn"):
        shape = ["sphere", "box", "cylinder"][int(rng.integers(3))]
        size_key = {"sphere": "radius", "box": "size", "cylinder": "radius"}[shape]
        spec = {"x": "1.5", "y": "0.5", size_key: "0.2", "t": "0.1"}
        if kind == "spawn_size":
            spec[size_key] = bad if rng.random() < 0.7 else ["-1", "0", "1e9"][int(rng.integers(3))]
        elif kind == "spawn_place":
            spec[["x", "y", "z", "yaw"][int(rng.integers(4))]] = bad
        elif kind == "spawn_time":
            spec["t"] = bad = [*_BAD_NUMBERS, "-5"][int(rng.integers(len(_BAD_NUMBERS) + 1))]
        else:
            spec.update(x="0", y="0", t=["0", "0.1"][int(rng.integers(2))])  # a cylinder where the robot stands
        text = f"{shape}:" + ",".join(f"{k}={v}" for k, v in spec.items())
        argv, names = [*_SIM, "--spawn", text], ["spawn", text]
    elif kind == "goal":
        goal = ["0.5", "0", "0"]
        goal[int(rng.integers(3))] = bad
        argv, names = ["navigate", "--goal", *goal, "--timeout", "1", "--json"], ["--goal", "goal"]
    else:
        argv, names = ["navigate", "--goal", "900000", "-900000.0", "0", "--timeout", "1", "--json"], ["goal"]
        invalid = False  # a goal off the map is move_base's to abort, not the command line's to refuse
    return Case(
        fmt, f"goal:{kind}:{bad}", invalid, {"run.json": json.dumps(argv).encode()}, seed.main, {"names": names}
    )


# --- rosbag2 recordings -------------------------------------------------------------------------------------


def _bag(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    files = dict(seed.files)
    mcap, meta = "rec/rec.mcap", "rec/metadata.yaml"
    kind = [
        "flip",
        "truncate",
        "zeros",
        "fifo",
        "dev_zero",
        "outside",
        "meta_value",
        "meta_delete",
        "no_meta",
        "graph_garbage",
        "compression",
        "chunk_size",
        "splice",
    ][int(rng.integers(13))]
    data = bytearray(files[mcap])
    invalid = kind in ("fifo", "dev_zero", "outside", "graph_garbage", "compression")
    if kind == "flip":
        for _ in range(int(rng.integers(1, 20))):
            data[int(rng.integers(8, len(data)))] ^= int(rng.integers(1, 256))
        files[mcap] = bytes(data)
    elif kind == "truncate":
        files[mcap] = bytes(data[: int(rng.integers(0, len(data)))])
    elif kind == "zeros":
        k = int(rng.integers(8, len(data)))
        data[k : k + int(rng.integers(1, 400))] = b"\x00" * len(data[k : k + 400])
        files[mcap] = bytes(data[: len(files[mcap])])
    elif kind == "fifo":
        files[mcap] = FIFO
    elif kind == "dev_zero":
        files[mcap] = LINK_PREFIX + b"/dev/zero"
    elif kind == "outside":
        files[meta] = files[meta].replace(b"- rec.mcap", b"- ../../../../../dev/zero")
    elif kind == "meta_value":
        case = _yaml_value(fmt, Seed(files, seed.main, [meta]), rng)
        files = case.files
    elif kind == "meta_delete":
        doc = yaml.safe_load(files[meta])
        info = doc["rosbag2_bagfile_information"]
        del info[list(info)[int(rng.integers(len(info)))]]
        files[meta] = _dump(doc)
    elif kind == "no_meta":
        del files[meta]
    elif kind == "graph_garbage":
        doc = yaml.safe_load(files[meta])
        doc["rosbag2_bagfile_information"]["custom_data"] = {
            "navlab.graph": ['{"nodes": 5}', "[1, 2", "null"][int(rng.integers(3))]
        }
        invalid = doc["rosbag2_bagfile_information"]["custom_data"]["navlab.graph"] != "null"
        files[meta] = _dump(doc)
    elif kind == "compression":
        files[mcap] = (
            bytes(data).replace(b"\x04\x00\x00\x00zstd", b"\x04\x00\x00\x00zzzz")
            if b"zstd" in data
            else bytes(data).replace(b"\x00\x00\x00\x00\x00\x00\x00\x00", b"\xff" * 8, 3)
        )
        invalid = b"zstd" in data
    elif kind == "chunk_size":
        k = data.find(b"\x06", 8)  # the first chunk record: claim an enormous uncompressed size
        if k > 0:
            data[k + 25 : k + 33] = (2**62).to_bytes(8, "little")
        files[mcap] = bytes(data)
    else:
        k = int(rng.integers(8, len(data)))
        files[mcap] = bytes(data[:k] + data[k:][::-1])
    return Case(
        fmt,
        f"bag:{kind}",
        invalid,
        files,
        seed.main,
        {"keep": {"rec/notes.txt": "my notes", "rec/other/data.txt": "other data"}},
    )


# --- BARN-size worlds ----------------------------------------------------------------------------------------


def _world_nesting(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    files = dict(seed.files)
    data = files[seed.main]
    close = data.rfind(b"</world>")
    kind = ["nested_models", "include_cycle", "include_self", "many_models", "huge_geometry"][int(rng.integers(5))]
    invalid = True
    if kind == "nested_models":
        depth = int(rng.integers(50, 3000))
        body = b"<model name='m'><static>true</static>" * depth + b"<link name='l'/>" + b"</model>" * depth
    elif kind in ("include_cycle", "include_self"):
        other = "b" if kind == "include_cycle" else "a"
        files["models/a/model.config"] = b"<?xml version='1.0'?><model><name>a</name><sdf>model.sdf</sdf></model>"
        files["models/a/model.sdf"] = (
            f"<?xml version='1.0'?><sdf version='1.6'><model name='a'><include><uri>"
            f"model://{other}</uri></include><link name='l'/></model></sdf>"
        ).encode()
        files["models/b/model.config"] = b"<?xml version='1.0'?><model><name>b</name><sdf>model.sdf</sdf></model>"
        files["models/b/model.sdf"] = (
            b"<?xml version='1.0'?><sdf version='1.6'><model name='b'><include><uri>"
            b"model://a</uri></include><link name='l'/></model></sdf>"
        )
        body = b"<include><uri>model://a</uri></include>"
    elif kind == "many_models":
        n = int(rng.integers(2000, 20000))
        body = b"".join(
            b"<model name='c%d'><static>true</static><pose>%d 0 0 0 0 0</pose><link name='l'><collision "
            b"name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision></link>"
            b"</model>" % (k, k % 50)
            for k in range(n)
        )
        invalid = False
    else:
        body = (
            b"<model name='big'><static>true</static><link name='l'><collision name='c'><geometry><box><size>"
            b"1e300 1e300 1</size></box></geometry></collision></link></model>"
        )
    files[seed.main] = data[:close] + body + data[close:]
    return Case(fmt, f"world:{kind}", invalid, files, seed.main, {"model_path": "models"})


# --- CARMEN logs through SLAM ------------------------------------------------------------------------------------


def _slam_pose(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
    lines = seed.files[seed.main].decode().split("\n")
    scans = [i for i, ln in enumerate(lines) if ln.startswith("FLASER")]
    i = scans[int(rng.integers(len(scans)))]
    tok = lines[i].split()
    kind = ["wild", "overflow", "far_all", "range_huge"][int(rng.integers(4))]
    n = int(tok[1])
    if kind == "wild":
        tok[2 + n] = tok[5 + n] = repr(float(rng.choice([1e4, -5e5, 9e5])))
    elif kind == "overflow":
        tok[2 + n] = tok[5 + n] = "1e308"
    elif kind == "range_huge":
        tok[2 + int(rng.integers(n))] = "1e300"
    else:  # every pose far away: a consistent log, just not at the origin
        for j in scans:
            t = lines[j].split()
            t[2 + n] = t[5 + n] = repr(float(t[2 + n]) + 5e4)
            lines[j] = " ".join(t)
        return Case(fmt, f"slam:{kind}", False, {seed.main: "\n".join(lines).encode()}, seed.main)
    lines[i] = " ".join(tok)
    return Case(fmt, f"slam:{kind}", True, {seed.main: "\n".join(lines).encode()}, seed.main, {"skipped_at_least": 1})


def _as(base: str, mutator: Callable[[str, Seed, np.random.Generator], Case]) -> Callable[..., Case]:
    """``mutator`` with the rules of format ``base`` (a BARN world is a world, a SLAM log a CARMEN log)."""

    def run(fmt: str, seed: Seed, rng: np.random.Generator) -> Case:
        case = mutator(base, seed, rng)
        case.fmt = fmt
        return case

    return run


def mutators_nav(fmt: str) -> list[Callable[[str, Seed, np.random.Generator], Case]]:
    """The mutations of the formats this module adds."""
    return {
        "navparams": [_nav_size, _nav_size, _nav_planner, _text],
        "goal": [_goal],
        "bag": [_bag],
        "barn": [
            _world_nesting,
            _world_nesting,
            _as("world", _xml_value),
            _as("world", _xml_structure),
            _as("world", _text),
        ],
        "slam": [_slam_pose, _slam_pose, _as("carmen", _carmen), _as("carmen", _text)],
    }.get(fmt, [])
