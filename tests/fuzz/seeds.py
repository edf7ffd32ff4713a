"""Valid seed inputs of every fuzzed format, built from navlab's shipped files (bytes per relative path)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

FORMATS = (
    "robot",
    "urdf",
    "world",
    "amcl",
    "gmapping",
    "move_base",
    "map",
    "carmen",
    "launch",
    "route",
    "scenario",
    "navparams",
    "goal",
    "bag",
    "barn",
    "slam",
)


@dataclass
class Seed:
    """A valid input: its files (relative path -> bytes) and the one the loader is given."""

    files: dict[str, bytes]
    main: str
    mutable: list[str] = field(default_factory=list)  # the files mutations may change (default: main)


def _resources() -> Path:
    from navlab import resources

    return resources.root()


def _robot() -> Seed:
    pkg = _resources() / "robots" / "tb3_burger"
    files = {f"tb3/{p.name}": p.read_bytes() for p in sorted(pkg.iterdir()) if p.is_file()}
    return Seed(files, "tb3/tb3_burger.xacro", ["tb3/tb3_burger.xacro", "tb3/macros.xacro", "tb3/tb3_burger.gazebo"])


def _urdf() -> Seed:
    from navlab.description import load_robot

    model = load_robot(_resources() / "robots" / "tb3_burger" / "tb3_burger.xacro")
    return Seed({"robot.urdf": model.urdf_xml.encode()}, "robot.urdf")


def _world() -> Seed:
    return Seed({"room.world": (_resources() / "worlds" / "room.world").read_bytes()}, "room.world")


def _param(name: str) -> Seed:
    files = {f"{name}.yaml": (_resources() / "params" / f"{name}.yaml").read_bytes()}
    if name == "amcl":  # amcl builds its filter on a map: a small valid one, served by map_server
        files.update({f"map/{k}": v for k, v in _map().files.items()})
    return Seed(files, f"{name}.yaml", [f"{name}.yaml"])


def _move_base() -> Seed:
    folder = _resources() / "params" / "mybot"
    files = {f"params/{p.name}": p.read_bytes() for p in sorted(folder.glob("*.yaml"))}
    mutable = [
        f"params/{n}"
        for n in (
            "costmap_common_params.yaml",
            "local_costmap_params.yaml",
            "global_costmap_params.yaml",
            "base_local_planner_params.yaml",
            "move_base_params.yaml",
        )
    ]
    return Seed(files, "params", mutable)


def _map() -> Seed:
    width, height = 24, 16
    pixels = bytearray([254] * (width * height))
    for x in range(width):
        pixels[x] = pixels[(height - 1) * width + x] = 0
    for y in range(height):
        pixels[y * width] = pixels[y * width + width - 1] = 0
    for k in range(40, 60):
        pixels[k] = 205
    pgm = f"P5\n# CREATOR: navlab fuzz\n{width} {height}\n255\n".encode() + bytes(pixels)
    yaml_text = (
        "image: map.pgm\nresolution: 0.050000\norigin: [-0.600000, -0.400000, 0.000000]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
    )
    return Seed({"map.yaml": yaml_text.encode(), "map.pgm": pgm}, "map.yaml", ["map.yaml", "map.pgm"])


def _carmen() -> Seed:
    lines = ["# navlab fuzz seed log", "PARAM robot_front_laser_max 81.9"]
    t = 100.0
    for k in range(6):
        x, th = 0.1 * k, 0.01 * k
        ranges = " ".join(f"{1.5 + 0.01 * ((k + j) % 7):.3f}" for j in range(181))
        lines.append(f"ODOM {x:.3f} 0.000 {th:.3f} 0.2 0.0 0.0 {t:.6f} host {t:.6f}")
        lines.append(
            f"FLASER 181 {ranges} {x:.3f} 0.000 {th:.3f} {x:.3f} 0.000 {th:.3f} {t + 0.01:.6f} host {t + 0.01:.6f}"
        )
        rl = " ".join(f"{2.0 + 0.01 * j % 3:.3f}" for j in range(90))
        lines.append(
            f"ROBOTLASER1 0 -1.5708 3.14159 0.0349 81.9 0.01 0 90 {rl} 0 {x + 0.1:.3f} 0.000 {th:.3f} "
            f"{x:.3f} 0.000 {th:.3f} 0.2 0.0 0.0 0.0 0.0 {t + 0.02:.6f} host {t + 0.02:.6f}"
        )
        t += 0.5
    return Seed({"log.clf": ("\n".join(lines) + "\n").encode()}, "log.clf")


_LAUNCH_MAIN = """\
# fuzz seed: every launch entry kind
launch:
- arg: {name: rate, default: "5.0", description: "talker rate in Hz"}
- arg: {name: talk, default: "true"}
- let: {name: topic, value: chatter}
- include:
    file: talkers.launch.yaml
    arg:
    - {name: rate, value: "$(var rate)"}
    - {name: ns, value: "$(env NAVLAB_FUZZ_NS robots)"}
