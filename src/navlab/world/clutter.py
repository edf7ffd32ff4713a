"""BARN-style cluttered worlds (Perille et al. 2020, "Benchmarking Metric Ground Navigation").

A 4.5 m x 4.5 m field of 30 x 30 cells of 0.15 m, each cell holding a static cylinder of radius
0.075 m or not, filled by a cellular automaton (random fill at ``fill``, then ``smooth`` rounds in
which a cell with >= 5 of its 8 neighbours filled fills and one with <= 1 clears: clustered clutter
with scattered cylinders between). Walls run along both long sides and close the start end, so the
only way to the goal is through the field. A collision-free corridor for a disc of ``robot_radius + margin`` is carved
by removing the fewest cylinders along a cheapest path (a grid search), so every world is solvable.

World frame (m, rad): the field spans x in [0, 4.5], y in [-2.25, 2.25]; the robot starts 2 m
before it at (-2, 0) facing +x and the goal is 10 m from the start at (8, 0), 3.5 m past the field.
``ClutterWorld.reference_path_m`` is the length of the shortest collision-free path for a disc of
``robot_radius`` (8-connected Dijkstra on a 0.05 m grid of exact clearances, then shortened by line of
sight), BARN's T_opt = reference length / 2 m/s. Worlds are written as SDF 1.6 ``.world`` files that
navlab's :func:`navlab.world.load_world` and Gazebo classic both load.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from navlab.io import write_text_atomic
from navlab.world.clutter_geometry import Clearance
from navlab.world.errors import WorldError
from navlab.world.sdf_writer import box_geometry, cylinder_geometry, link, static_model, world_sdf

CELL = 0.15  # m: BARN's grid cell
CELLS = 30  # cells per side of the field (4.5 m)
FIELD = CELL * CELLS  # m
CYLINDER_RADIUS = 0.075  # m
CYLINDER_HEIGHT = 0.8  # m
WALL_THICKNESS = 0.2  # m
WALL_HEIGHT = 1.0  # m
START_GAP = 2.0  # m from the start to the field's near edge
GOAL_DISTANCE = 10.0  # m from the start to the goal
BARN_SPEED = 2.0  # m/s: BARN's T_opt speed
_BEHIND = 0.75  # m of floor behind the start, inside the back wall
_REF_RES = 0.05  # m: grid of the reference-path search and the corridor check
_CARVE_WEIGHT = 20.0  # extra cost per cylinder a carving step would remove


@dataclass(frozen=True)
class Box:
    """A static wall: centre (x, y) and full size (sx, sy) on the floor, ``height`` tall (m, world frame)."""

    name: str
    x: float
    y: float
    sx: float
    sy: float
    height: float = WALL_HEIGHT


@dataclass
class ClutterWorld:
    """One generated world (all in the world frame: m, rad).

    ``cells``: (30, 30) bool, ``cells[i, j]`` is the field cell at x = (j + 0.5) 0.15, y = -2.25 +
    (i + 0.5) 0.15 (row 0 lowest y); ``cylinders``: (k, 2) centres of the cells that hold one;
    ``reference_path``: (n, 2) shortest collision-free path for a disc of ``robot_radius``;
    ``difficulty``: fraction of the field's cells holding a cylinder (after smoothing and carving);
    ``metrics``: more figures: ``fill_initial``, ``fill_final``, ``tortuosity`` (reference length / 10 m),
    ``mean_clearance_m`` (robot centre to the nearest surface along the reference path in the field) and
    ``bottleneck_m`` (half-width of the narrowest passage on the widest route).
    """

    seed: int
    fill: float
    smooth: int
    robot_radius: float
    margin: float
    cells: np.ndarray
    cylinders: np.ndarray
    walls: list[Box]
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    reference_path: np.ndarray
    reference_path_m: float
    difficulty: float
    carved: int
    metrics: dict[str, float] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """World name used in the SDF (``clutter_s<seed>_f<fill>_k<smooth>``)."""
        return f"clutter_s{self.seed}_f{round(self.fill * 100):02d}_k{self.smooth}"

    def t_opt(self, speed: float = BARN_SPEED) -> float:
        """BARN's optimal traversal time (s): reference path length / ``speed`` (m/s)."""
        return self.reference_path_m / speed

    def summary(self) -> dict[str, object]:
        """The figures a user reads (JSON-ready): parameters, poses, counts, reference length, difficulty."""
        return {
            "name": self.name,
            "seed": self.seed,
            "fill": self.fill,
            "smooth": self.smooth,
            "robot_radius": self.robot_radius,
            "margin": self.margin,
            "cylinders": len(self.cylinders),
            "carved": self.carved,
            "start": list(self.start),
            "goal": list(self.goal),
            "reference_path_m": round(self.reference_path_m, 4),
            "t_opt_s": round(self.t_opt(), 4),
            "difficulty": round(self.difficulty, 4),
            "metrics": {k: round(v, 4) for k, v in self.metrics.items()},
        }

    def to_sdf(self) -> str:
        """The world as SDF 1.6 text (ground plane, sun, static walls and cylinders)."""
        return _sdf(self)

    def write_world(self, path: str | os.PathLike[str]) -> Path:
        """Write the ``.world`` file atomically; returns its path."""
        out = Path(path)
        write_text_atomic(out, self.to_sdf())
        return out

    def clearance(self, points: np.ndarray) -> np.ndarray:
        """Distance (m) from each (x, y) point to the nearest cylinder or wall surface (0 inside one)."""
        return Clearance(self.cylinders, self.walls, CYLINDER_RADIUS)(np.asarray(points, dtype=float).reshape(-1, 2))


