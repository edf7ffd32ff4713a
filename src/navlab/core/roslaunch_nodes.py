"""The nodes of a ROS 1 launch configuration mapped to navlab's: :class:`NodeSpec` for the nodes navlab
implements, processes for the others (with the ROS bridge on), notes for what is covered or skipped.

=====================================  ====================================================================
ROS 1 node (pkg/type)                  navlab
=====================================  ====================================================================
gazebo_ros/gzserver (empty_world)      ``gazebo`` with the world of its arguments (``worlds/empty.world``
                                       is navlab's empty world) and the robot of ``spawn_model``
gazebo_ros/spawn_model                 the robot of ``gazebo``: ``-urdf -param NAME`` (a xacro ``command``
                                       or ``textfile`` parameter) or ``-file F``, ``-x -y -z -Y``
gazebo_ros/gzclient, rviz/rviz         navlab's viewer (``--view``); with the ROS bridge on, rviz runs
robot_state_publisher,                 covered by ``gazebo`` (it publishes /joint_states and the robot's tf)
joint_state_publisher(_gui)
gmapping/slam_gmapping                 ``slam_gmapping``
map_server/map_server, map_saver       ``map_server`` (the map YAML argument), ``map_saver`` (``-f NAME``)
amcl/amcl, move_base/move_base         ``amcl``, ``move_base``
teleop_twist_keyboard                  ``teleop_twist_keyboard``
navlab/NAME                            the navlab node NAME (``explore``, ``route_follower``, ...)
=====================================  ====================================================================
"""

from __future__ import annotations

import logging
import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.core.errors import LaunchError
from navlab.core.launch import NodeSpec, Session, start_node
from navlab.core.roslaunch import RosConfig, RosNode, load, ns_join

#: (pkg, type) -> navlab node executable, for nodes whose private parameters pass through unchanged
DIRECT: dict[tuple[str, str], str] = {
    ("gmapping", "slam_gmapping"): "slam_gmapping",
    ("amcl", "amcl"): "amcl",
    ("move_base", "move_base"): "move_base",
    ("teleop_twist_keyboard", "teleop_twist_keyboard.py"): "teleop_twist_keyboard",
    ("teleop_twist_keyboard", "teleop_twist_keyboard"): "teleop_twist_keyboard",
}
GAZEBO = {("gazebo_ros", "gzserver"), ("gazebo_ros", "debug"), ("gazebo_ros", "gazebo")}
COVERED = {
    ("robot_state_publisher", "robot_state_publisher"): "navlab's gazebo node publishes the robot's tf",
    ("robot_state_publisher", "state_publisher"): "navlab's gazebo node publishes the robot's tf",
    ("joint_state_publisher", "joint_state_publisher"): "navlab's gazebo node publishes /joint_states",
    ("joint_state_publisher_gui", "joint_state_publisher_gui"): "navlab's gazebo node publishes /joint_states",
}
VIEWERS = {("gazebo_ros", "gzclient"), ("rviz", "rviz")}
_SPAWN_FLOATS = {"-x": "x", "-y": "y", "-z": "z", "-R": "roll", "-P": "pitch", "-Y": "yaw"}


@dataclass
class Plan:
    """What to start: navlab nodes in launch order, processes, and what to tell the user (``notes``: what
    navlab covers another way, logged as info; ``warnings``: what does not run)."""

    nodes: list[NodeSpec] = field(default_factory=list)
    processes: list[RosNode] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def _remaps(node: RosNode) -> dict[str, str]:
    return dict(node.remaps)


def _spawn_robot(config: RosConfig, node: RosNode) -> dict[str, Any]:
    """gazebo's ``robot``/``robot_args``/pose parameters from a ``spawn_model`` node's arguments."""
    try:
        words = shlex.split(node.args)
    except ValueError as exc:
        raise LaunchError(f"{node.where}: args {node.args!r}: {exc}") from None
    out: dict[str, Any] = {}
    i = 0
    while i < len(words):
        flag = words[i]
        value = words[i + 1] if i + 1 < len(words) else None
        if flag in _SPAWN_FLOATS or flag in (
            "-param",
            "-file",
            "-model",
            "-robot_namespace",
            "-gazebo_namespace",
            "-reference_frame",
            "-database",
        ):
            if value is None:
                raise LaunchError(f"{node.where}: spawn_model {flag} needs a value")
            if flag in _SPAWN_FLOATS:
                try:
                    out[_SPAWN_FLOATS[flag]] = float(value)
                except ValueError:
                    raise LaunchError(f"{node.where}: spawn_model {flag} {value!r}: expected a number") from None
            elif flag == "-param":
                name = ns_join(node.namespace, value)
                if name not in config.sources:
                    raise LaunchError(
                        f"{node.where}: spawn_model -param {value}: parameter {name!r} was not set "
                        'from a file (expected <param name=... command="xacro FILE"> or textfile=)'
                    )
                path, xargs = config.sources[name]
                out["robot"] = str(path)
                out["robot_args"] = [f"{k}:={v}" for k, v in xargs.items()]
            elif flag == "-file":
                out["robot"] = value
            elif flag == "-database":
                raise LaunchError(
                    f"{node.where}: spawn_model -database {value}: navlab spawns robots from -file or "
                    "-param (a URDF/xacro)"
                )
            i += 2
            continue
        if flag == "-sdf":
            raise LaunchError(
                f"{node.where}: spawn_model -sdf: navlab spawns a robot from a URDF (-urdf); put "
                "static SDF models in the .world file"
            )
        if flag == "-J":  # -J JOINT POSITION
            i += 3
            continue
        i += 1  # -urdf, -unpause, -wait ... change nothing here
    if "robot" not in out:
        raise LaunchError(f"{node.where}: spawn_model needs -param NAME or -file FILE")
    return out


