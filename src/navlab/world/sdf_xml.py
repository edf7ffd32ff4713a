"""Reading SDF elements (:mod:`navlab.world.sdf`): numbers, vectors, poses and flags with errors that name the
element and what was expected, and the XML file itself."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

from navlab.world.errors import WorldError
from navlab.world.model import Pose6


def floats(text: str | None, n: int, where: str) -> tuple[float, ...]:
    """``n`` finite numbers from an element's text (``where`` names it in the error)."""
    parts = (text or "").split()
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise WorldError(f"{where}: expected {n} numbers, got {text!r}") from None
    if len(vals) != n or not all(math.isfinite(v) and abs(v) < 1e9 for v in vals):
        raise WorldError(f"{where}: expected {n} finite numbers (|v| < 1e9), got {text!r}")
    return vals


def vec3(text: str | None, where: str) -> tuple[float, float, float]:
    """Three finite numbers (x y z) from an element's text."""
    x, y, z = floats(text, 3, where)
    return x, y, z


def num(el: ET.Element | None, tag: str, where: str, default: float) -> float:
    """The number in ``el``'s child ``tag``, or ``default`` when it is missing or empty."""
    sub = el.find(tag) if el is not None else None
    if sub is None or not (sub.text or "").strip():
        return default
    return floats(sub.text, 1, f"{where}/<{tag}>")[0]


def pose_of(el: ET.Element, where: str, warnings: list[str] | None = None) -> Pose6:
    """The element's ``<pose>`` (x y z roll pitch yaw) relative to its parent frame."""
    p = el.find("pose")
    if p is None or not (p.text or "").strip():
        return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    frame = p.get("relative_to") or p.get("frame") or ""
    if frame and frame not in ("world", "__model__") and warnings is not None:
        warnings.append(f"{where}/<pose>: frame {frame!r} is not supported; taken relative to the parent")
    v = floats(p.text, 6, f"{where}/<pose>")
    return (v[0], v[1], v[2], v[3], v[4], v[5])


def flag(el: ET.Element, tag: str, default: bool) -> bool:
    """SDF's boolean in ``el``'s child ``tag`` (1/true), or ``default`` when it is missing."""
    text = (el.findtext(tag) or "").strip().lower()
    return default if not text else text in ("1", "true")


def parse_xml(path: Path, what: str) -> ET.Element:
    """The root element of the XML file ``path`` (a ``what``), or a WorldError saying what is wrong with it."""
    if path.is_dir():
        raise WorldError(f"{path}: is a directory; expected a {what}")
    if not path.is_file():
        if path.exists():  # a named pipe would block the parser, a device never end
            raise WorldError(f"{path}: is not a regular file (a pipe, device or socket); expected a {what}")
        raise WorldError(f"{path}: {what} not found")
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise WorldError(f"{path}: malformed XML ({exc})") from None
