"""BARN's cluttered worlds (Perille et al. 2020, "Benchmarking Metric Ground Navigation"), generated as its
dataset generator (jackal-map-creation) makes them.

A 30 x 30 grid of 0.15 m cells, each holding a static cylinder of radius 0.075 m (1 m tall) or not. The first
and last rows are filled (the field's side walls); the others are filled at random with probability ``fill``, then
``smooth`` rounds of a cellular automaton run: a cell with >= 5 of its 8 neighbours filled fills, one with <= 1
clears, the others keep their state (neighbours beyond the side walls count as filled, beyond the ends as empty).
The robot's configuration space is the cells whose (2 ``robot_cells`` + 1)^2 window holds no cylinder (BARN's
Jackal: 2 cells, a 5 x 5 window, so its centre keeps >= 0.375 m from every cylinder surface); a draw is kept only
when the largest 4-connected free region touching the first column is the largest one touching the last, else the
automaton is drawn again (BARN throws such worlds away). Nothing is carved. Cylinders inside a filled block (all 8
neighbours filled) are not written, as BARN writes none there. The grid order of parameters is BARN's 300 worlds':
fill 0.15, 0.20, 0.25, 0.30 x 2, 3, 4 smoothing rounds.

World frame (m, rad; BARN's y forward is navlab's x): the field's cells span x in [0, 4.5], y in [-2.25, 2.25];
touching rows of cylinders (here boxes 0.15 m thick along their tangents) close a 4.95 m x 4.2 m start zone before
the field: its sides in line with the field's wall rows, its back 2.925 m behind the start, as BARN's containment
walls. The robot starts 2.1 m before the field facing +x, 0.25 m off its centre line (the challenge's
INIT_POSITION (-2, 3) against the field's centre -2.25), and the goal is 10 m straight ahead, past the field in
the open. ``ClutterWorld.reference_path_m`` is the length of the shortest collision-free path for a disc of
``robot_radius`` (8-connected Dijkstra on a 0.05 m grid of exact clearances, then shortened by line of
sight): navlab's stricter T_opt = reference length / 2 m/s. BARN's own T_opt comes from the path its generator
saves (``ClutterWorld.barn_path``, ``barn_t_opt``: :func:`navlab.world.barn_grid.barn_path`). Worlds are written
as SDF 1.6 ``.world`` files that navlab's :func:`navlab.world.load_world` and Gazebo classic both load.
"""

from __future__ import annotations

import itertools
import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from navlab.deprecation import NavlabDeprecationWarning
from navlab.io import write_text_atomic
from navlab.world.barn_grid import CELL as CELL
from navlab.world.barn_grid import CELLS as CELLS
from navlab.world.barn_grid import FIELD as FIELD
from navlab.world.barn_grid import ROBOT_CELLS as ROBOT_CELLS
from navlab.world.barn_grid import barn_path as barn_path
from navlab.world.barn_grid import barn_path_length as barn_path_length
from navlab.world.barn_grid import cellular_automaton as cellular_automaton
from navlab.world.barn_grid import configuration_space as configuration_space
from navlab.world.barn_grid import field_centres as field_centres
from navlab.world.barn_grid import way_through as way_through
from navlab.world.barn_grid import written_cylinders as written_cylinders
from navlab.world.clutter_geometry import Clearance
from navlab.world.clutter_path import WALL_THICKNESS as WALL_THICKNESS
from navlab.world.clutter_path import Grid as Grid
from navlab.world.clutter_path import bottleneck as bottleneck
from navlab.world.clutter_path import cell_of, connected
from navlab.world.clutter_path import clearance_grid as clearance_grid
from navlab.world.clutter_path import reference_path as reference_path
from navlab.world.errors import WorldError
from navlab.world.sdf_writer import box_geometry, cylinder_geometry, link, static_model, world_sdf