def barn_score(success: bool, time_s: float, t_opt: float) -> float:
    """BARN's score of one trial: success x T_opt / clip(T, 2 T_opt, 8 T_opt) (0 on failure, at most 0.5)."""
    if not success:
        return 0.0
    return float(t_opt / min(max(time_s, 2.0 * t_opt), 8.0 * t_opt))


# ------------------------------------------------------------------------------------------ layout
def field_centres() -> tuple[np.ndarray, np.ndarray]:
    """x of the field's columns and y of its rows (m): cell centres on the 0.15 m grid."""
    c = (np.arange(CELLS) + 0.5) * CELL
    return c, c - FIELD / 2


def _walls() -> list[Box]:
    """Side walls along the field and the start zone, and a back wall behind the start."""
    t, half = WALL_THICKNESS, FIELD / 2
    x_back = -START_GAP - _BEHIND
    length = FIELD - x_back
    cx = (FIELD + x_back) / 2
    return [
        Box("wall_left", cx, half + t / 2, length, t),
        Box("wall_right", cx, -half - t / 2, length, t),
        Box("wall_back", x_back - t / 2, 0.0, t, FIELD + 2 * t),
    ]


# ------------------------------------------------------------------------------ cellular automaton
def cellular_automaton(
    rng: np.random.Generator, fill: float, smooth: int, *, fill_threshold: int = 5, clear_threshold: int = 1
) -> np.ndarray:
    """(30, 30) bool field: random fill with probability ``fill``, then ``smooth`` rounds of the rule.

    Each round, a cell with >= ``fill_threshold`` filled neighbours (of 8) fills, one with <=
    ``clear_threshold`` clears, the others keep their state (5 and 3 make the usual 4-5 cave rule);
    cells outside the field count as empty.
    """
    cells = rng.random((CELLS, CELLS)) < fill
    kernel = np.ones((3, 3), dtype=np.int16)
    kernel[1, 1] = 0
    for _ in range(smooth):
        n = ndimage.convolve(cells.astype(np.int16), kernel, mode="constant", cval=0)
        cells = (cells | (n >= fill_threshold)) & (n > clear_threshold)
    return cells


# ------------------------------------------------------------------------------------ grid search
def _grid_dijkstra(
    passable: np.ndarray, enter_cost: np.ndarray, step: float, source: int, target: int
) -> list[int] | None:
    """Cheapest 8-connected path of flat cell indices from ``source`` to ``target``, or None.

    A move costs its length (``step`` or ``step`` sqrt 2) times ``1 + enter_cost`` of the cell entered.
    """
    ny, nx = passable.shape
    idx = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, weights = [], [], []
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = idx[: ny - di, max(0, -dj) : nx - max(0, dj)]  # (i, j) -> (i + di, j + dj), di >= 0
        b = idx[di:, max(0, dj) : nx - max(0, -dj)]
        a, b = a.ravel(), b.ravel()
        ok = passable.ravel()[a] & passable.ravel()[b]
        a, b = a[ok], b[ok]
        length = step * math.hypot(di, dj)
        cost = enter_cost.ravel()
        rows += [a, b]
        cols += [b, a]
        weights += [length * (1.0 + cost[b]), length * (1.0 + cost[a])]
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(ny * nx, ny * nx)
    ).tocsr()
    dist, pred = dijkstra(graph, indices=source, return_predecessors=True)
    if not np.isfinite(dist[target]):
        return None
    path = [target]
    while path[-1] != source:
        path.append(int(pred[path[-1]]))
    return path[::-1]


