"""Files shipped with navlab: robots, worlds, parameters and launch files.

``path("robots/mybot/mybot.xacro")`` returns the absolute path of a shipped file, and
``package_paths()`` maps the ROS package names of shipped descriptions (``mybot_description``) to
their directories, for ``$(find pkg)`` and ``package://pkg/...``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from navlab.errors import NavlabError

# ROS package name -> directory (relative to this package) of the shipped robot descriptions.
_SHIPPED_PACKAGES = (
    ("mybot_description", "robots/mybot"),
    ("navlab_tb3_burger_description", "robots/tb3_burger"),
    ("navlab_jackal_description", "robots/jackal"),
    ("navlab_jackal_skid_description", "robots/jackal_skid"),
    ("gazebo_ros", "ros/gazebo_ros"),  # stand-ins for a ROS install: empty_world.launch, $(find xacro)
    ("xacro", "ros/xacro"),
)


class ResourceError(NavlabError):
    """A shipped file that does not exist was asked for."""


def root() -> Path:
    """The directory that holds navlab's shipped files."""
    return Path(str(resources.files(__name__)))


def path(relative: str, *, must_exist: bool = True) -> Path:
    """Absolute path of a shipped file, e.g. ``path("worlds/room.world")``.

    Raises ``ResourceError`` naming the file (and what exists beside it) when it is missing.
    """
    full = root() / relative
    if must_exist and not full.exists():
        parent = full.parent
        choices = sorted(p.name for p in parent.iterdir()) if parent.is_dir() else []
        hint = f"; {parent} holds: {', '.join(choices)}" if choices else ""
        raise ResourceError(f"no shipped file {relative!r} (looked for {full}){hint}")
    return full


def package_paths() -> dict[str, Path]:
    """ROS package name -> directory for the robot descriptions shipped with navlab."""
    return {name: root() / rel for name, rel in _SHIPPED_PACKAGES}


def shipped(kind: str) -> list[str]:
    """The names of the shipped worlds, robots or routes (``kind``: world, robot or route), sorted."""
    if kind == "robot":  # robots/NAME/NAME.xacro
        return sorted(p.parent.name for p in (root() / "robots").glob("*/*.xacro") if p.stem == p.parent.name)
    pattern = {"world": "worlds/*.world", "route": "routes/*.yaml"}[kind]
    return sorted(p.stem for p in root().glob(pattern))


def world(name: str) -> Path:
    """A shipped world by name (``"room"`` or ``"room.world"``)."""
    full = path(f"worlds/{name if name.endswith('.world') else name + '.world'}", must_exist=False)
    if not full.is_file():
        raise _unknown("world", name, shipped("world"))
    return full


def robot(name: str) -> Path:
    """A shipped robot's top xacro by name (``"mybot"``)."""
    full = path(f"robots/{name}/{name}.xacro", must_exist=False)
    if not full.is_file():
        raise _unknown("robot", name, shipped("robot"))
    return full


def route(name: str) -> Path:
    """A shipped mapping route by name (``"room"``: a loop through room.world for ``navlab map --route``)."""
    full = path(f"routes/{name if name.endswith('.yaml') else name + '.yaml'}", must_exist=False)
    if not full.is_file():
        raise _unknown("route", name, shipped("route"))
    return full


def _unknown(kind: str, name: str, shipped: list[str]) -> ResourceError:
    """One line: ``world 'rooom': no such file here and no shipped world of that name; did you mean 'room'?``"""
    from navlab.errors import did_you_mean

    hint = did_you_mean(name, shipped)
    return ResourceError(
        f"{kind} {name!r}: no such file here and no shipped {kind} of that name{hint} (shipped: {', '.join(shipped)})"
    )


def model_path() -> Path:
    """The directory of Gazebo models shipped with navlab (``ground_plane``, ``sun``)."""
    return root() / "worlds" / "models"
