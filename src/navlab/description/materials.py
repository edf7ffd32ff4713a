"""Gazebo classic's named materials (``gazebo.material`` scripts) as RGBA colours.

A ``<gazebo reference="link"><material>Gazebo/Orange</material></gazebo>`` tag in a URDF, or a
``<material><script><name>Gazebo/Wood</name></script></material>`` in an SDF world, names one of
these; Gazebo draws the visual in its diffuse colour (values from Gazebo 11's media scripts, rounded).
"""

from __future__ import annotations

RGBA = tuple[float, float, float, float]

GAZEBO_MATERIALS: dict[str, RGBA] = {
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/DarkGray": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/LightGrey": (0.8, 0.8, 0.8, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/SkyBlue": (0.53, 0.81, 0.92, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/ZincYellow": (0.97, 0.87, 0.3, 1.0),
    "Gazebo/DarkYellow": (0.7, 0.7, 0.0, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
    "Gazebo/Gold": (0.8, 0.64, 0.2, 1.0),
    "Gazebo/Wood": (0.55, 0.4, 0.25, 1.0),
    "Gazebo/WoodFloor": (0.6, 0.45, 0.3, 1.0),
    "Gazebo/Bricks": (0.6, 0.3, 0.2, 1.0),
    "Gazebo/WhiteGlow": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/GreyTransparent": (0.5, 0.5, 0.5, 0.5),
    "Gazebo/BlueTransparent": (0.0, 0.0, 1.0, 0.5),
    "Gazebo/GreenTransparent": (0.0, 1.0, 0.0, 0.5),
    "Gazebo/RedTransparent": (1.0, 0.0, 0.0, 0.5),
}


def gazebo_material(name: str) -> RGBA | None:
    """The RGBA of a Gazebo named material (``Gazebo/Orange``), None if navlab does not know it."""
    return GAZEBO_MATERIALS.get(name.strip())
