"""GMapping-style Rao-Blackwellized particle filter SLAM (Grisetti, Stachniss, Burgard 2007).

Each particle carries a pose, a trajectory and its own occupancy map. For every scan the particles
move by the odometry step with GMapping's motion noise (srr, srt, str, stt); once the robot has moved
``linearUpdate`` m or turned ``angularUpdate`` rad (or ``temporalUpdate`` s passed), each particle's
pose is improved by GMapping's hill-climbing scan matcher against its own map (the scan-matching
proposal), its weight gains the scan's log-likelihood, particles are resampled when N_eff drops below
``resampleThreshold`` * N, and each map integrates the scan. Parameter names and defaults are
GMapping's. Pure: numpy in, poses and maps out; the random generator is passed in.

The particles' maps are copy-on-write tiles in one shared pool (``gmapping_tiles``), as GMapping's
reference-counted patches are: a resampled particle copies its source's small tile table, and a tile is
copied only when a particle writes into one it shares. The maps grow as GMapping's ``ScanMatcherMap``
does: they start around the first scan and gain whole tiles (every cell staying where it is) when a scan
to integrate reaches past them; cells outside a map read as unknown, which is what an unseen cell holds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from navlab.core import ParamSpec, check_ceiling
from navlab.geometry import between2, compose2, wrap_angle
from navlab.grid import GridMap
from navlab.mapping.errors import MappingError
from navlab.mapping.gmapping_match import Scan, draw_motion, match_score, optimize
from navlab.mapping.gmapping_tiles import TILE, TilePool, raycast_tiles, tiles_for, to_dense
from navlab.mapping.occupancy import L_CLAMP, L_FREE, L_OCC, logodds_to_grid, scan_cells

MAP_MARGIN_CELLS = 20  # unknown cells kept around what the scans reached, in maps allocated, grown or published


@dataclass
class GMappingParams:
    """slam_gmapping's parameters (ROS names and defaults; lengths m, angles rad, times s)."""

    particles: int = 30
    linearUpdate: float = 1.0
    angularUpdate: float = 0.5
    temporalUpdate: float = -1.0
    delta: float = 0.05
    maxUrange: float = 80.0
    maxRange: float = 0.0
    sigma: float = 0.05
    kernelSize: int = 1
    lstep: float = 0.05
    astep: float = 0.05
    iterations: int = 5
    lsigma: float = 0.075
    ogain: float = 3.0
    lskip: int = 0
    minimumScore: float = 0.0
    srr: float = 0.1
    srt: float = 0.2
    str: float = 0.1
    stt: float = 0.2
    resampleThreshold: float = 0.5
    # slam_gmapping's initial map extent; here maps start at the first scan and grow, and these only
    # place the cell lattice (its corner: the start pose minus the laser's reach, clipped to xmin, ymin)
    xmin: float = -100.0
    ymin: float = -100.0
    xmax: float = 100.0
    ymax: float = 100.0
    llsamplerange: float = 0.01
    llsamplestep: float = 0.01
    lasamplerange: float = 0.005
    lasamplestep: float = 0.005
    occ_thresh: float = 0.25
    # navlab: at the end, match every scan that fell between map updates against the best particle's map
    # (its pose otherwise comes from the odometry since the last update; sparse logs skip many scans)
    refineSkipped: bool = True
    # navlab: with refineSkipped, the scans that updated the maps are matched against that map too (every
    # pose then comes from the one final map, not some from the particles' maps as they were then)
    refineUpdated: bool = True
    # navlab: the kernel of those final matches (as GMapping's sigma, m²); 0: 2 delta², so that exp(-d²/sigma)
    # falls to 1/e at one cell diagonal (GMapping's freeCellRatio cells). sigma (0.05: 1/e at 4.5 cells) suits
    # the filter's proposal, whose particles must find a map they only partly match; against the finished map
    # a kernel of the cells' own scale tells apart end points that sigma scores alike
    refineSigma: float = 0.0
    # navlab: then refine all poses with dense verified scan-to-scan constraints (mapping.refine)
    refine: bool = True
    # navlab: a match that scores under ``wideScore`` per scored beam is retried from starts turned by
    # ``wideStep`` up to ``wideTurn`` rad either way (the hill climb's reach is a few astep; real odometry
    # can be 20-30 degrees off in a fast turn), and the best-scoring result is kept; 0 turns this off.
    # The turned starts are climbed on every (wideSkip + 1)-th scored beam (a cheap look at where each
    # leads), then the best of them once on every beam; wideSkip 0 climbs every turned start in full.
    # 0.65, not 0.7: 0.7 retried 22 % of CSAIL's particle matches, 0.65 17 %, the filter alone as accurate
    # (docs/mapping.md) for ~1 s less CPU
    wideScore: float = 0.65
    wideStep: float = 0.0873
    wideTurn: float = 0.524
    wideSkip: int = 3

    PARAMS: ClassVar[ParamSpec] = ParamSpec("gmapping", MappingError, at_least={"particles": 1})

    def validate(self) -> None:
        """The particle count's ceiling."""
        check_ceiling(MappingError, "gmapping", "particles", self.particles, "particles")