CYLINDER_RADIUS = 0.075  # m
CYLINDER_HEIGHT = 1.0  # m: BARN's unit cylinders
WALL_HEIGHT = 1.0  # m
START_GAP = 2.1  # m from the start to the field's near edge (BARN: start y 3, first cells from y 5.1)
START_Y = -0.25  # m: the start's offset from the field's centre line (BARN: x -2 against -2.25)
START_ZONE = 4.95  # m from the back wall's inner face to the field (BARN: containment from y 0.15 to 5.1)
GOAL_DISTANCE = 10.0  # m from the start to the goal, straight ahead
BARN_SPEED = 2.0  # m/s: BARN's T_opt speed
BARN_FILLS = (0.15, 0.20, 0.25, 0.30)  # BARN's initial fill levels
BARN_SMOOTHS = (2, 3, 4)  # BARN's smoothing rounds
MAX_DRAWS = 50_000  # automaton draws before a world's parameters are refused
_BATCH = 256  # automaton fields drawn at once


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
    (i + 0.5) 0.15 (row 0 lowest y; rows 0 and 29 are the side walls); ``cylinders``: (k, 2) centres of the
    cylinders written (the filled cells but those inside a filled block); ``reference_path``: (n, 2) shortest
    collision-free path for a disc of ``robot_radius``; ``robot_cells``: the configuration space's reach (cells);
    ``attempts``: automaton draws until one had a way through; ``difficulty``: fraction of the 28 inner rows'
    cells holding a cylinder; ``metrics``: more figures: ``fill_initial``, ``fill_final`` (= difficulty),
    ``tortuosity`` (reference length / 10 m), ``mean_clearance_m`` (robot centre to the nearest surface along
    the reference path in the field) and ``bottleneck_m`` (half-width of the narrowest passage on the widest route);
    ``barn_path``: (m, 2) (row, col) cells of the path BARN's generator saves for this field
    (:func:`navlab.world.barn_grid.barn_path`), ``barn_path_m`` its length as the challenge's run.py measures it
    (start, cells, goal), the length BARN's T_opt comes from.
    """

    seed: int
    fill: float
    smooth: int
    robot_radius: float
    robot_cells: int
    cells: np.ndarray
    cylinders: np.ndarray
    walls: list[Box]
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    reference_path: np.ndarray
    reference_path_m: float
    difficulty: float
    attempts: int
    metrics: dict[str, float] = field(default_factory=dict)
    barn_path: np.ndarray | None = None
    barn_path_m: float | None = None

    @property
    def name(self) -> str:
        """World name used in the SDF (``clutter_s<seed>_f<fill>_k<smooth>``)."""
        return f"clutter_s{self.seed}_f{round(self.fill * 100):02d}_k{self.smooth}"

    def t_opt(self, speed: float = BARN_SPEED) -> float:
        """navlab's optimal traversal time (s): the shortest collision-free path (``reference_path_m``) /
        ``speed`` (m/s); shorter than :meth:`barn_t_opt` but by run.py's offset (see ``barn_grid.RUNNER_OFFSET``), so a
        score with it is stricter than BARN's."""
        return self.reference_path_m / speed

    def barn_t_opt(self, speed: float = BARN_SPEED) -> float:
        """BARN's optimal traversal time (s), as the challenge's run.py computes it: ``barn_path_m`` / ``speed``
        (m/s); :meth:`t_opt` for a world made without BARN's path."""
        return self.t_opt(speed) if self.barn_path_m is None else self.barn_path_m / speed

    def summary(self) -> dict[str, object]:
        """The figures a user reads (JSON-ready): parameters, poses, counts, reference length, difficulty."""
        return {
            "name": self.name,
            "seed": self.seed,
            "fill": self.fill,
            "smooth": self.smooth,
            "robot_radius": self.robot_radius,
            "robot_cells": self.robot_cells,
            "cylinders": len(self.cylinders),
            "attempts": self.attempts,
            "start": list(self.start),
            "goal": list(self.goal),
            "reference_path_m": round(self.reference_path_m, 4),
            "t_opt_s": round(self.t_opt(), 4),
            "barn_path_m": None if self.barn_path_m is None else round(self.barn_path_m, 4),
            "barn_t_opt_s": round(self.barn_t_opt(), 4),
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
def _walls() -> list[Box]:
    """BARN's containment walls around the start zone: both sides in line with the field's wall rows, from the back
    wall up to the field, and the back wall across the field's whole width."""
    t, half = WALL_THICKNESS, FIELD / 2
    x_back = -START_ZONE - t  # the back wall's outer face
    return [
        Box("wall_left", x_back / 2, half - t / 2, -x_back, t),
        Box("wall_right", x_back / 2, -half + t / 2, -x_back, t),
        Box("wall_back", x_back + t / 2, 0.0, t, FIELD),
    ]


def corridor_exists(world: ClutterWorld, radius: float) -> bool:
    """Whether start and goal are connected through cells with clearance >= ``radius`` (0.05 m grid)."""
    clearance = Clearance(world.cylinders, world.walls, CYLINDER_RADIUS)
    goal = np.array(world.goal[:2])
    xs, ys, _, clear = clearance_grid(clearance, world.walls, goal)
    return connected(clear >= radius, cell_of(xs, ys, np.array(world.start[:2])), cell_of(xs, ys, goal))


# ------------------------------------------------------------------------------------- generator
def guaranteed_clearance(robot_cells: int = ROBOT_CELLS) -> float:
    """Clearance (m) every world keeps for the robot's centre along its way through: (robot_cells + 1) cells to
    the nearest cylinder centre, less its radius (0.375 m for BARN's Jackal, 2 cells)."""
    return (robot_cells + 1) * CELL - CYLINDER_RADIUS


def _check_options(fill: float, smooth: int, robot_radius: float, robot_cells: int, ft: int, ct: int) -> None:
    if not 0.0 <= fill <= 1.0:
        raise WorldError(f"clutter: fill must be in [0, 1], got {fill}")
    if smooth < 0 or int(smooth) != smooth:
        raise WorldError(f"clutter: smooth must be an integer >= 0, got {smooth}")
    if not 0 < robot_radius <= FIELD / 2 - CELL:
        raise WorldError(
            f"clutter: robot_radius must be > 0 m and fit between the walls {FIELD - 2 * CELL:g} m apart, "
            f"got {robot_radius}"
        )
    if robot_cells < 0 or int(robot_cells) != robot_cells or 2 * robot_cells + 1 > CELLS - 2:
        raise WorldError(f"clutter: robot_cells must be an integer in 0..{(CELLS - 3) // 2}, got {robot_cells}")
    if not 0 <= ct < ft <= 8:
        raise WorldError(
            "clutter: need 0 <= clear_threshold < fill_threshold <= 8 (neighbour counts), got "
            f"clear_threshold {ct}, fill_threshold {ft}"
        )


def generate_clutter(
    seed: int,
    *,
    fill: float,
    smooth: int,
    robot_radius: float = 0.2,
    robot_cells: int = ROBOT_CELLS,
    fill_threshold: int = 5,
    clear_threshold: int = 1,
    margin: float | None = None,
) -> ClutterWorld:
    """A BARN world from ``seed`` (same seed and options, same world).

    ``fill``: initial fill probability of each inner cell (0..1); ``smooth``: cellular-automaton rounds (>= 0);
    ``robot_cells``: the configuration space's reach that must connect the field's ends (BARN's Jackal: 2);
    ``robot_radius`` (m): the disc the reference path is planned for (at most :func:`guaranteed_clearance`, or
    a world may have none); ``fill_threshold``/``clear_threshold``: the automaton's neighbour counts (see
    :func:`cellular_automaton`). The automaton is drawn again from the same random stream until the way
    through exists (``attempts``). ``margin`` is deprecated and ignored (nothing is carved any more).
    """
    if margin is not None:
        warnings.warn(
            "generate_clutter(margin=...) is ignored and will be removed: worlds are no longer carved; each is "
            "drawn until the robot's configuration space (robot_cells) connects the field's ends, as BARN's",
            NavlabDeprecationWarning,
            stacklevel=2,
        )
    _check_options(fill, smooth, robot_radius, robot_cells, fill_threshold, clear_threshold)
    rng = np.random.default_rng(seed)
    attempts = 0
    while True:  # draw in batches from one stream: the first field with a way through, as drawn one by one
        batch = min(_BATCH, MAX_DRAWS - attempts)
        stack = cellular_automaton(
            rng, fill, int(smooth), fill_threshold=fill_threshold, clear_threshold=clear_threshold, count=batch
        )
        hits = np.flatnonzero(way_through(configuration_space(stack, int(robot_cells))))
        # BARN also throws away a field its A* finds no path through (none of the suites' fields so far); the
        # path's random end rows come from the same stream, after the batch
        found = next(((int(h), p) for h in hits if (p := barn_path(stack[h], rng, int(robot_cells))) is not None), None)
        if found is not None:
            cells, bpath, attempts = stack[found[0]], found[1], attempts + found[0] + 1
            break
        attempts += batch
        if attempts >= MAX_DRAWS:
            raise WorldError(
                f"clutter: seed {seed}: no way through for robot_cells {robot_cells} in {MAX_DRAWS} draws of fill "
                f"{fill}, smooth {smooth} (BARN's worlds use fill 0.15..0.30); lower fill or robot_cells"
            )
    start = np.array([-START_GAP, START_Y])
    goal = start + np.array([GOAL_DISTANCE, 0.0])
    walls = _walls()
    cylinders = written_cylinders(cells)
    clearance = Clearance(cylinders, walls, CYLINDER_RADIUS)
    grid = clearance_grid(clearance, walls, goal)
    path = reference_path(clearance, walls, start, goal, robot_radius, grid=grid)
    if path is None:
        raise WorldError(
            f"clutter: seed {seed}: no collision-free path for robot_radius {robot_radius} m (every world keeps "
            f"{guaranteed_clearance(int(robot_cells)):.3f} m for robot_cells {robot_cells}); raise robot_cells"
        )
    barn_m = barn_path_length(bpath, start, goal)
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
    difficulty = float(cells[1:-1].mean())
    metrics = {
        "fill_initial": float(fill),
        "fill_final": difficulty,
        "tortuosity": length / GOAL_DISTANCE,
        "mean_clearance_m": float(np.mean(np.minimum(along, FIELD / 2))),
        "bottleneck_m": bottleneck(clearance, walls, start, goal, grid=grid),
    }
    return ClutterWorld(
        seed=int(seed),
        fill=float(fill),
        smooth=int(smooth),
        robot_radius=float(robot_radius),
        robot_cells=int(robot_cells),
        cells=cells,
        cylinders=cylinders,
        walls=walls,
        start=(float(start[0]), float(start[1]), 0.0),
        goal=(float(goal[0]), float(goal[1]), 0.0),
        reference_path=path,
        reference_path_m=length,
        difficulty=difficulty,
        attempts=attempts,
        metrics=metrics,
        barn_path=bpath,
        barn_path_m=barn_m,
    )


def suite_parameters(n: int = 50) -> list[tuple[float, int]]:
    """(fill, smooth) of the suite's worlds, in BARN's order: its 12 parameter sets (fill 0.15, 0.20, 0.25, 0.30,
    each with 2, 3 and 4 smoothing rounds) in equal shares, world k of n taking set 12 k // n."""
    if n < 1:
        raise WorldError(f"clutter_suite: n must be >= 1, got {n}")
    sets = [(f, s) for f in BARN_FILLS for s in BARN_SMOOTHS]
    return [sets[k * len(sets) // n] for k in range(n)]


def clutter_suite(
    n: int = 50, seed: int = 0, *, robot_radius: float = 0.2, margin: float | None = None
) -> list[ClutterWorld]:
    """``n`` worlds of graded difficulty (deterministic for ``seed``): world k has seed ``seed * 1000 + k``."""
    if margin is not None:
        warnings.warn(
            "clutter_suite(margin=...) is ignored and will be removed (nothing is carved any more)",
            NavlabDeprecationWarning,
            stacklevel=2,
        )
    return [
        generate_clutter(seed * 1000 + k, fill=f, smooth=s, robot_radius=robot_radius)
        for k, (f, s) in enumerate(suite_parameters(n))
    ]


# ------------------------------------------------------------------------------------------- SDF
def _sdf(w: ClutterWorld) -> str:
    sx, sy, _ = w.start
    gx, gy, _ = w.goal
    comment = (
        f"navlab BARN clutter world: seed {w.seed}, fill {w.fill}, smooth {w.smooth}, robot_cells {w.robot_cells} "
        f"({w.attempts} draws); {len(w.cylinders)} cylinders r {CYLINDER_RADIUS} m on a {CELL} m grid over "
        f"x 0..{FIELD}, y {-FIELD / 2}..{FIELD / 2};\n"
        f"     start ({sx:g}, {sy:g}, yaw 0), goal ({gx:g}, {gy:g}); reference path {w.reference_path_m:.3f} m "
        f"for robot radius {w.robot_radius} m; difficulty (fill of the inner rows) {w.difficulty:.4f}"
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
