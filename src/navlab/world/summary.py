"""Plain-data summary of a world, for ``navlab check world`` (text or ``--json``)."""

from __future__ import annotations

import math
from typing import Any

from navlab.description import shape_summary
from navlab.world.model import WorldModel
from navlab.world.occupancy import extents


def world_summary(world: WorldModel) -> dict[str, Any]:
    """Models (static, links, shapes), extents in x/y, physics and warnings of a world."""
    models = []
    for m in world.models:
        shapes = [shape_summary(s) for link in m.links for s in link.collisions]
        models.append(
            {
                "name": m.name,
                "static": m.static,
                "pose": list(m.pose),
                "links": len(m.links),
                "collision_shapes": len(shapes),
                "kinds": sorted({s["kind"] for s in shapes}),
                "non_convex_meshes": [s["mesh"] for s in shapes if s.get("convex") is False],
            }
        )
    box = extents(world, z_min=-math.inf, z_max=math.inf)
    ext = None
    if box is not None:
        ext = {"x": [round(box[0], 4), round(box[2], 4)], "y": [round(box[1], 4), round(box[3], 4)]}
    return {
        "kind": "world",
        "name": world.name,
        "source": str(world.source) if world.source else None,
        "ground_plane": world.ground_plane,
        "gravity": list(world.gravity),
        "max_step_size": world.max_step_size,
        "models": models,
        "extents": ext,
        "warnings": list(world.warnings),
    }


def format_world(s: dict[str, Any]) -> str:
    """Human-readable text of :func:`world_summary`."""
    lines = [
        f"world {s['name']}  ({s['source']})",
        f"  ground plane {'yes' if s['ground_plane'] else 'NO'}, gravity {s['gravity']}, step {s['max_step_size']} s",
        f"  models ({len(s['models'])}):",
    ]
    for m in s["models"]:
        x, y, z = m["pose"][:3]
        lines.append(
            f"    {m['name']:<22} {'static' if m['static'] else 'dynamic':<8} at ({x:g}, {y:g}, {z:g}), "
            f"{m['links']} link(s), {m['collision_shapes']} collision shape(s) {', '.join(m['kinds'])}"
        )
        for mesh in m["non_convex_meshes"]:
            lines.append(f"      concave collision mesh (decomposed for physics): {mesh}")
    if s["extents"]:
        lines.append(f"  extents x {s['extents']['x']} m, y {s['extents']['y']} m")
    lines += [f"  warning: {w}" for w in s["warnings"]]
    lines.append("  OK" if not s["warnings"] else f"  OK with {len(s['warnings'])} warning(s)")
    return "\n".join(lines)
