"""AMCL's motion and sensor models (Probabilistic Robotics ch. 5–6, as in ROS 1 amcl).

Motion (``odom_model_type``): the odometry model in ROS amcl's two differential-drive variants,
``diff`` (:func:`sample_motion_diff`, ROS's original, which passes the variance expression as the
standard deviation) and ``diff-corrected`` (:func:`sample_motion_diff_corrected`, square root taken,
as the book writes it). Sensors (``laser_model_type``): :class:`LikelihoodFieldModel` and
:class:`BeamModel`, each returning ROS amcl's per-particle score ``1 + sum(pz**3)`` over the used beams.
The registry in ``navlab.plugins`` maps the ROS (and Nav2) names to these.

The Numba kernels take particle poses in the grid frame (``MapField.to_grid``) and beam endpoints in
the robot base frame (one loop over particles × beams).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple, Self

import numpy as np
from numba import njit

from navlab.geometry import wrap_angle
from navlab.localization.errors import LocalizationError
from navlab.localization.raycast import cast_one
from navlab.plugins import PluginContext

if TYPE_CHECKING:
    from navlab.localization.amcl import AmclParams
    from navlab.localization.field import MapField


class Beams(NamedTuple):
    """The beams of one scan a laser model scores: bearings (rad, laser frame), ranges (m), which of them
    returned a usable hit, and the range limits (m) applied."""

    bearings: np.ndarray
    ranges: np.ndarray
    hit: np.ndarray
    range_min: float
    range_max: float


def _angle_diff(a: np.ndarray | float, b: np.ndarray | float) -> np.ndarray:
    """Smallest signed difference a - b (rad)."""
    return wrap_angle(np.asarray(a) - np.asarray(b))


def _scalar_diff(a: float, b: float) -> float:
    """:func:`_angle_diff` of two numbers, in Python floats (the same operations as NumPy's on 0-d arrays)."""
    return float(wrap_angle(float(a) - float(b)))


def sample_motion_diff(
    particles: np.ndarray,
    odom_old: tuple[float, float, float],
    odom_new: tuple[float, float, float],
    alphas: tuple[float, float, float, float],
    rng: np.random.Generator,
    *,
    corrected: bool = False,
) -> None:
    """Move ``particles`` (N, 3; x, y m, yaw rad; map frame) in place by the odometry delta.

    ``odom_old``/``odom_new``: robot poses in the odom frame before and after the motion.
    ``alphas``: odom_alpha1..4 (rotation noise from rotation, rotation from translation,
    translation from translation, translation from rotation).
    """
    a1, a2, a3, a4 = alphas
    dx = odom_new[0] - odom_old[0]
    dy = odom_new[1] - odom_old[1]
    dth = _scalar_diff(odom_new[2], odom_old[2])
    trans = math.hypot(dx, dy)
    rot1 = 0.0 if trans < 0.01 else _scalar_diff(math.atan2(dy, dx), odom_old[2])
    rot2 = _scalar_diff(dth, rot1)
    # Treat driving backwards like forwards when sizing the noise (as ROS does).
    rot1_n = min(abs(_scalar_diff(rot1, 0.0)), abs(_scalar_diff(rot1, math.pi)))
    rot2_n = min(abs(_scalar_diff(rot2, 0.0)), abs(_scalar_diff(rot2, math.pi)))
    v_rot1 = a1 * rot1_n**2 + a2 * trans**2
    v_trans = a3 * trans**2 + a4 * rot1_n**2 + a4 * rot2_n**2
    v_rot2 = a1 * rot2_n**2 + a2 * trans**2
    if corrected:
        s_rot1, s_trans, s_rot2 = math.sqrt(v_rot1), math.sqrt(v_trans), math.sqrt(v_rot2)
    else:
        s_rot1, s_trans, s_rot2 = v_rot1, v_trans, v_rot2
    n = particles.shape[0]
    noise = rng.standard_normal((3, n))
    # heading, trans_hat, rot2_hat into noise's rows; cos and sin of the heading by NumPy (its SIMD cos and sin
    # differ from libm's), the rest in two compiled passes with NumPy's operations in NumPy's order
    _motion_draws(particles, noise, rot1, s_rot1, trans, s_trans, rot2, s_rot2)
    _motion_apply(particles, noise, np.cos(noise[0]), np.sin(noise[0]))


@njit(cache=True)
def _motion_draws(
    particles: np.ndarray,
    noise: np.ndarray,
    rot1: float,
    s_rot1: float,
    trans: float,
    s_trans: float,
    rot2: float,
    s_rot2: float,
) -> None:  # pragma: no cover - compiled
    """Rows of ``noise`` (3, N) become each particle's heading after the first turn, its translation and its second
    turn (rad, m, rad): ``yaw + (rot1 - s_rot1 * n0)``, ``trans - s_trans * n1``, ``rot2 - s_rot2 * n2``."""
    for k in range(particles.shape[0]):
        noise[0, k] = particles[k, 2] + (rot1 - s_rot1 * noise[0, k])
        noise[1, k] = trans - s_trans * noise[1, k]
        noise[2, k] = rot2 - s_rot2 * noise[2, k]


@njit(cache=True)
def _motion_apply(particles: np.ndarray, moves: np.ndarray, cos_h: np.ndarray, sin_h: np.ndarray) -> None:
    """Move each particle by its row of ``moves`` (:func:`_motion_draws`; heading cosines and sines given); the
    new yaw wrapped to [-pi, pi) as ``geometry.wrap_angle`` does."""
    two_pi = 2.0 * math.pi
    for k in range(particles.shape[0]):
        particles[k, 0] += moves[1, k] * cos_h[k]
        particles[k, 1] += moves[1, k] * sin_h[k]
        particles[k, 2] = ((moves[0, k] + moves[2, k]) + math.pi) % two_pi - math.pi


def sample_motion_diff_corrected(
    particles: np.ndarray,
    odom_old: tuple[float, float, float],
    odom_new: tuple[float, float, float],
    alphas: tuple[float, float, float, float],
    rng: np.random.Generator,
) -> None:
    """ROS amcl's ``diff-corrected`` (Nav2's DifferentialMotionModel): :func:`sample_motion_diff` with the
    noise standard deviations as Probabilistic Robotics writes them."""
    sample_motion_diff(particles, odom_old, odom_new, alphas, rng, corrected=True)


LUT_SIZE = 4096


def gaussian_lut(sigma_hit: float, max_dist: float) -> tuple[np.ndarray, float]:
    """``exp(-d**2 / (2 sigma_hit**2))`` tabulated for d in [0, max_dist]; returns (table, entries per metre)."""
    d = np.linspace(0.0, max_dist, LUT_SIZE)
    return np.exp(-(d**2) / (2.0 * sigma_hit**2)), (LUT_SIZE - 1) / max_dist


@njit(cache=True, fastmath=True)
def _likelihood_field(xs, ys, yaws, bx, by, sdf, inv_res, max_dist, lut, lut_scale, z_hit, z_rand_term, out):
    h, w = sdf.shape
    nb = bx.shape[0]
    for k in range(xs.shape[0]):
        c = math.cos(yaws[k])
        s = math.sin(yaws[k])
        x0 = xs[k]
        y0 = ys[k]
        p = 1.0
        for m in range(nb):
            u = (x0 + c * bx[m] - s * by[m]) * inv_res - 0.5
            v = (y0 + s * bx[m] + c * by[m]) * inv_res - 0.5
            fi = math.floor(u)
            fj = math.floor(v)
            i = int(fi)
            j = int(fj)
            fu = u - fi
            fv = v - fj
            if i >= 0 and i + 1 < w and j >= 0 and j + 1 < h:
                a = sdf[j, i] + fu * (sdf[j, i + 1] - sdf[j, i])
                b = sdf[j + 1, i] + fu * (sdf[j + 1, i + 1] - sdf[j + 1, i])
                d = abs(a + fv * (b - a))
                if d > max_dist:
                    d = max_dist
            else:
                d = max_dist
            pz = z_hit * lut[int(d * lut_scale)] + z_rand_term
            p += pz * pz * pz
        out[k] = p


@njit(cache=True)
def _grid_columns(
    poses: np.ndarray, ox: float, oy: float, oyaw: float, c: float, s: float, out: np.ndarray
) -> None:  # pragma: no cover - compiled
    """``out`` (3, N): the x, y and yaw columns of ``MapField.to_grid(poses)`` (origin ``ox, oy, oyaw``, its
    cosine ``c`` and sine ``s``), with the same operations in the same order."""
    for k in range(poses.shape[0]):
        dx = poses[k, 0] - ox
        dy = poses[k, 1] - oy
        out[0, k] = c * dx + s * dy
        out[1, k] = -s * dx + c * dy
        out[2, k] = poses[k, 2] - oyaw


def likelihood_field_weights(
    poses_grid: np.ndarray,
    end_x: np.ndarray,
    end_y: np.ndarray,
    signed: np.ndarray,
    resolution: float,
    max_dist: float,
    lut: tuple[np.ndarray, float],
    z_hit: float,
    z_rand: float,
    range_max: float,
) -> np.ndarray:
    """Likelihood-field score per particle (ROS amcl's ``1 + sum(pz**3)``).

    ``end_x``/``end_y``: beam endpoints (m) in the base frame (only beams that returned a hit);
    ``signed``: the map's signed distance field (``MapField.signed``); the distance of an endpoint to
    the nearest obstacle is its bilinear interpolation (absolute value, clipped at ``max_dist``),
    so walls sit on cell boundaries rather than half a cell off. ``lut``: from ``gaussian_lut``.
    """
    out = np.empty(poses_grid.shape[0])
    _likelihood_field(
        np.ascontiguousarray(poses_grid[:, 0]),
        np.ascontiguousarray(poses_grid[:, 1]),
        np.ascontiguousarray(poses_grid[:, 2]),
        end_x,
        end_y,
        signed,
        1.0 / resolution,
        max_dist,
        lut[0],
        lut[1],
        z_hit,
        z_rand / range_max,
        out,
    )
    return out


@njit(cache=True, fastmath=True)
def _beam(
    xs,
    ys,
    yaws,
    lx,
    ly,
    lyaw,
    bearings,
    ranges,
    occ,
    res,
    range_max,
    z_hit,
    z_short,
    z_max,
    z_rand,
    sigma_hit,
    lambda_short,
    out,
):
    inv_res = 1.0 / res
    denom = 2.0 * sigma_hit * sigma_hit
    for k in range(xs.shape[0]):
        c = math.cos(yaws[k])
        s = math.sin(yaws[k])
        sx = xs[k] + c * lx - s * ly
        sy = ys[k] + s * lx + c * ly
        syaw = yaws[k] + lyaw
        p = 1.0
        for m in range(bearings.shape[0]):
            obs = ranges[m]
            expected = cast_one(occ, inv_res, res, sx, sy, syaw + bearings[m], range_max)
            z = obs - expected
            pz = z_hit * math.exp(-(z * z) / denom)
            if z < 0:
                pz += z_short * lambda_short * math.exp(-lambda_short * obs)
            if obs >= range_max:
                pz += z_max
            else:
                pz += z_rand / range_max
            p += pz * pz * pz
        out[k] = p


def beam_weights(
    poses_grid: np.ndarray,
    laser_pose: tuple[float, float, float],
    bearings: np.ndarray,
    ranges: np.ndarray,
    occupied: np.ndarray,
    resolution: float,
    range_max: float,
    z: tuple[float, float, float, float],
    sigma_hit: float,
    lambda_short: float,
) -> np.ndarray:
    """Beam-model score per particle; ``ranges`` already clipped to ``range_max`` (max readings kept).

    ``z``: (z_hit, z_short, z_max, z_rand); ``laser_pose``: the laser in the base frame.
    """
    out = np.empty(poses_grid.shape[0])
    z_hit, z_short, z_max, z_rand = (float(v) for v in z)
    _beam(
        np.ascontiguousarray(poses_grid[:, 0]),
        np.ascontiguousarray(poses_grid[:, 1]),
        np.ascontiguousarray(poses_grid[:, 2]),
        float(laser_pose[0]),
        float(laser_pose[1]),
        float(laser_pose[2]),
        np.ascontiguousarray(bearings, dtype=np.float64),
        np.ascontiguousarray(ranges, dtype=np.float64),
        occupied,
        float(resolution),
        float(range_max),
        z_hit,
        z_short,
        z_max,
        z_rand,
        float(sigma_hit),
        float(lambda_short),
        out,
    )
    return out


class FieldModel:
    """What the laser models share: built from amcl's parameters and the map's field (``context.map_field``)."""

    def __init__(self, field: MapField, params: AmclParams) -> None:
        raise NotImplementedError

    @classmethod
    def from_params(cls, params: AmclParams, *, context: PluginContext) -> Self:
        """``params``: ``AmclParams``; ``context.map_field``: the map's ``MapField`` (required)."""
        if context.map_field is None:
            raise LocalizationError(f"laser model {cls.__name__}: needs the map's field (context.map_field)")
        return cls(context.map_field, params)


class LikelihoodFieldModel(FieldModel):
    """``laser_model_type: likelihood_field``: each beam endpoint scored by its distance to the nearest
    obstacle (Gaussian of ``laser_sigma_hit``, mixed with ``laser_z_rand``); beams without a hit are skipped."""

    def __init__(self, field: MapField, params: AmclParams) -> None:
        self.field = field
        self.z_hit = params.laser_z_hit
        self.z_rand = params.laser_z_rand
        self._lut = gaussian_lut(params.laser_sigma_hit, field.max_dist)
        self._signed = np.ascontiguousarray(field.signed)

    def weights(self, particles: np.ndarray, beams: Beams, laser_pose: tuple[float, float, float]) -> np.ndarray:
        """Scores (N,) of ``particles`` (N, 3; map frame) for ``beams`` of a laser at ``laser_pose`` (base frame)."""
        lx, ly, lyaw = laser_pose
        hit = beams.hit
        a = lyaw + beams.bearings[hit]
        rr = beams.ranges[hit]
        ex = np.ascontiguousarray(lx + rr * np.cos(a))
        ey = np.ascontiguousarray(ly + rr * np.sin(a))
        f = self.field
        ox, oy, oyaw = f.origin
        cols = np.empty((3, particles.shape[0]))  # MapField.to_grid's x, y, yaw columns, in one compiled pass
        _grid_columns(particles, ox, oy, oyaw, math.cos(oyaw), math.sin(oyaw), cols)
        out = np.empty(particles.shape[0])
        lut, lut_scale = self._lut
        z_rand = self.z_rand / beams.range_max
        inv_res, zh = 1.0 / f.resolution, self.z_hit
        _likelihood_field(
            cols[0], cols[1], cols[2], ex, ey, self._signed, inv_res, f.max_dist, lut, lut_scale, zh, z_rand, out
        )
        return out


class BeamModel(FieldModel):
    """``laser_model_type: beam``: each beam's range compared with the range ray-cast in the map (hit, short,
    max and random components); max-range readings count as readings of ``range_max``."""

    def __init__(self, field: MapField, params: AmclParams) -> None:
        self.field = field
        self.z = (params.laser_z_hit, params.laser_z_short, params.laser_z_max, params.laser_z_rand)
        self.sigma_hit = params.laser_sigma_hit
        self.lambda_short = params.laser_lambda_short

    def weights(self, particles: np.ndarray, beams: Beams, laser_pose: tuple[float, float, float]) -> np.ndarray:
        """Scores (N,) of ``particles`` (N, 3; map frame) for ``beams`` of a laser at ``laser_pose`` (base frame)."""
        r, rmax = beams.ranges, beams.range_max
        keep = ~np.isnan(r)
        obs = np.where(np.isfinite(r[keep]), np.minimum(r[keep], rmax), rmax)
        f = self.field
        return beam_weights(
            f.to_grid(particles),
            laser_pose,
            beams.bearings[keep],
            obs,
            f.occupied,
            f.resolution,
            rmax,
            self.z,
            self.sigma_hit,
            self.lambda_short,
        )
