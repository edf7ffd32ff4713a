"""A generated office floor for SLAM tests: many alike rooms along corridors that close two loops.

World frame (m, rad), the floor spans x in [0, ``width``], y in [0, ``depth``] (wall centre lines)::

    y=depth ┌────────────────────────────────────────────┐
            │ north rooms (doors onto corridor B)          │
            ├── ─── ── ─── ── ─── ── ─── ── ─── ── ─── ──┤
            │ corridor B                                   │
            │   ┌── ─ ── ─ ──┐   ┌── ─ ── ─ ──┐            │
            │ W │ block rooms│ M │ block rooms│ E          │  W, M, E: north-south corridors
            │   └── ─ ── ─ ──┘   └── ─ ── ─ ──┘            │
            │ corridor A                                   │
            ├── ─── ── ─── ── ─── ── ─── ── ─── ── ─── ──┤
            │ south rooms (doors onto corridor A)          │
    y=0     └────────────────────────────────────────────┘

Corridors A and B join the west, middle and east corridors, so the corridors close two loops (around
each block). Every room has one door (``door`` m wide, centred) onto its corridor; rooms in a row are
alike (``room`` m wide), so places repeat along the corridors: the aliasing that breaks SLAM. Walls are
``wall`` m thick boxes written as SDF 1.6 (``write_world``) that navlab and Gazebo classic both load.
``OfficeWorld.route`` is a drive through both loops with short visits into rooms.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from navlab.io import write_text_atomic
from navlab.world.errors import WorldError
from navlab.world.sdf_writer import box_geometry, link, static_model, world_sdf

WALL_HEIGHT = 1.0  # m


@dataclass(frozen=True)
class Wall:
    """A wall box: centre (x, y) and full size (sx, sy) on the floor (m, world frame)."""

    x: float
    y: float
    sx: float
    sy: float


@dataclass
class OfficeWorld:
    """The layout's figures (m) and its walls; see the module docstring for the frame."""

    width: float
    depth: float
    corridor: float
    room: float
    door: float
    wall: float
    walls: list[Wall] = field(default_factory=list)
    corridor_a: float = 0.0  # y of corridor A's centre line
    corridor_b: float = 0.0
    corridor_x: tuple[float, float, float] = (0.0, 0.0, 0.0)  # x of the west, middle, east corridors' centres
    rooms: int = 0
    doors: list[tuple[float, float, float]] = field(default_factory=list)  # (x, y, +-1: room side) per room

    @property
    def name(self) -> str:
        """World name used in the SDF."""
        return f"office_{self.width:g}x{self.depth:g}"

    @property
    def start(self) -> tuple[float, float, float]:
        """The route's start pose (x, y, yaw): corridor A, west, facing east."""
        return (self.corridor_x[0] + 2.0, self.corridor_a, 0.0)

    def to_sdf(self) -> str:
        """The world as SDF 1.6 text (ground plane, sun, one static model of wall boxes)."""
        geo = [
            link(
                f"wall_{k:03d}",
                w.x,
                w.y,
                WALL_HEIGHT / 2,
                box_geometry(w.sx, w.sy, WALL_HEIGHT),
                "0.9 0.9 0.85",
                parts=f"wall_{k:03d}_",
            )
            for k, w in enumerate(self.walls)
        ]
        comment = (
            f"navlab office floor {self.width:g} m x {self.depth:g} m: {self.rooms} rooms of {self.room:g} m, "
            f"corridors {self.corridor:g} m wide closing two loops, doors {self.door:g} m"
        )
        return world_sdf(self.name, [static_model("office_walls", geo)], comment)

    def write_world(self, path: str | os.PathLike[str]) -> Path:
        """Write the ``.world`` file atomically; returns its path."""
        out = Path(path)
        write_text_atomic(out, self.to_sdf())
        return out

    def occupied(self, points: np.ndarray) -> np.ndarray:
        """Whether each (x, y) point (m) lies inside a wall box (N,) bool."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        out = np.zeros(len(p), dtype=bool)
        for w in self.walls:
            out |= (np.abs(p[:, 0] - w.x) <= w.sx / 2) & (np.abs(p[:, 1] - w.y) <= w.sy / 2)
        return out

    def route(self) -> np.ndarray:
        """Waypoints (N, 2) of a drive from ``start``: around the west loop (closed at the middle corridor),
        into a south room and out, around the east loop with a north room on the way, and back west along
        corridor A to the start (places seen again, some from the other direction)."""
        xw, xm, xe = self.corridor_x
        ya, yb = self.corridor_a, self.corridor_b

        def visit(side: float, along: float, x_lo: float, x_hi: float) -> list[tuple[float, float]]:
            """Into the room on ``side`` whose door is nearest the middle of x_lo..x_hi, and back out."""
            cands = [d for d in self.doors if d[2] == side and x_lo < d[0] < x_hi and abs(d[1] - along) < self.corridor]
            dx, dy, _ = min(cands, key=lambda d: abs(d[0] - (x_lo + x_hi) / 2))
            return [(dx, along), (dx, dy + side * 2.0), (dx, along)]

        pts = [self.start[:2], (xm, ya), (xm, yb), (xw, yb), (xw, ya), (xm, ya)]  # the west loop
        pts += [*visit(-1.0, ya, xm, xe), (xe, ya), (xe, yb)]
        pts += [*visit(1.0, yb, xm, xe), (xm, yb), (xm, ya), self.start[:2]]  # the east loop, back west
        return np.array(pts, dtype=np.float64)


def generate_office(
    *,
    rooms_per_block: int = 3,
    room: float = 4.0,
    corridor: float = 2.0,
    outer_depth: float = 4.5,
    block_depth: float = 7.5,
    door: float = 1.0,
    wall: float = 0.2,
) -> OfficeWorld:
    """The office floor: two blocks of ``2 x rooms_per_block`` rooms between three north-south corridors,
    and a row of outer rooms (about ``room`` m wide) on the far side of each east-west corridor (m).

    With the defaults it is 30 m x 20.5 m with 26 rooms. Raises ``WorldError`` for sizes that leave no
    room for a door or a robot (a corridor under 1.2 m, a door under 0.8 m or wider than a room)."""
    if rooms_per_block < 1:
        raise WorldError(f"office: rooms_per_block must be >= 1, got {rooms_per_block}")
    if corridor < 1.2 or door < 0.8 or door > room - 2 * wall or block_depth < 2 * door:
        raise WorldError(
            f"office: corridor {corridor} m (>= 1.2), door {door} m (0.8 .. room - 2 wall = "
            f"{room - 2 * wall:g}) and block_depth {block_depth} m (>= 2 doors) do not fit"
        )
    block = rooms_per_block * room
    width = 3 * corridor + 2 * block
    depth = 2 * outer_depth + 2 * corridor + block_depth
    walls: list[Wall] = []
    half = wall / 2

    def hwall(y: float, x0: float, x1: float, gaps: list[float] = ()) -> None:  # type: ignore[assignment]
        """A wall along x from x0 to x1 at y, with door gaps centred at ``gaps``."""
        edges = [x0 - half]
        for g in sorted(gaps):
            edges += [g - door / 2, g + door / 2]
        edges.append(x1 + half)
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            if b - a > 1e-6:
                walls.append(Wall((a + b) / 2, y, b - a, wall))

    def vwall(x: float, y0: float, y1: float) -> None:
        walls.append(Wall(x, (y0 + y1) / 2, wall, y1 - y0 + wall))

    ya0 = outer_depth  # corridor A between ya0 and ya1
    ya1 = ya0 + corridor
    ymid = ya1 + block_depth / 2
    yb0 = ya1 + block_depth
    yb1 = yb0 + corridor
    xs = [0.0, corridor, corridor + block, 2 * corridor + block, 2 * corridor + 2 * block, width]
    doors: list[tuple[float, float, float]] = []
    # outer rooms: about `room` wide across the whole width
    n_outer = max(1, round(width / room))
    outer = [width * (k + 0.5) / n_outer for k in range(n_outer)]
    doors += [(x, ya0, -1.0) for x in outer] + [(x, yb1, 1.0) for x in outer]
    hwall(0.0, 0.0, width)
    hwall(depth, 0.0, width)
    hwall(ya0, 0.0, width, outer)
    hwall(yb1, 0.0, width, outer)
    vwall(0.0, 0.0, depth)
    vwall(width, 0.0, depth)
    for k in range(1, n_outer):
        x = width * k / n_outer
        vwall(x, 0.0, ya0)
        vwall(x, yb1, depth)
    # the two blocks: rooms facing corridor A and rooms facing corridor B, split along ymid
    for b0, b1 in ((xs[1], xs[2]), (xs[3], xs[4])):
        centres = [b0 + room * (k + 0.5) for k in range(rooms_per_block)]
        doors += [(x, ya1, 1.0) for x in centres] + [(x, yb0, -1.0) for x in centres]
        hwall(ya1, b0, b1, centres)
        hwall(yb0, b0, b1, centres)
        hwall(ymid, b0, b1)
        vwall(b0, ya1, yb0)
        vwall(b1, ya1, yb0)
        for k in range(1, rooms_per_block):
            vwall(b0 + room * k, ya1, yb0)
    return OfficeWorld(
        width=width,
        depth=depth,
        corridor=corridor,
        room=room,
        door=door,
        wall=wall,
        walls=walls,
        corridor_a=(ya0 + ya1) / 2,
        corridor_b=(yb0 + yb1) / 2,
        corridor_x=(corridor / 2, corridor + block + corridor / 2, width - corridor / 2),
        rooms=2 * n_outer + 4 * rooms_per_block,
        doors=doors,
    )