- node:
    if: "$(var talk)"
    pkg: navlab
    exec: talker
    name: talker
    param: [{name: rate, value: "$(var rate)"}, {from: talker.yaml}]
    remap: [{from: chatter, to: "$(var topic)"}]
- node:
    unless: "false"
    pkg: navlab
    exec: listener
    name: listener
    remap: [{from: chatter, to: "$(var topic)"}]
"""

_LAUNCH_INCLUDED = """\
launch:
- arg: {name: rate, default: "1.0"}
- arg: {name: ns, default: ""}
- node: {pkg: navlab, exec: talker, name: talker2, namespace: "$(var ns)", param: [{name: rate, value: "$(var rate)"}]}
"""


def _launch() -> Seed:
    return Seed(
        {
            "main.launch.yaml": _LAUNCH_MAIN.encode(),
            "talkers.launch.yaml": _LAUNCH_INCLUDED.encode(),
            "talker.yaml": b"rate: 2.0\n",
        },
        "main.launch.yaml",
        ["main.launch.yaml", "talkers.launch.yaml", "talker.yaml"],
    )


def _route() -> Seed:
    text = (
        "segments:\n  - {linear: 0.0, angular: 0.8, duration: 8.0}\n  - {linear: 0.2, angular: 0.0, "
        "duration: 2.5}\nwaypoints:\n  - [1.2, -1.0]\n  - [-1.5, -0.9]\n  - [0.0, 0.0]\n"
    )
    return Seed({"route.yaml": text.encode()}, "route.yaml")


def _scenario() -> Seed:
    return Seed(
        {"scenario.yaml": (_resources() / "scenarios" / "obstacles_after_mapping.yaml").read_bytes()}, "scenario.yaml"
    )


def _goal() -> Seed:
    return Seed({"run.json": b'["sim", "--duration", "0.2", "--quiet", "--json"]'}, "run.json")


def _bag() -> Seed:
    """A small navlab recording (two topics, its node graph) with the user's other files beside it."""
    import tempfile

    from navlab.io.rosbag import GRAPH_KEY, BagWriter
    from navlab.msgs import TYPESTORE

    string_t, time_t = TYPESTORE.types["std_msgs/msg/String"], TYPESTORE.types["builtin_interfaces/msg/Time"]
    clock_t = TYPESTORE.types["rosgraph_msgs/msg/Clock"]
    with tempfile.TemporaryDirectory() as tmp:
        with BagWriter(Path(tmp) / "rec") as bag:
            for k in range(300):
                bag.write("/chatter", string_t(f"hello {k}"), k * 10_000_000)
                bag.write("/clock", clock_t(time_t(sec=k // 100, nanosec=k % 100 * 10_000_000)), k * 10_000_000)
            bag.set_custom_data(
                GRAPH_KEY, '{"nodes": ["/talker"], "topics": {"/chatter": {"pub": ["/talker"], "sub": []}}}'
            )
        files = {f"rec/{p.name}": p.read_bytes() for p in (Path(tmp) / "rec").iterdir()}
    files.update({"rec/notes.txt": b"my notes", "rec/other/data.txt": b"other data"})
    return Seed(files, "rec", ["rec/rec.mcap", "rec/metadata.yaml"])


def _barn() -> Seed:
    """A BARN-size world (navlab world clutter: about 200 cylinders and the walls)."""
    import tempfile

    from navlab.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        import contextlib
        import io

        with contextlib.redirect_stdout(io.StringIO()):
            main(["world", "clutter", "--seed", "3", "--fill", "0.3", "--smooth", "2", "--out", tmp])
        return Seed({"barn.world": (Path(tmp) / "clutter.world").read_bytes()}, "barn.world")


def build_seeds() -> dict[str, Seed]:
    """One valid seed per format in :data:`FORMATS`."""
    return {
        "robot": _robot(),
        "urdf": _urdf(),
        "world": _world(),
        "amcl": _param("amcl"),
        "gmapping": _param("gmapping"),
        "move_base": _move_base(),
        "map": _map(),
        "carmen": _carmen(),
        "launch": _launch(),
        "route": _route(),
        "scenario": _scenario(),
        "navparams": _move_base(),
        "goal": _goal(),
        "bag": _bag(),
        "barn": _barn(),
        "slam": _carmen(),
    }
