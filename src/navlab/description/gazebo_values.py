"""Values of ``<gazebo>`` plugin tags shared by the plugin readers: booleans, numbers, ROS 2 namespaces and
remappings, update rates, and Noetic's defaults for missing tags."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from navlab.description.errors import DescriptionError
from navlab.description.urdf import floats

GAZEBO_DEFAULT_RATE = 1000.0  # Hz: Gazebo's default physics rate; a plugin rate of 0 means every step


def parse_bool(text: str, where: str) -> bool:
    t = text.strip().lower()
    if t in ("1", "true", "yes"):
        return True
    if t in ("0", "false", "no"):
        return False
    raise DescriptionError(f"{where}: expected true/false, got {text!r}")


def number(el: ET.Element | None, where: str, default: float) -> float:
    if el is None or not (el.text or "").strip():
        return default
    return floats(el.text, 1, where, f"<{el.tag}>")[0]


def ros_remaps(plugin: ET.Element) -> tuple[str, dict[str, str]]:
    """ROS 2 ``<ros><namespace>`` and ``<remapping>from:=to</remapping>`` of a plugin."""
    ros = plugin.find("ros")
    if ros is None:
        return "", {}
    ns = (ros.findtext("namespace") or "").strip()
    remaps = {}
    for r in ros.findall("remapping"):
        src, sep, dst = (r.text or "").partition(":=")
        if sep:
            remaps[src.strip()] = dst.strip()
    return ns, remaps


def scoped(ns: str, topic: str) -> str:
    """``topic`` in namespace ``ns`` (absolute topics stay as they are)."""
    if not ns or topic.startswith("/"):
        return topic
    return "/" + ns.strip("/") + "/" + topic.lstrip("~/")


def plugin_rate(value: float) -> float:
    return GAZEBO_DEFAULT_RATE if value <= 0 else value


def plugin_file(plugin: ET.Element) -> str:
    """A plugin's library file name without its folder (``libgazebo_ros_laser.so``)."""
    return (plugin.get("filename") or "").rsplit("/", 1)[-1]
