"""Adaptive Monte Carlo Localization — the particle filter of ROS 1 amcl, over numpy arrays.

``Amcl`` holds the particle set in the map frame. Feed it the robot's odometry pose (odom frame)
and a laser scan with ``update``; it applies the odometry motion model once the robot moved
``update_min_d``/``update_min_a``, weights the particles with the laser model, tracks the
short/long-term average likelihood for recovery, and resamples (KLD-sampling, low variance) every
``resample_interval`` updates. ``estimate``/``covariance`` give the heaviest cluster's mean pose.
No topics, no clock: time is whatever the caller's sequence of updates is.

Two deliberate differences from ROS amcl, both following Probabilistic Robotics (Table 8.3):
``w_avg`` is the weighted mean laser score (ROS divides it by the particle count too, so it
jumps when KLD-sampling changes N), and the slow/fast averages are not reset after random
particles are injected (ROS resets them, which stops injection after one burst).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numba import njit

from navlab.core import check_ceiling
from navlab.geometry import wrap_angle
from navlab.localization import sampling
from navlab.localization.errors import LocalizationError
from navlab.localization.field import MapField
from navlab.localization.models import Beams
from navlab.pcg64 import Draws
from navlab.plugins import PluginContext, PluginError, load_plugin


@dataclass
class AmclParams:
    """ROS 1 amcl's filter, laser and odometry parameters (same names, same defaults).

    ``odom_model_type`` and ``laser_model_type`` are plugin names (``navlab.plugins`` kinds
    ``motion_model`` and ``laser_model``; Nav2's spellings such as ``nav2_amcl::DifferentialMotionModel``
    are registered too).
    """

    min_particles: int = 100
    max_particles: int = 5000
    kld_err: float = 0.01
    kld_z: float = 0.99
    update_min_d: float = 0.2  # m
    update_min_a: float = math.pi / 6.0  # rad
    resample_interval: int = 2
    recovery_alpha_slow: float = 0.0
    recovery_alpha_fast: float = 0.0
    selective_resampling: bool = False
    laser_max_beams: int = 30
    laser_min_range: float = -1.0  # m; <= 0: use the scan's range_min
    laser_max_range: float = -1.0  # m; <= 0: use the scan's range_max
    laser_z_hit: float = 0.95
    laser_z_short: float = 0.1
    laser_z_max: float = 0.05
    laser_z_rand: float = 0.05
    laser_sigma_hit: float = 0.2  # m
    laser_lambda_short: float = 0.1
    laser_likelihood_max_dist: float = 2.0  # m
    laser_model_type: str = "likelihood_field"
    odom_model_type: str = "diff"
    odom_alpha1: float = 0.2
    odom_alpha2: float = 0.2
    odom_alpha3: float = 0.2
    odom_alpha4: float = 0.2
    initial_cov_xx: float = 0.5 * 0.5  # m²
    initial_cov_yy: float = 0.5 * 0.5  # m²
    initial_cov_aa: float = (math.pi / 12.0) ** 2  # rad²

    def validate(self) -> None:
        """Raise ``LocalizationError`` naming the first bad parameter."""
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not math.isfinite(v):
                raise LocalizationError(f"amcl parameter {f.name}: expected a finite number, got {v!r}")
        if self.min_particles < 1 or self.max_particles < self.min_particles:
            raise LocalizationError(
                f"amcl parameters min_particles={self.min_particles}, max_particles={self.max_particles}: "
                "expected 1 <= min_particles <= max_particles"
            )
        if not 0 < self.kld_err < 1:
            raise LocalizationError(f"amcl parameter kld_err: expected 0 < kld_err < 1, got {self.kld_err}")
        if self.resample_interval < 1:
            raise LocalizationError(f"amcl parameter resample_interval: expected >= 1, got {self.resample_interval}")
        if self.laser_max_beams < 1:
            raise LocalizationError(f"amcl parameter laser_max_beams: expected >= 1, got {self.laser_max_beams}")
        check_ceiling(LocalizationError, "amcl", "max_particles", self.max_particles, "particles")
        for name in ("laser_sigma_hit", "laser_lambda_short", "laser_likelihood_max_dist"):
            if getattr(self, name) <= 0:
                raise LocalizationError(f"amcl parameter {name}: expected > 0, got {getattr(self, name)}")
        if not 0 < self.kld_z < 1:
            raise LocalizationError(f"amcl parameter kld_z: expected 0 < kld_z < 1, got {self.kld_z}")
        for name in (
            "update_min_d",
            "update_min_a",
            "laser_z_hit",
            "laser_z_short",
            "laser_z_max",
            "laser_z_rand",
            "odom_alpha1",
            "odom_alpha2",
            "odom_alpha3",
            "odom_alpha4",
            "initial_cov_xx",
            "initial_cov_yy",
            "initial_cov_aa",
        ):
            if getattr(self, name) < 0:
                raise LocalizationError(f"amcl parameter {name}: expected >= 0, got {getattr(self, name)}")
        if 0 < self.laser_max_range <= self.laser_min_range:
            raise LocalizationError(
                f"amcl parameters laser_min_range={self.laser_min_range}, laser_max_range="
                f"{self.laser_max_range}: expected laser_min_range < laser_max_range"
            )
        self.motion_model()
        self.laser_model()
        for name in ("recovery_alpha_slow", "recovery_alpha_fast"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise LocalizationError(f"amcl parameter {name}: expected 0..1, got {getattr(self, name)}")
        if self.recovery_alpha_slow > 0 and self.recovery_alpha_fast <= self.recovery_alpha_slow:
            raise LocalizationError(
                "amcl parameters recovery_alpha_fast must exceed recovery_alpha_slow "
                f"(got fast={self.recovery_alpha_fast}, slow={self.recovery_alpha_slow})"
            )

    def motion_model(self) -> Any:
        """The ``odom_model_type`` plugin (a ``MotionModel`` function); an unknown name says "did you mean"."""
        return _plugin("motion_model", "odom_model_type", self.odom_model_type)

    def laser_model(self) -> Any:
        """The ``laser_model_type`` plugin class (a ``LaserModel``, built from the map field and these params)."""
        return _plugin("laser_model", "laser_model_type", self.laser_model_type)


def _plugin(kind: str, param: str, name: str) -> Any:
    try:
        return load_plugin(kind, name, param=f"amcl parameter {param}")
    except PluginError as exc:
        raise LocalizationError(str(exc)) from None


@dataclass(frozen=True)
class Scan:
    """A planar laser scan: ranges (m) at ``angle_min + i * angle_increment`` (rad, laser frame)."""

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float


@njit(cache=True)
def any_in_range(ranges: np.ndarray, range_min: float, range_max: float) -> bool:  # pragma: no cover - compiled
    """Whether one of ``ranges`` (m) lies in [range_min, range_max) (NaN does not)."""
    found = False
    for k in range(ranges.size):
        if range_min <= ranges[k] < range_max:
            found = True
            break
    return found


class Amcl:
    """The particle filter. ``rng`` (a seeded ``numpy.random.Generator``) drives every random draw."""

    def __init__(self, field: MapField, params: AmclParams | None = None, *, rng: np.random.Generator) -> None:
        self.params = params if params is not None else AmclParams()
        self.params.validate()
        self.field = field
        self.rng = rng
        self._draws_of: Draws | None = None  # see _draws
        self.motion_model = self.params.motion_model()
        context = PluginContext(map_field=field, rng=rng)
        self.laser_model = self.params.laser_model().from_params(self.params, context=context)
        self.particles = np.zeros((0, 3))
        self.weights = np.zeros(0)
        self.w_slow = 0.0
        self.w_fast = 0.0
        self.odom_ref: tuple[float, float, float] | None = None
        self.resample_count = 0
        self.n_updates = 0
        self._force = False
        self.estimate: tuple[float, float, float] = (math.nan, math.nan, math.nan)
        self.covariance = np.full((3, 3), math.nan)
        self.clusters: sampling.Clusters | None = None
        # the beams laser_max_beams picks, by (beam count, angle_min, angle_increment, laser_max_beams): (indices,
        # bearings)
        self._picked: tuple[tuple[int, float, float, int], np.ndarray, np.ndarray] | None = None

    # --- initialisation -------------------------------------------------------------------------

    def set_initial_pose(self, x: float, y: float, yaw: float, cov: np.ndarray | None = None) -> None:
        """Spread ``max_particles`` by a Gaussian around (x, y, yaw) (map frame; m, rad).

        ``cov``: 3×3 covariance (default: initial_cov_xx/yy/aa). Raises ``LocalizationError`` for a
        pose that is not finite or lies outside the map.
        """
        p = self.params
        if not all(math.isfinite(float(v)) for v in (x, y, yaw)):
            raise LocalizationError(f"initial pose ({x}, {y}, {yaw}) is not finite; expected numbers (m, m, rad)")
        h, w = self.field.shape
        res = self.field.resolution
        if not self.field.contains(x, y):
            raise LocalizationError(
                f"initial pose ({x:.3f}, {y:.3f}) lies outside the map "
                f"({w}×{h} cells of {res} m from origin {self.field.origin[:2]})"
            )
        if cov is None:
            cov = np.diag([p.initial_cov_xx, p.initial_cov_yy, p.initial_cov_aa])
        cov = np.asarray(cov, dtype=np.float64)
        if cov.shape != (3, 3) or not np.all(np.isfinite(cov)):
            raise LocalizationError(f"initial covariance must be a finite 3×3 matrix, got shape {cov.shape}")
        cov = 0.5 * (cov + cov.T)
        vals, vecs = np.linalg.eigh(cov)
        std = vecs * np.sqrt(np.clip(vals, 0.0, None))
        n = p.max_particles
        pts = self.rng.standard_normal((n, 3)) @ std.T + np.array([x, y, yaw])
        pts[:, 2] = wrap_angle(pts[:, 2])
        self._reset(pts)

    def global_localization(self) -> None:
        """Spread ``max_particles`` uniformly over the free cells of the map (ROS ``global_localization``)."""
        self._reset(self.field.random_free_poses(self.params.max_particles, self.rng))

    def _reset(self, pts: np.ndarray) -> None:
        self.particles = pts
        self.weights = np.full(pts.shape[0], 1.0 / pts.shape[0])
        self.w_slow = self.w_fast = 0.0
        self.resample_count = 0
        self.odom_ref = None  # the next scan sets the odometry reference (no motion from before the reset)
        self._force = True
        self._estimate()

    def request_nomotion_update(self) -> None:
        """Make the next scan update the filter even if the robot has not moved (ROS service)."""
        self._force = True

    # --- update -----------------------------------------------------------------------------------

    def _beams(self, scan: Scan) -> Beams | None:
        """The ``laser_max_beams`` beams spread evenly over the scan, or None when none has a usable return."""
        p = self.params
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        n = ranges.shape[0]
        if n == 0:
            return None
        key = (n, scan.angle_min, scan.angle_increment, p.laser_max_beams)
        if self._picked is None or self._picked[0] != key:  # the same for every scan of one laser: worked out once
            idx = np.unique(np.round(np.linspace(0, n - 1, min(p.laser_max_beams, n))).astype(np.int64))
            self._picked = (key, idx, scan.angle_min + idx * scan.angle_increment)
        _, idx, bearings = self._picked
        r = ranges[idx]
        rmin = p.laser_min_range if p.laser_min_range > 0 else scan.range_min
        rmax = min(p.laser_max_range, scan.range_max) if p.laser_max_range > 0 else scan.range_max
        hit = np.isfinite(r) & (r >= rmin) & (r < rmax)
        if not hit.any():
            return None
        return Beams(bearings, r, hit, float(rmin), float(rmax))

    def update(
        self,
        odom_pose: tuple[float, float, float],
        scan: Scan,
        laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> bool:
        """Process one scan taken at robot odometry pose ``odom_pose`` (odom frame; m, rad).

        ``laser_pose``: the laser in the robot base frame. Returns True if the filter updated
        (enough motion since the last update, or a forced update) and False otherwise — including
        when no beam returned a usable range (all inf/NaN/out of limits), which leaves the filter
        untouched so the motion is applied at the next good scan.
        """
        if self.particles.shape[0] == 0:
            raise LocalizationError("AMCL has no particles: set an initial pose or call global_localization()")
        if not all(math.isfinite(float(v)) for v in odom_pose):
            raise LocalizationError(f"odometry pose {odom_pose} is not finite")
        p = self.params
        odom = (float(odom_pose[0]), float(odom_pose[1]), float(odom_pose[2]))
        if not self.wants_update(odom):
            return False
        beams = self._beams(scan)
        if beams is None:
            return False
        if self.odom_ref is not None:  # moved, or a forced update: apply whatever motion there was
            alphas = (p.odom_alpha1, p.odom_alpha2, p.odom_alpha3, p.odom_alpha4)
            self.motion_model(self.particles, self.odom_ref, odom, alphas, self.rng)
        self.odom_ref = odom
        self._force = False
        score = self.laser_model.weights(self.particles, beams, laser_pose)
        w = self.weights * score
        total = float(w.sum())
        if total > 0 and math.isfinite(total):
            # Probabilistic Robotics' w_avg: the weighted mean likelihood (independent of N).
            w_avg = total / float(self.weights.sum())
            self.weights = w / total
            if self.w_slow == 0.0:
                self.w_slow = self.w_fast = w_avg
            else:
                self.w_slow += p.recovery_alpha_slow * (w_avg - self.w_slow)
                self.w_fast += p.recovery_alpha_fast * (w_avg - self.w_fast)
        else:
            self.weights = np.full(self.weights.shape[0], 1.0 / self.weights.shape[0])
        self.n_updates += 1
        self.resample_count += 1
        if self.resample_count % p.resample_interval == 0:
            n_eff = 1.0 / float(np.sum(self.weights**2))
            if not p.selective_resampling or n_eff < 0.5 * self.weights.shape[0]:
                self._resample()
        self._estimate()
        return True

    def wants_update(self, odom_pose: tuple[float, float, float]) -> bool:
        """Whether a scan at odometry pose ``odom_pose`` would update the filter: the first scan, a forced update,
        or a move of more than ``update_min_d`` (m, along x or y) or ``update_min_a`` (rad) since the last update
        (what :meth:`update` checks first; the node builds the scan only then)."""
        ref = self.odom_ref
        if ref is None or self._force:
            return True
        p = self.params
        dx = float(odom_pose[0]) - ref[0]
        dy = float(odom_pose[1]) - ref[1]
        da = float(wrap_angle(float(odom_pose[2]) - ref[2]))
        return abs(dx) > p.update_min_d or abs(dy) > p.update_min_d or abs(da) > p.update_min_a

    def _resample(self) -> None:
        """KLD-sampling with low-variance draws and random-particle recovery."""
        p = self.params
        m = p.max_particles
        w_diff = 0.0
        if self.w_slow > 0.0 and p.recovery_alpha_slow > 0:
            w_diff = max(0.0, 1.0 - self.w_fast / self.w_slow)
        drawn = sampling.low_variance_indices(self.weights, m, self.rng)
        order = drawn[self._draws().permutation(m)]  # drawn, then shuffled: the candidates are particles[order]
        cand = None  # gathered only when recovery particles replace some of them
        if w_diff > 0.0:
            inject = self.rng.random(m) < w_diff
            k = int(inject.sum())
            if k:
                cand = self.particles[order]
                cand[inject] = self.field.random_free_poses(k, self.rng)
        if cand is None:
            n = sampling.kld_count(self.particles, p.kld_err, p.kld_z, p.min_particles, m, order=order)
        else:
            n = sampling.kld_count(cand, p.kld_err, p.kld_z, p.min_particles, m)
        new = self.particles[sampling.low_variance_indices(self.weights, n, self.rng)]
        if cand is not None:
            inj = inject[:n]
            new[inj] = cand[:n][inj]
        self.particles = new
        self.weights = np.full(n, 1.0 / n)

    def _draws(self) -> Draws:
        """``rng``'s permutations in the compiled loop (NumPy's values and generator state; see ``navlab.pcg64``)."""
        d = self._draws_of
        if d is None or d.gen is not self.rng:
            d = self._draws_of = Draws(self.rng)
        return d

    def _estimate(self) -> None:
        c = sampling.cluster(self.particles, self.weights)
        b = c.best
        self.clusters = c
        self.estimate = (float(c.mean[b, 0]), float(c.mean[b, 1]), float(c.mean[b, 2]))
        self.covariance = c.cov[b].copy()

    def map_to_odom(self) -> tuple[float, float, float]:
        """``map_T_odom`` (x, y, yaw) implied by the estimate and the odometry pose of the last update."""
        if self.odom_ref is None:
            raise LocalizationError("no update yet: map→odom is unknown until the first scan is processed")
        ex, ey, eth = self.estimate
        ox, oy, oth = self.odom_ref
        yaw = eth - oth
        c, s = math.cos(yaw), math.sin(yaw)
        return ex - (c * ox - s * oy), ey - (s * ox + c * oy), float(wrap_angle(yaw))

    def pose_from_odom(self, odom_pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """The robot's map-frame pose now, from its odometry pose now and the latest ``map_T_odom``."""
        mx, my, mth = self.map_to_odom()
        c, s = math.cos(mth), math.sin(mth)
        x, y, th = odom_pose
        return mx + c * x - s * y, my + s * x + c * y, float(wrap_angle(mth + th))

    @property
    def n_particles(self) -> int:
        """Current number of particles."""
        return int(self.particles.shape[0])