def _gazebo_world(node: RosNode) -> tuple[str, bool]:
    """The world file of a gzserver command line, and whether it starts paused (``-u``)."""
    words = shlex.split(node.args)
    worlds = [w for w in words if w.endswith((".world", ".sdf"))]
    world = worlds[-1] if worlds else "worlds/empty.world"
    if not Path(world).is_absolute() and not Path(world).is_file() and world.startswith("worlds/"):
        world = Path(world).stem  # Gazebo's own worlds/NAME.world: navlab's shipped world NAME
    return world, "-u" in words


def plan(config: RosConfig, *, ros: bool) -> Plan:
    """Map ``config``'s nodes to navlab's; with ``ros`` other nodes become processes, else notes."""
    out = Plan(warnings=list(config.notes))
    gazebo: NodeSpec | None = None
    spawns: list[RosNode] = []
    for node in config.nodes:
        key = (node.pkg, node.type)
        params = config.params_under(node.fqn)
        files = config.files_under(node.fqn)  # unknown keys are reported naming the file that set them
        origin = f"{node.where} ({node.pkg}/{node.type})"
        if key in GAZEBO:
            if gazebo is not None:
                raise LaunchError(f"{node.where}: a second Gazebo server; navlab runs one world per launch")
            world, paused = _gazebo_world(node)
            if paused:
                out.warnings.append(
                    f"{node.where}: paused:=true: navlab's simulation starts running (time still "
                    "advances only as the launch runs)"
                )
            gazebo = NodeSpec("gazebo", node.name, node.namespace, {"world": world}, _remaps(node), origin)
            out.nodes.append(gazebo)
        elif key == ("gazebo_ros", "spawn_model"):
            spawns.append(node)
        elif key in DIRECT:
            out.nodes.append(NodeSpec(DIRECT[key], node.name, node.namespace, params, _remaps(node), origin, files))
        elif key == ("map_server", "map_server"):
            words = shlex.split(node.args)
            if words:
                params = {**params, "yaml_filename": words[0]}
            out.nodes.append(NodeSpec("map_server", node.name, node.namespace, params, _remaps(node), origin, files))
        elif key == ("map_server", "map_saver"):
            out.nodes.append(
                NodeSpec("map_saver", node.name, node.namespace, {**params, **_saver_args(node)}, _remaps(node), origin)
            )
        elif node.pkg == "navlab":
            out.nodes.append(NodeSpec(node.type, node.name, node.namespace, params, _remaps(node), origin, files))
        elif key in COVERED:
            out.notes.append(f"{node.where}: {node.pkg}/{node.type}: {COVERED[key]}")
        elif key in VIEWERS and not (ros and key == ("rviz", "rviz")):
            out.notes.append(f"{node.where}: {node.pkg}/{node.type}: navlab's viewer shows the run (add --view)")
        elif ros:
            out.processes.append(node)
        else:
            out.warnings.append(
                f"{node.where}: node {node.fqn!r} ({node.pkg}/{node.type}) is not one navlab runs; "
                "with the ROS bridge on (ros:=true) it is started as a process"
            )
    if spawns:
        if gazebo is None:
            raise LaunchError(
                f"{spawns[0].where}: spawn_model needs a Gazebo server in the launch (include "
                "gazebo_ros empty_world.launch)"
            )
        if len(spawns) > 1:
            raise LaunchError(
                f"{spawns[1].where}: navlab simulates one robot per world (already spawned by {spawns[0].where})"
            )
        robot = _spawn_robot(config, spawns[0])
        gazebo.params.update({k: v for k, v in robot.items() if k in ("robot", "robot_args", "x", "y", "yaw")})
    elif gazebo is not None:
        raise LaunchError(
            f"{gazebo.origin}: the world has no robot; navlab's gazebo needs one (spawn it with "
            "gazebo_ros spawn_model -urdf -param robot_description)"
        )
    return out


def _saver_args(node: RosNode) -> dict[str, Any]:
    """map_saver's ``-f NAME``, ``--occ``, ``--free`` as navlab map_saver parameters."""
    words = shlex.split(node.args)
    out: dict[str, Any] = {}
    flags = {"-f": "map_file", "--occ": "threshold_occupied", "--free": "threshold_free"}
    for i, word in enumerate(words):
        if word in flags and i + 1 < len(words):
            value: Any = words[i + 1]
            out[flags[word]] = value if word == "-f" else int(value)
    return out


def start_xml(session: Session, files: list[Path], args: dict[str, str], *, ros: bool, seed: int) -> None:
    """ROS 1 XML launch files: read as roslaunch does, then the known nodes started as navlab nodes (in
    file order) and, with ``ros``, the others as processes."""
    config = load(files, args, seed=seed, allow_commands=ros)
    todo = plan(config, ros=ros)
    log = logging.getLogger("navlab.launch")
    for note in todo.notes:
        log.info(note)
    for warning in todo.warnings:
        log.warning(warning)
    session.notes = todo.notes + todo.warnings
    session.params = config.params
    for spec in todo.nodes:
        start_node(session, spec)
    if todo.processes:
        from navlab.core.processes import ProcessGroup

        ex = session.executor

        def required_exit(why: str) -> None:  # roslaunch: a required process that dies ends the launch
            log.error(why)
            ex.post(ex.stop)

        group = ProcessGroup(on_required_exit=required_exit)
        session.processes = group
        try:
            for node in todo.processes:
                group.start(node)
                log.info(f"process[{node.fqn}]: started ({node.pkg}/{node.type})")
        except LaunchError:
            group.stop()
            raise
