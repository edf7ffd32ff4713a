"""A robot's footprint for costmap_2d, from its collision geometry: what navigation uses for a robot
that comes without parameter files of its own."""

from __future__ import annotations

import numpy as np

from navlab.description.errors import DescriptionError
from navlab.description.model import Origin, RobotModel, Shape


def _link_poses(model: RobotModel) -> dict[str, np.ndarray]:
    """4x4 pose of every link in the root link's frame, with every joint at zero."""
    poses = {model.root_link: np.eye(4)}
    pending = list(model.joints)
    while pending:
        progressed = [j for j in pending if j.parent in poses]
        if not progressed:
            break
        for joint in progressed:
            poses[joint.child] = poses[joint.parent] @ joint.origin.matrix()
            pending.remove(joint)
    return poses


def _corners(shape: Shape) -> np.ndarray:
    """Points (N x 3, the shape's frame) whose hull bounds the shape."""
    g = shape.geometry
    if g.kind == "box":
        sx, sy, sz = (s / 2 for s in g.size)
        return np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)])
    if g.kind in ("cylinder", "sphere"):
        r = g.size[0]
        h = g.size[1] / 2 if g.kind == "cylinder" else r
        a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
        ring = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        return np.vstack([np.column_stack([ring, np.full(16, z)]) for z in (-h, h)])
    return np.zeros((0, 3))  # meshes: their links' boxes and cylinders bound most robots; skipped


def collision_points_xy(model: RobotModel, base_frame: str | None = None) -> np.ndarray:
    """Every box, cylinder and sphere collision shape seen from above, as points (N x 2, m, in ``base_frame``,
    default the diff-drive plugin's base frame or the root link): a box's corners, 16 points on each circle of a
    cylinder or sphere. Meshes are not counted."""
    poses = _link_poses(model)
    base = base_frame or (model.diff_drive.robot_base_frame if model.diff_drive else model.root_link)
    if base not in poses:
        raise DescriptionError(f"{model.source}: base frame {base!r} is not a link of the robot")
    base_inv = np.linalg.inv(poses[base])
    points = []
    for name, link in model.links.items():
        if name not in poses:
            continue
        for shape in link.collisions:
            pts = _corners(shape)
            if len(pts):
                m = base_inv @ poses[name] @ (shape.origin or Origin()).matrix()
                points.append(pts @ m[:3, :3].T + m[:3, 3])
    if not points:
        raise DescriptionError(f"{model.source}: no box, cylinder or sphere collision geometry to size a footprint")
    return np.vstack(points)[:, :2]


def collision_reach(model: RobotModel, base_frame: str | None = None) -> float:
    """How far (m) the collision geometry reaches from the base frame's origin, seen from above: the least
    ``robot_radius`` + ``footprint_padding`` whose circle holds the whole robot (a round robot's wheels may
    stick out of its chassis)."""
    xy = collision_points_xy(model, base_frame)
    return float(np.hypot(xy[:, 0], xy[:, 1]).max())


def robot_footprint(model: RobotModel, base_frame: str | None = None) -> list[list[float]]:
    """The axis-aligned rectangle (m, in ``base_frame``, default the diff-drive plugin's base frame or the
    root link) around every collision shape, seen from above: ``[[x, y], ...]`` as costmap_2d's
    ``footprint`` parameter. Meshes are not counted."""
    xy = collision_points_xy(model, base_frame)
    (x0, y0), (x1, y1) = np.round(xy.min(axis=0), 3), np.round(xy.max(axis=0), 3)
    return [[float(x0), float(y0)], [float(x0), float(y1)], [float(x1), float(y1)], [float(x1), float(y0)]]
