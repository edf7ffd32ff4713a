"""Writing SDF 1.6 ``.world`` text for generated worlds: a ground plane, the sun, ODE at 1 ms, and static
models made of box and cylinder links (m, world frame). Gazebo classic and navlab both load the result."""

from __future__ import annotations

from collections.abc import Sequence


def box_geometry(sx: float, sy: float, sz: float) -> str:
    """``<geometry>`` of a box with full sizes (m)."""
    return f"<geometry><box><size>{sx:.4f} {sy:.4f} {sz:.4f}</size></box></geometry>"


def cylinder_geometry(radius: float, length: float) -> str:
    """``<geometry>`` of a cylinder along z (m)."""
    return f"<geometry><cylinder><radius>{radius}</radius><length>{length}</length></cylinder></geometry>"


def link(name: str, x: float, y: float, z: float, geometry: str, rgb: str, *, parts: str = "") -> str:
    """A link at (x, y, z) with one collision and one visual of ``geometry`` coloured ``rgb`` ("r g b").

    ``parts`` prefixes the collision and visual names (``wall_0_`` gives ``wall_0_collision``)."""
    return (
        f'      <link name="{name}">\n        <pose>{x:.4f} {y:.4f} {z:.4f} 0 0 0</pose>\n'
        f'        <collision name="{parts}collision">{geometry}</collision>\n'
        f'        <visual name="{parts}visual">{geometry}\n'
        f"          <material><ambient>{rgb} 1</ambient><diffuse>{rgb} 1</diffuse></material>\n"
        "        </visual>\n      </link>\n"
    )


def static_model(name: str, links: Sequence[str]) -> str:
    """A static model at the origin holding ``links``."""
    return (
        f'    <model name="{name}">\n      <static>true</static>\n      <pose>0 0 0 0 0 0</pose>\n'
        + "".join(links)
        + "    </model>\n"
    )


def world_sdf(name: str, models: Sequence[str], comment: str = "") -> str:
    """A whole ``.world``: ground plane, sun, gravity, ODE physics at 1 ms and the ``models``."""
    return (
        '<?xml version="1.0" ?>\n' + (f"<!-- {comment} -->\n" if comment else "") + '<sdf version="1.6">\n'
        f'  <world name="{name}">\n'
        "    <include>\n      <uri>model://ground_plane</uri>\n    </include>\n"
        "    <include>\n      <uri>model://sun</uri>\n    </include>\n"
        "    <gravity>0 0 -9.8</gravity>\n"
        '    <physics name="default_physics" default="0" type="ode">\n'
        "      <max_step_size>0.001</max_step_size>\n      <real_time_factor>1</real_time_factor>\n"
        "      <real_time_update_rate>1000</real_time_update_rate>\n    </physics>\n"
        + "".join(models)
        + "  </world>\n</sdf>\n"
    )
