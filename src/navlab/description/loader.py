"""``load_robot``: a xacro/URDF file with ``<gazebo>`` tags → :class:`RobotModel`."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping
from pathlib import Path

from navlab import resources
from navlab.description.errors import DescriptionError
from navlab.description.gazebo import check_plugin_joints, read_gazebo_tags
from navlab.description.meshes import prepare_mesh, up_axis_warning
from navlab.description.model import RobotModel
from navlab.description.packages import PackageIndex
from navlab.description.urdf import parse_urdf
from navlab.description.xacro import expand


def _moving_mass_check(model: RobotModel, source: str) -> None:
    """Every moving body (root or child of a non-fixed joint) needs mass, counting fixed children.

    MuJoCo (like Gazebo) cannot simulate a body with zero mass on a joint, so a moving link with no
    ``<inertial>`` (and no massive link fixed to it) is an error naming that link.
    """
    fixed_children: dict[str, list[str]] = {}
    moving = {model.root_link}
    for j in model.joints:
        if j.type == "fixed":
            fixed_children.setdefault(j.parent, []).append(j.child)
        else:
            moving.add(j.child)

    def mass(link: str) -> float:
        inertial = model.links[link].inertial
        own = inertial.mass if inertial is not None else 0.0
        return own + sum(mass(c) for c in fixed_children.get(link, []))

    for link in sorted(moving):
        if mass(link) <= 0.0:
            how = "the root link (it floats freely)" if link == model.root_link else "on a moving joint"
            raise DescriptionError(
                f'{source}: <link name="{link}"> is {how} but has no <inertial> with mass > 0 (nor a '
                "massive link fixed to it); add <inertial><mass value=.../><inertia .../></inertial>"
            )


def robot_path(name_or_path: str | os.PathLike[str], search_paths: Iterable[str | os.PathLike[str]] = ()) -> Path:
    """The description file a shipped name (``mybot``), a ``package://pkg/urdf/x.xacro`` URI (found
    through ``search_paths`` and ``ROS_PACKAGE_PATH``), a ``file://`` URI or a path names."""
    text = str(name_or_path).strip()
    if text.startswith(("package://", "file://")):
        return PackageIndex(search_paths).resolve_uri(text, base_dir=Path.cwd()).expanduser().resolve()
    path = Path(text).expanduser()
    if not path.exists() and not path.suffix and "/" not in text:
        return resources.robot(text)  # ResourceError lists the shipped robots
    return path.resolve()


def load_robot(
    path: str | os.PathLike[str],
    *,
    search_paths: Iterable[str | os.PathLike[str]] = (),
    args: Mapping[str, str] | None = None,
) -> RobotModel:
    """Load a robot description (``.xacro`` or ``.urdf``: a path, ``package://pkg/...`` or a shipped
    name, see :func:`robot_path`) with its Gazebo plugin tags.

    ``search_paths``: directories holding ROS packages (or package directories) for ``$(find pkg)``
    and ``package://pkg/...``; ``ROS_PACKAGE_PATH``, the packages enclosing ``path`` and navlab's
    shipped packages (``mybot_description``) are searched after them. ``args``: xacro arguments
    (``name:=value``). Raises DescriptionError naming the file and element on bad input; unknown
    plugins, sensors and tags become ``RobotModel.warnings``.
    """
    search_paths = list(search_paths)
    path = robot_path(path, search_paths)
    index = PackageIndex(search_paths, near=path)
    urdf_xml, warnings = expand(path, index, args)
    warnings = list(warnings)
    source = str(path)
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:  # pragma: no cover - xacro already parsed it
        raise DescriptionError(f"{source}: expanded URDF is not XML ({exc})") from None

    def resolve_mesh(filename: str, where: str) -> tuple[Path, float, Path]:
        try:
            named = index.resolve_uri(filename, base_dir=path.parent)
        except DescriptionError as exc:
            raise type(exc)(f"{where}: {exc}") from None
        sim_path, unit = prepare_mesh(named, where)
        warning = up_axis_warning(named, where)
        if warning:
            warnings.append(warning)
        return sim_path, unit, named

    name, links, joints, root_link = parse_urdf(root, source, resolve_mesh, warnings=warnings)
    model = RobotModel(
        name=name, links=links, joints=joints, root_link=root_link, source=path, urdf_xml=urdf_xml, warnings=warnings
    )
    _moving_mass_check(model, source)
    tags = read_gazebo_tags(root, links, {j.name for j in joints}, source)
    parent_joint = {j.child: j.name for j in joints}
    chain = {j.name: (parent_joint.get(j.parent, ""), j.origin) for j in joints}
    check_plugin_joints(tags, {j.name: j.type for j in joints}, links, source, chain)
    model.diff_drive = tags.diff_drive
    model.ros_control = tags.ros_control
    model.lidars = tags.lidars
    model.imus = tags.imus
    model.ground_truths = tags.ground_truths
    model.sensors = tags.sensors
    model.warnings += tags.warnings
    if model.diff_drive is None and model.ros_control is None:
        model.warnings.append(f"{source}: no libgazebo_ros_diff_drive.so plugin; cmd_vel will not move the robot")
    return model