class _Particle:
    """A particle's map (its table of tiles), trajectory and weight (its pose is row n of ``GMapping.poses``)."""

    __slots__ = ("node", "table", "weight", "weight_sum")

    def __init__(self, table: np.ndarray, node: tuple | None, weight: float = 0.0, weight_sum: float = 0.0) -> None:
        self.table = table
        self.node = node  # trajectory: (scan index, pose, parent node)
        self.weight = weight  # log-likelihood since the last resampling
        self.weight_sum = weight_sum  # ... over the whole trajectory (GMapping's weightSum: picks the best)


def _readings(ranges: np.ndarray, no_return: float | None) -> np.ndarray:
    """Ranges as contiguous float64, non-finite readings replaced by ``no_return`` (if given)."""
    r = np.asarray(ranges, dtype=np.float64)
    return np.ascontiguousarray(r if no_return is None else np.where(np.isfinite(r), r, no_return))


def _between(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """``geometry.between2(a, b)`` with the same arithmetic (bit for bit), as floats: it runs on every scan."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    c, s = math.cos(a2), math.sin(a2)
    i0, i1, i2 = -c * a0 - s * a1, s * a0 - c * a1, -a2
    c, s = math.cos(i2), math.sin(i2)
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return i0 + c * b0 - s * b1, i1 + s * b0 + c * b1, (i2 + b2 + math.pi) % (2.0 * math.pi) - math.pi


def _scored_beams(scan: Scan, skip: int) -> int:
    """How many beams the matcher scores with ``skip``: every ``skip + 1``-th with a range in (0, max_urange)."""
    scored = scan[0][:: skip + 1]
    return int(np.count_nonzero((scored > 0) & (scored < scan[3])))


class GMapping:
    """The RBPF. ``add_scan`` takes laser ranges and the laser's odometry pose; poses are laser poses."""

    def __init__(self, params: GMappingParams | None = None, *, rng: np.random.Generator | None = None) -> None:
        self.p = params or GMappingParams()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.particles: list[_Particle] = []
        self.poses = np.zeros((0, 3))  # the particles' laser poses (N, 3), row n particle n's
        self._best = 0  # index of the particle with the highest weight (weights change at map updates only)
        self._anchor = np.zeros(2)  # map-frame corner (m) of lattice cell (0, 0)
        self._offset = np.zeros(2, dtype=np.int64)  # lattice (column, row) of every map's cell (0, 0)
        self.pool = TilePool()  # the tiles of every particle's map
        # lattice (column, row) box holding every cell any particle has written (the published map's extent)
        self._seen = (np.zeros(2, dtype=np.int64), np.zeros(2, dtype=np.int64))
        self._scan_tiles = 1  # tiles the scan being integrated can touch (at most): free tiles to have at hand
        self.resamples = 0
        self.updates = 0
        self.map_resizes = 0
        self.tiles_in_use = 0  # map tiles held by the particles after the last update (each 64 x 64 float32)
        self._odom_last: np.ndarray | None = None
        self._odom_at_update: np.ndarray | None = None
        self._time = 0.0
        self._time_at_update = -math.inf
        self._scan_count = 0
        self._scan_ref: list[tuple[int, np.ndarray]] = []  # per scan: (last updated scan, odom step since)
        self._last_update_scan = -1
        self._odom_by_scan: dict[int, np.ndarray] = {}
        self._scan_data: dict[int, tuple[np.ndarray, np.ndarray, float]] = {}  # scans between updates (refineSkipped)
        self.keep_scans = False  # keep scans between updates for ``finish`` (offline; a live node never finishes)
        self.keep_history = True  # per-scan odometry for ``finish``; the live node turns it off (bounded memory)

    # --- map bookkeeping ----------------------------------------------------------------------------

    @property
    def origin(self) -> np.ndarray:
        """Map-frame (x, y) (m) of the lower-left corner of the particles' maps (they share one window)."""
        return self._anchor + self._offset * self.p.delta

    def _cover(self, poses: np.ndarray, r: np.ndarray, ang: np.ndarray, max_urange: float, max_range: float) -> None:
        """Grow every particle's table by whole tiles (cells stay put) to hold the scan integrated from
        ``poses``, and note how many tiles that scan can touch."""
        lo, hi = scan_cells(
            poses,
            r,
            ang,
            (float(self._anchor[0]), float(self._anchor[1])),
            self.p.delta,
            max_urange=max_urange,
            max_range=max_range,
        )
        self._seen = (np.minimum(self._seen[0], lo), np.maximum(self._seen[1], hi))
        th, tw = self.particles[0].table.shape
        t_lo, t_hi = (lo - self._offset) // TILE, (hi - self._offset) // TILE  # (column, row) of tiles
        self._scan_tiles = int(np.prod(t_hi - t_lo + 1))
        # a side that grows gains a tile more than it needs (fewer, and still cheap, growths)
        left, bottom = (max(0, 1 - int(t)) if t < 0 else 0 for t in t_lo)
        right, top = (max(0, int(t) - n + 2) if t >= n else 0 for t, n in zip(t_hi, (tw, th), strict=True))
        if left or right or bottom or top:
            self._check_size((th + bottom + top) * TILE, (tw + left + right) * TILE)  # (if no tile were shared)
            for part in self.particles:
                part.table = np.pad(part.table, ((bottom, top), (left, right)))
            self._offset = self._offset - TILE * np.array([left, bottom])
            self.map_resizes += 1

    # --- the filter ---------------------------------------------------------------------------------

    def _sample_motion_all(self, step: tuple[float, float, float]) -> None:
        """GMapping's MotionModel::drawFromMotion for all particles (in place): the odometry step plus noise
        scaled by its translation and rotation (srr, srt, str, stt)."""
        p = self.p
        dist = math.hypot(step[0], step[1])
        rot = abs(math.atan2(math.sin(step[2]), math.cos(step[2])))
        sig = (p.srr * abs(step[0]) + p.str * rot, p.srr * abs(step[1]) + p.str * rot, p.stt * rot + p.srt * dist)
        draw_motion(self.poses, self.rng.normal(0.0, 1.0, self.poses.shape), *step, *sig)

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_pose: np.ndarray | tuple[float, float, float],
        *,
        stamp: float | None = None,
        no_return: float | None = None,
    ) -> np.ndarray:
        """Process one scan with the laser at ``odom_pose`` (odometry frame); returns the best particle's pose.
        ``no_return``: the range a non-finite reading counts as (slam_gmapping: the scan's ``range_max``);
        the ranges are read only by the scans that update the map (or are kept for ``finish``)."""
        p = self.p
        odom = np.asarray(odom_pose, dtype=np.float64)
        self._time = stamp if stamp is not None else self._time + 1.0
        k = self._scan_count
        self._scan_count += 1
        if self.keep_history:  # finish() needs every scan's odometry; a live node never finishes
            self._odom_by_scan[k] = odom
        if not self.particles:
            r = _readings(ranges, no_return)
            ang, max_range, max_urange = self._beams(r, angle_min, angle_increment)
            self._init(odom, r, ang, max_urange, max_range)
            self._odom_last = odom
            self._odom_at_update = odom
            self._time_at_update = self._time
            self._mark_update(k)
            return odom.copy()
        assert self._odom_last is not None and self._odom_at_update is not None  # set with the first particles
        self._sample_motion_all(_between(self._odom_last, odom))
        self._odom_last = odom
        moved = _between(self._odom_at_update, odom)
        due = (
            math.hypot(moved[0], moved[1]) >= p.linearUpdate
            or abs(moved[2]) >= p.angularUpdate
            or (p.temporalUpdate >= 0 and self._time - self._time_at_update > p.temporalUpdate)
        )
        if due:
            r = _readings(ranges, no_return)
            ang, max_range, max_urange = self._beams(r, angle_min, angle_increment)
            self._update(k, r, ang, max_urange, max_range)
            if p.refineSkipped and p.refineUpdated and self.keep_scans:
                self._scan_data[k] = (r, ang, max_urange)
            self._odom_at_update = odom
            self._time_at_update = self._time
        elif self.keep_history:  # live, these per-scan records would grow by 40 a second without being read
            self._scan_ref.append((self._last_update_scan, between2(self._odom_by_scan[self._last_update_scan], odom)))
            if p.refineSkipped and self.keep_scans:
                r = _readings(ranges, no_return)
                ang, _max_range, max_urange = self._beams(r, angle_min, angle_increment)
                self._scan_data[k] = (r, ang, max_urange)
        return self.poses[self._best].copy()

    def _beams(self, r: np.ndarray, angle_min: float, angle_increment: float) -> tuple[np.ndarray, float, float]:
        """(beam angles, maxRange, maxUrange) of a scan; a ``maxRange`` of 0 is its longest finite reading.
        Only scans that are integrated or kept need them (not the ~40 a second between map updates)."""
        p = self.p
        ang = angle_min + angle_increment * np.arange(len(r))
        max_range = p.maxRange if p.maxRange > 0 else float(np.nanmax(np.where(np.isfinite(r), r, 0))) + 1e-3
        return ang, max_range, min(p.maxUrange, max_range)

    def _check_size(self, rows: int, cols: int) -> None:
        """Every particle holds a map: refuse maps that together would not fit the machine's memory."""
        check_ceiling(
            MappingError,
            "gmapping",
            "particles x map cells (the map spans the scans' reach at delta)",
            float(self.p.particles) * rows * cols,
            "slam_particle_cells",
        )

    def _init(self, odom: np.ndarray, r: np.ndarray, ang: np.ndarray, max_urange: float, max_range: float) -> None:
        p = self.p
        reach = min(max_urange, 30.0) + 2.0
        lo = np.minimum(np.maximum([p.xmin, p.ymin], odom[:2] - reach), odom[:2] - 1.0)
        self._anchor = np.floor(lo / p.delta) * p.delta
        cells_lo, cells_hi = scan_cells(
            odom,
            r,
            ang,
            (float(self._anchor[0]), float(self._anchor[1])),
            p.delta,
            max_urange=max_urange,
            max_range=max_range,
        )
        self._offset = cells_lo - MAP_MARGIN_CELLS
        self._seen = (cells_lo, cells_hi)
        w, h = (cells_hi - cells_lo + 1 + 2 * MAP_MARGIN_CELLS).tolist()
        self._check_size(h, w)
        table = np.zeros(tiles_for((h, w)), dtype=np.int64)
        self._scan_tiles = table.size
        self.pool.recount([table])
        self._integrate(table, odom, r, ang, max_urange, max_range)
        node = (0, odom.copy(), None)
        self.particles = [_Particle(table.copy(), node) for _ in range(p.particles)]
        self.pool.recount([q.table for q in self.particles])
        self.poses = np.tile(odom, (p.particles, 1))
        self._best = 0

    def _integrate(
        self, table: np.ndarray, pose: np.ndarray, r: np.ndarray, ang: np.ndarray, max_urange: float, max_range: float
    ) -> None:
        """Ray-cast the scan into the map of ``table`` (copying the tiles it shares before writing them)."""
        free = self.pool.free(self._scan_tiles)  # (may grow the pool: its arrays are read after)
        cow = (
            self.pool.tiles,
            self.pool.masks,
            self.pool.means,
            table,
            self.pool.refs,
            free,
            np.zeros(1, dtype=np.int64),
        )
        at = (float(pose[0]), float(pose[1]), float(pose[2]))
        raycast_tiles(*cow, self._lattice(), at, (r, ang, max_urange, max_range), (L_OCC, L_FREE, L_CLAMP))

    def _lattice(self) -> tuple[float, float, int, int, float]:
        """(anchor x, anchor y, offset column, offset row, cell size) as the numba kernels take them."""
        return float(self._anchor[0]), float(self._anchor[1]), int(self._offset[0]), int(self._offset[1]), self.p.delta

    def _model(self, sigma: float | None = None) -> tuple[int, float, float, int]:
        """The matcher's (kernelSize, sigma (or ``sigma``), lsigma, lskip) as the numba kernels take them."""
        p = self.p
        return p.kernelSize, p.sigma if sigma is None else sigma, p.lsigma, p.lskip

    def _mark_update(self, k: int) -> None:
        if self.keep_history:
            self._scan_ref.append((k, np.zeros(3)))
        self._last_update_scan = k

    def _update(self, k: int, r: np.ndarray, ang: np.ndarray, max_urange: float, max_range: float) -> None:
        p = self.p
        self.updates += 1
        lattice = self._lattice()
        scan, model = (r, np.cos(ang), np.sin(ang), max_urange), self._model()
        poses = self.poses
        pool = self.pool  # (its arrays are read at each use: growing it moves them)
        for part, pose in zip(self.particles, poses, strict=True):
            x, y, t, score, lik = self._match(part.table, pose, scan)
            matched = score > p.minimumScore
            if matched:
                pose[:] = x, y, wrap_angle(t)
            if not matched or pose[2] != t:  # the weight takes the log-likelihood at another pose
                _s, lik, _n = match_score(
                    pool.tiles, pool.masks, pool.means, part.table, lattice, (pose[0], pose[1], pose[2]), scan, model
                )
            part.weight += lik
            part.weight_sum += lik
        # normalise (GMapping: gain 1 / (ogain * N)) and resample on N_eff
        lw = np.array([q.weight for q in self.particles])
        w = np.exp((lw - lw.max()) / (p.ogain * len(lw)))
        w /= w.sum()
        neff = 1.0 / float(np.sum(w**2))
        copy_of = list(range(len(self.particles)))  # particle n's map is particle copy_of[n]'s (resampling)
        if neff < p.resampleThreshold * len(w):
            self.resamples += 1
            # systematic resampling
            pos = (self.rng.random() + np.arange(len(w))) / len(w)
            idx = np.minimum(np.searchsorted(np.cumsum(w), pos), len(w) - 1)
            first: dict[int, int] = {}
            new = []
            for n, i in enumerate(idx):
                src = self.particles[int(i)]
                # a copy of a particle drawn before takes that one's table once it has integrated the scan
                # (same map, same pose: the same result); until then it holds only unknown tiles
                copy_of[n] = first.setdefault(int(i), n)
                table = src.table.copy() if copy_of[n] == n else np.zeros_like(src.table)
                new.append(_Particle(table, src.node, 0.0, src.weight_sum))
            self.particles = new
            self.poses = self.poses[idx]  # a copy
            self.pool.recount([q.table for q in new])  # the dropped particles' tiles are free
        # grow the maps (by whole tiles) to hold this scan from every particle
        self._cover(self.poses, r, ang, max_urange, max_range)
        for n, part in enumerate(self.particles):
            part.node = (k, self.poses[n].copy(), part.node)
            if copy_of[n] != n:
                part.table = self.particles[copy_of[n]].table.copy()  # shares every tile
                np.add.at(self.pool.refs, part.table.ravel(), 1)
            else:
                self._integrate(part.table, self.poses[n], r, ang, max_urange, max_range)
        weights = [q.weight_sum for q in self.particles]
        self._best = weights.index(max(weights))
        self.tiles_in_use = self.pool.in_use()
        self._mark_update(k)

    # --- results ------------------------------------------------------------------------------------

    def best(self) -> _Particle:
        """The particle with the highest accumulated weight (the first of equals)."""
        return self.particles[self._best]

    def best_pose(self) -> np.ndarray:
        """The best particle's laser pose (a copy)."""
        return self.poses[self._best].copy()

    def trajectory(self) -> dict[int, np.ndarray]:
        """Best particle's pose at every updated scan (scan index -> laser pose)."""
        out: dict[int, np.ndarray] = {}
        node = self.best().node
        while node is not None:
            out[node[0]] = node[1]
            node = node[2]
        return out

    def finish(self) -> np.ndarray:
        """Laser poses (N, 3) for every scan added: updated scans from the best trajectory, the others
        from the preceding updated scan plus the odometry step since."""
        traj = self.trajectory()
        out = np.zeros((self._scan_count, 3))
        for k, (ref, step) in enumerate(self._scan_ref):
            base = traj.get(ref)
            if base is None:  # before resampling histories joined; fall back on odometry
                base = self._odom_by_scan[ref]
            out[k] = compose2(base, step)
            scan = self._scan_data.get(k)
            if scan is not None:  # matched against the best map (a scan between updates; with refineUpdated, all)
                out[k] = self._refine(self.best().table, out[k], *scan)
        return out

    def _refine(
        self, table: np.ndarray, pose: np.ndarray, r: np.ndarray, ang: np.ndarray, max_urange: float
    ) -> np.ndarray:
        """``pose`` improved by the scan matcher, with the ``refineSigma`` kernel, against the map of ``table``
        (unchanged if the match scores too low)."""
        p = self.p
        scan = (r, np.cos(ang), np.sin(ang), max_urange)
        x, y, t, score, _lik = self._match(table, pose, scan, sigma=p.refineSigma or 2.0 * p.delta**2)
        return np.array([x, y, wrap_angle(t)]) if score > p.minimumScore else pose

    def _match(
        self, table: np.ndarray, pose: np.ndarray, scan: Scan, *, sigma: float | None = None
    ) -> tuple[float, float, float, float, float]:
        """GMapping's hill climb of the scan from ``pose`` against the map of ``table``: (x, y, theta, score,
        log-likelihood). A climb that ends under ``wideScore`` per scored beam (stuck: the start was turned
        too far for its steps to reach the scan's place) is retried from starts turned by ``wideStep``,
        ``2 wideStep``, ... up to ``wideTurn`` either way, nearest first, each climbed on every
        ``wideSkip + 1``-th scored beam, until one scores ``wideScore`` per beam it scores; the best of them
        is then climbed on every beam and kept only if it beats the first climb, so the scan turns away
        from its odometry only where the map matches it better there."""
        p = self.p
        fixed = (self.pool.tiles, self.pool.masks, self.pool.means, table, self._lattice())
        model, steps = self._model(sigma), (p.lstep, p.astep, p.iterations)
        best = optimize(*fixed, (pose[0], pose[1], pose[2]), scan, model, steps)
        if p.wideScore <= 0 or p.wideStep <= 0:
            return best
        if best[3] >= p.wideScore * _scored_beams(scan, p.lskip):
            return best
        skip = (p.lskip + 1) * (max(p.wideSkip, 0) + 1) - 1
        look = (model[0], model[1], model[2], skip)
        enough = p.wideScore * _scored_beams(scan, skip)
        top = None
        for n in range(1, int(p.wideTurn / p.wideStep + 1e-9) + 1):
            for turn in (n * p.wideStep, -n * p.wideStep):
                got = optimize(*fixed, (pose[0], pose[1], pose[2] + turn), scan, look, steps)
                if top is None or got[3] > top[3]:
                    top = got
            if top is not None and top[3] >= enough:
                break
        if top is None:
            return best
        if skip != p.lskip:  # the look was cheap: climb the best of it on every beam
            top = optimize(*fixed, (top[0], top[1], top[2]), scan, model, steps)
        return top if top[3] > best[3] else best

    def map(self, *, frame_id: str = "map") -> GridMap:
        """The best particle's occupancy grid: the cells any scan reached plus ``MAP_MARGIN_CELLS``."""
        g = to_dense(self.pool.tiles, self.best().table)
        (c0, r0), (c1, r1) = (
            (self._seen[0] - MAP_MARGIN_CELLS - self._offset).tolist(),
            (self._seen[1] + MAP_MARGIN_CELLS + 1 - self._offset).tolist(),
        )
        c0, r0 = max(c0, 0), max(r0, 0)
        origin = self.origin + np.array([c0, r0]) * self.p.delta
        return logodds_to_grid(
            g[r0:r1, c0:c1].astype(np.float64), self.p.delta, (float(origin[0]), float(origin[1])), frame_id=frame_id
        )
