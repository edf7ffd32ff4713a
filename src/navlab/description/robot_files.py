"""A robot package's own ROS configuration: its ros_control YAML and its robot_localization YAML.

A ROS 1 robot ships them beside its description (``<robot>_description/config/``) or in a sibling control
package (``<robot>_control/config/``, as jackal_control does). They are found by content, not by name: the
control YAML is the one naming a ``diff_drive_controller/DiffDriveController``; the robot_localization YAML the
one with an ``odom0`` or ``imu0`` input (flat, as ``rosparam load`` into the EKF node reads it), in the same
folder as the control YAML (or, without one, in the package's config folder).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml

CONTROLLER_TYPE = "diff_drive_controller/DiffDriveController"
_SUFFIX = "_description"


@dataclass(frozen=True)
class RobotFiles:
    """The control YAML and the robot_localization YAML of a robot's package (None: not found)."""

    control: Path | None = None
    ekf: Path | None = None


def package_dir(description: Path) -> Path | None:
    """The ROS package (folder with a package.xml) enclosing a description file."""
    for folder in description.resolve().parents:
        if (folder / "package.xml").is_file():
            return folder
    return None


def _load(path: Path) -> dict | None:
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError):
        return None
    return data if isinstance(data, dict) else None


def _is_control(data: dict) -> bool:
    return any(isinstance(v, dict) and v.get("type") == CONTROLLER_TYPE for v in data.values())


def _is_ekf(data: dict) -> bool:
    return "odom0" in data or "imu0" in data


def robot_files(description: Path) -> RobotFiles:
    """The robot's control and robot_localization YAMLs (see the module docstring)."""
    pkg = package_dir(description)
    if pkg is None:
        return RobotFiles()
    folders = [pkg / "config"]
    if pkg.name.endswith(_SUFFIX):
        folders.append(pkg.parent / (pkg.name[: -len(_SUFFIX)] + "_control") / "config")
    for folder in folders:
        files = sorted(folder.glob("*.yaml")) if folder.is_dir() else []
        loaded = [(f, _load(f)) for f in files]
        control = next((f for f, d in loaded if d is not None and _is_control(d)), None)
        ekf = next((f for f, d in loaded if d is not None and _is_ekf(d)), None)
        if control is not None or ekf is not None:
            return RobotFiles(control=control, ekf=ekf)
    return RobotFiles()