def _segment_distances(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Distance from each point (k, 2) to the polyline ``path`` (n, 2)."""
    a, b = path[:-1], path[1:]
    ab = b - a
    denom = np.maximum((ab * ab).sum(axis=1), 1e-12)
    ap = points[:, None, :] - a[None, :, :]
    t = np.clip((ap * ab[None]).sum(axis=2) / denom[None], 0.0, 1.0)
    closest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - closest, axis=2).min(axis=1)


def _carve(
    cylinders: np.ndarray, walls: list[Box], start: np.ndarray, goal: np.ndarray, clear: float
) -> tuple[np.ndarray, np.ndarray]:
    """Keep-mask of cylinders after clearing a corridor of half-width ``clear`` (m), and its polyline.

    The corridor follows the cheapest path over the 0.15 m grid from start to goal, where entering a
    cell costs extra for every cylinder that would have to go; rows too close to the side walls are
    not used.
    """
    x_lo = start[0] - CELL / 2
    xs = np.arange(math.floor(x_lo / CELL), math.ceil((goal[0] + CELL) / CELL)) * CELL + CELL / 2
    ys = field_centres()[1]
    gx, gy = np.meshgrid(xs, ys)
    pts = np.c_[gx.ravel(), gy.ravel()]
    passable = (Clearance(np.zeros((0, 2)), walls, CYLINDER_RADIUS)(pts) >= clear).reshape(gx.shape)
    reach = clear + CYLINDER_RADIUS
    count = np.zeros(len(pts))
    if len(cylinders):
        count = np.array([len(n) for n in cKDTree(cylinders).query_ball_point(pts, reach - 1e-9)], dtype=float)
    cost = _CARVE_WEIGHT * count.reshape(gx.shape)
    ys_ok = np.flatnonzero(passable[:, np.argmin(np.abs(xs - FIELD / 2))])  # rows usable between the walls
    if not len(ys_ok):
        raise WorldError(
            f"clutter: robot_radius + margin = {clear - _REF_RES:.3f} m does not fit between the walls {FIELD} m apart"
        )

    def nearest(p: np.ndarray) -> int:
        i = ys_ok[np.argmin(np.abs(ys[ys_ok] - p[1]))]
        return int(i * len(xs) + np.argmin(np.abs(xs - p[0])))

    cells = _grid_dijkstra(passable, cost, CELL, nearest(start), nearest(goal))
    if cells is None:  # cannot happen: the rows between the walls are all passable
        raise WorldError("clutter: no corridor between the walls")
    poly = np.vstack([start, pts[cells], goal])
    if not len(cylinders):
        return np.zeros(0, dtype=bool), poly
    return _segment_distances(cylinders, poly) >= reach, poly


# ------------------------------------------------------------------------------- reference path
def _search_grid(walls: list[Box], goal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centre x and y (m) of the 0.05 m grid the reference path is searched on."""
    x0 = min(w.x - w.sx / 2 for w in walls) - 0.25
    x1 = goal[0] + 1.0
    y1 = FIELD / 2 + WALL_THICKNESS + 0.5
    xs = np.arange(x0 + _REF_RES / 2, x1, _REF_RES)
    ys = np.arange(-y1 + _REF_RES / 2, y1, _REF_RES)
    return xs, ys


def _free_grid(
    clearance: Clearance, walls: list[Box], goal: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    xs, ys = _search_grid(walls, goal)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.c_[gx.ravel(), gy.ravel()]
    clear = clearance(pts).reshape(gx.shape)
    return xs, ys, pts, clear >= radius


def _cell_of(xs: np.ndarray, ys: np.ndarray, p: np.ndarray) -> int:
    return int(np.argmin(np.abs(ys - p[1])) * len(xs) + np.argmin(np.abs(xs - p[0])))


def reference_path(
    clearance: Clearance, walls: list[Box], start: np.ndarray, goal: np.ndarray, radius: float
) -> np.ndarray | None:
    """Shortest collision-free path (n, 2) for a disc of ``radius`` from start to goal, or None.

    8-connected Dijkstra over the 0.05 m grid cells whose exact clearance is >= ``radius``, then
    shortened by line of sight: from each vertex, on to the farthest grid-path point it sees (exact
    segment tests against the cylinders and walls).
    """
    xs, ys, pts, free = _free_grid(clearance, walls, goal, radius)
    s, g = _cell_of(xs, ys, start), _cell_of(xs, ys, goal)
    if not (free.ravel()[s] and free.ravel()[g]):
        return None
    cells = _grid_dijkstra(free, np.zeros(free.shape), _REF_RES, s, g)
    if cells is None:
        return None
    raw = np.vstack([start, pts[cells[1:-1]], goal])
    out, i = [raw[0]], 0
    while i < len(raw) - 1:
        seen = np.flatnonzero(clearance.segments_clear(raw[i], raw[i + 2 :], radius))
        i = i + 2 + int(seen[-1]) if len(seen) else i + 1
        out.append(raw[i])
    return np.array(out)


def _connected(free: np.ndarray, a: int, b: int) -> bool:
    labels, _ = ndimage.label(free, structure=np.ones((3, 3)))
    la, lb = labels.ravel()[a], labels.ravel()[b]
    return bool(la and la == lb)


def corridor_exists(world: ClutterWorld, radius: float) -> bool:
    """Whether start and goal are connected through cells with clearance >= ``radius`` (0.05 m grid)."""
    clearance = Clearance(world.cylinders, world.walls, CYLINDER_RADIUS)
    goal = np.array(world.goal[:2])
    xs, ys, _, free = _free_grid(clearance, world.walls, goal, radius)
    return _connected(free, _cell_of(xs, ys, np.array(world.start[:2])), _cell_of(xs, ys, goal))


def bottleneck(
    clearance: Clearance, walls: list[Box], start: np.ndarray, goal: np.ndarray, tol: float = 0.005
) -> float:
    """Half-width (m) of the narrowest passage on the widest route: the largest clearance c for which
    start and goal connect through 0.05 m cells with clearance >= c (bisection to ``tol``)."""
    xs, ys = _search_grid(walls, goal)
    gx, gy = np.meshgrid(xs, ys)
    clear = clearance(np.c_[gx.ravel(), gy.ravel()]).reshape(gx.shape)
    a, b = _cell_of(xs, ys, start), _cell_of(xs, ys, goal)
    lo, hi = 0.0, float(min(clear.ravel()[a], clear.ravel()[b]))
    if _connected(clear >= hi, a, b):
        return hi
    while hi - lo > tol:
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if _connected(clear >= mid, a, b) else (lo, mid)
    return lo


# ------------------------------------------------------------------------------------- generator
def generate_clutter(
    seed: int,
    *,
    fill: float,
    smooth: int,
    robot_radius: float = 0.2,
    margin: float = 0.05,
    fill_threshold: int = 5,
    clear_threshold: int = 1,
) -> ClutterWorld:
    """A BARN-style world from ``seed`` (same seed and options, same world).

    ``fill``: initial fill probability of each field cell (0..1); ``smooth``: cellular-automaton rounds
    (>= 0); ``robot_radius`` (m): the disc the reference path is planned for; the carved corridor is
    clear for ``robot_radius + margin``; ``fill_threshold``/``clear_threshold``: the automaton's
    neighbour counts (see :func:`cellular_automaton`).
    """
    if not 0.0 <= fill <= 1.0:
        raise WorldError(f"clutter: fill must be in [0, 1], got {fill}")
    if smooth < 0 or int(smooth) != smooth:
        raise WorldError(f"clutter: smooth must be an integer >= 0, got {smooth}")
    if not robot_radius > 0.0 or not margin >= 0.0:
        raise WorldError(f"clutter: robot_radius must be > 0 and margin >= 0 m, got {robot_radius}, {margin}")
    if not 0 <= clear_threshold < fill_threshold <= 8:
        raise WorldError(
            "clutter: need 0 <= clear_threshold < fill_threshold <= 8 (neighbour counts), got "
            f"clear_threshold {clear_threshold}, fill_threshold {fill_threshold}"
        )
    rng = np.random.default_rng(seed)
    cells = cellular_automaton(rng, fill, int(smooth), fill_threshold=fill_threshold, clear_threshold=clear_threshold)
    start = np.array([-START_GAP, 0.0])
    goal = start + np.array([GOAL_DISTANCE, 0.0])
    walls = _walls()
    xc, yc = field_centres()
    ii, jj = np.nonzero(cells)
    cylinders = np.c_[xc[jj], yc[ii]]
    # Carve with one fine cell to spare, so the corridor survives discretisation in checks.
    keep, _ = _carve(cylinders, walls, start, goal, robot_radius + margin + _REF_RES)
    carved = int((~keep).sum())
    cells[ii[~keep], jj[~keep]] = False
    cylinders = cylinders[keep] if len(cylinders) else cylinders
    clearance = Clearance(cylinders, walls, CYLINDER_RADIUS)
    path = reference_path(clearance, walls, start, goal, robot_radius)
    if path is None:
        raise WorldError(
            f"clutter: seed {seed}: no collision-free path for robot_radius {robot_radius} m "
            "after carving (a bug: please report the seed and options)"
        )
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    length = float(seg.sum())
    samples = np.vstack(
        [
            a + t * (b - a)
            for a, b in itertools.pairwise(path)
            for t in np.linspace(0.0, 1.0, max(2, math.ceil(np.linalg.norm(b - a) / 0.05)))
        ]
    )
    in_field = (samples[:, 0] >= 0.0) & (samples[:, 0] <= FIELD)
    along = clearance(samples[in_field]) if in_field.any() else np.array([np.inf])
    metrics = {
        "fill_initial": float(fill),
        "fill_final": float(cells.mean()),
        "tortuosity": length / GOAL_DISTANCE,
        "mean_clearance_m": float(np.mean(np.minimum(along, FIELD / 2))),
        "bottleneck_m": bottleneck(clearance, walls, start, goal),
    }
    return ClutterWorld(
        seed=int(seed),
        fill=float(fill),
        smooth=int(smooth),
        robot_radius=float(robot_radius),
        margin=float(margin),
        cells=cells,
        cylinders=cylinders,
        walls=walls,
        start=(float(start[0]), float(start[1]), 0.0),
        goal=(float(goal[0]), float(goal[1]), 0.0),
        reference_path=path,
        reference_path_m=length,
        difficulty=float(cells.mean()),
        carved=carved,
        metrics=metrics,
    )


def suite_parameters(n: int = 50) -> list[tuple[float, int]]:
    """(fill, smooth) of the suite's worlds, easiest first: fill rises from 0.10 to 0.45 while the
    smoothing cycles through 1..4 rounds (scattered to clustered clutter at every level)."""
    if n < 1:
        raise WorldError(f"clutter_suite: n must be >= 1, got {n}")
    return [(round(0.10 + 0.35 * k / max(n - 1, 1), 4), 1 + k % 4) for k in range(n)]


def clutter_suite(n: int = 50, seed: int = 0, *, robot_radius: float = 0.2, margin: float = 0.05) -> list[ClutterWorld]:
    """``n`` worlds of graded difficulty (deterministic for ``seed``): world k has seed ``seed * 1000 + k``."""
    return [
        generate_clutter(seed * 1000 + k, fill=f, smooth=s, robot_radius=robot_radius, margin=margin)
        for k, (f, s) in enumerate(suite_parameters(n))
    ]


# ------------------------------------------------------------------------------------------- SDF
def _sdf(w: ClutterWorld) -> str:
    sx, sy, _ = w.start
    gx, gy, _ = w.goal
    comment = (
        f"navlab BARN-style clutter world: seed {w.seed}, fill {w.fill}, smooth {w.smooth}; "
        f"{len(w.cylinders)} cylinders r {CYLINDER_RADIUS} m on a {CELL} m grid over x 0..{FIELD}, "
        f"y {-FIELD / 2}..{FIELD / 2};\n"
        f"     start ({sx:g}, {sy:g}, yaw 0), goal ({gx:g}, {gy:g}); reference path {w.reference_path_m:.3f} m "
        f"for robot radius {w.robot_radius} m; difficulty (fill after smoothing) {w.difficulty:.4f}"
    )
    walls = [
        link(b.name, b.x, b.y, b.height / 2, box_geometry(b.sx, b.sy, b.height), "0.9 0.9 0.85", parts=f"{b.name}_")
        for b in w.walls
    ]
    models = [static_model("clutter_walls", walls)]
    if len(w.cylinders):
        geometry = cylinder_geometry(CYLINDER_RADIUS, CYLINDER_HEIGHT)
        models.append(
            static_model(
                "clutter_cylinders",
                [
                    link(f"cylinder_{k:03d}", float(x), float(y), CYLINDER_HEIGHT / 2, geometry, "0.3 0.3 0.35")
                    for k, (x, y) in enumerate(w.cylinders)
                ],
            )
        )
    return world_sdf(w.name, models, comment)
