"""The world model that SDF loading produces and the simulator consumes (SI units, REP-103)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from navlab.description import Link, Origin
from navlab.geometry import Pose6  # x y z roll pitch yaw, as in SDF <pose>


@dataclass
class ModelSpec:
    """An SDF model: its pose in the world, whether it is static, and its links (poses in the model frame).

    ``link_origins`` maps a link name to that link's pose in the model frame.
    """

    name: str
    pose: Pose6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    static: bool = False
    links: list[Link] = field(default_factory=list)
    link_origins: dict[str, Origin] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)  # from load_model (world loads use WorldModel's)


@dataclass
class WorldModel:
    """A Gazebo-classic world: ground plane, gravity, physics step, and models."""

    name: str
    models: list[ModelSpec] = field(default_factory=list)
    ground_plane: bool = True
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    max_step_size: float = 0.001  # s
    warnings: list[str] = field(default_factory=list)
    source: Path | None = None