def load_robot_named(name_or_path: str, args: list[str] | None = None) -> RobotModel:
    """A robot from a shipped name (``mybot``), a ``package://`` URI or a .xacro/.urdf path, with xacro
    arguments as on a command line (``["name:=value", ...]``; items without ``:=`` are ignored)."""
    return load_robot(name_or_path, args=dict(a.split(":=", 1) for a in args or [] if ":=" in a))


def xacro_text(path: str | os.PathLike[str], args: Mapping[str, str] | None = None) -> str:
    """The URDF text ``xacro FILE name:=value`` prints (a launch file's ``<param command="xacro ...">``)."""
    file = robot_path(path)
    return expand(file, PackageIndex(near=file), args)[0]


def _footprint_or_default(model: RobotModel) -> list[list[float]]:
    """:func:`robot_footprint`, or costmap_2d's default footprint for a robot of meshes only."""
    from navlab.description.footprint import robot_footprint

    try:
        return robot_footprint(model)
    except DescriptionError:
        return [[-0.325, -0.325], [-0.325, 0.325], [0.325, 0.325], [0.46, 0.0], [0.325, -0.325]]


def robot_launch_values(name_or_path: str | os.PathLike[str]) -> dict[str, str]:
    """What launch files take from a robot (``$(robot KEY)``): ``base_frame`` (the drive plugin's
    ``robotBaseFrame``, else the root link), ``odom_frame`` and ``scan_topic`` (the first laser's topic,
    else ``scan``) from its plugin tags; ``params``: the navigation parameter folder navlab ships for it,
    else the generic ROS-default one (``params_note`` then says so); ``footprint``: the rectangle around its
    collision geometry (``[[x, y], ...]``, m, in the base frame). From its package's own configuration
    (:mod:`navlab.description.robot_files`): ``wheel_controller`` (``true`` when a ``gazebo_ros_control`` robot
    has a control YAML), ``controller_params`` (that YAML, else ``diff_drive_controller.yaml`` in ``params``),
    ``own_controller_params`` (that YAML, else empty),
    ``ekf`` (``true`` when a robot_localization YAML sits beside it) and ``ekf_params`` (that YAML, else
    navlab's ``params/ekf.yaml``); ``imu_topic`` (its first IMU's topic, else ``imu``) and ``ekf_mapless``
    (``true`` also when it has an IMU: mapless navigation fuses it, as the real robots do)."""
    from navlab.description.robot_files import robot_files

    model = load_robot(name_or_path)
    dd = model.diff_drive
    shipped = resources.root() / "params" / model.name
    own = shipped.is_dir() and model.source is not None and resources.root() in model.source.resolve().parents
    files = robot_files(model.source) if model.source is not None else None
    control = files.control if files is not None and model.ros_control is not None else None
    ekf = files.ekf if files is not None else None
    params = shipped if own else resources.root() / "params" / "generic"
    values = {
        "base_frame": dd.robot_base_frame if dd else model.root_link,
        "odom_frame": dd.odometry_frame if dd else "odom",
        "scan_topic": model.lidars[0].topic if model.lidars else "scan",
        "params": str(params),
        "footprint": str(_footprint_or_default(model)),
        "wheel_controller": "true" if control is not None else "false",
        "controller_params": str(control or params / "diff_drive_controller.yaml"),
        "own_controller_params": str(control or ""),
        "ekf": "true" if ekf is not None else "false",
        "ekf_mapless": "true" if ekf is not None or model.imus else "false",
        "imu_topic": model.imus[0].topic if model.imus else "imu",
        "ekf_params": str(ekf or resources.path("params/ekf.yaml")),
        "collision_monitor": "true" if (params / "collision_monitor.yaml").is_file() else "false",
        "collision_monitor_params": str(params / "collision_monitor.yaml") if own else "",
    }
    if not own:
        values["params_note"] = (
            f"robot {model.name!r} has no navigation parameters of its own and params:= was not given: move_base "
            f"uses navlab's generic ROS-default set ({values['params']}) with the footprint {values['footprint']} (m) "
            "around "
            "its collision geometry; pass params:=DIR for the robot's tuned files"
        )
    return values
