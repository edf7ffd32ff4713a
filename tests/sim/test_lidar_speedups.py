"""The lidar's speed-ups change no range: compiled noise draws are NumPy's, bit for bit; the cast's broad phase
(geoms nearest first, a beam skipping a geom beyond its hit so far; boxes' and cylinders' azimuth spans from their
corners' tangents) gives what testing every geom gives."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from sim_helpers import make_mybot, make_room

from navlab.sim import Simulation, primitive_model
from navlab.sim.lidar_noise import NormalDraws
from navlab.sim.raycast import cast_planar, ray_hit


def test_compiled_draws_are_numpys_and_keep_the_generator_in_step() -> None:
    gen, ref = np.random.default_rng(11), np.random.default_rng(11)
    draws = NormalDraws(gen, 720)
    assert draws.compiled
    for k in range(300):  # 216,000 draws: the ziggurat's wedge and tail paths are taken too
        assert draws.draw().tobytes() == ref.standard_normal(720).tobytes()
        if k % 100 == 0:  # the generator's own draws in between stay in step
            assert gen.random() == ref.random()
    assert gen.bit_generator.state == ref.bit_generator.state


def test_another_bit_generator_draws_with_numpy() -> None:
    gen = np.random.Generator(np.random.Philox(5))
    draws = NormalDraws(gen, 50)
    assert not draws.compiled
    assert draws.draw().tobytes() == np.random.Generator(np.random.Philox(5)).standard_normal(50).tobytes()


def every_beam(
    m: mujoco.MjModel, d: mujoco.MjData, geoms: np.ndarray, origin: np.ndarray, rot: np.ndarray, a: np.ndarray,
    range_min: float, cutoff: float,
) -> np.ndarray:  # fmt: skip
    """The ranges of beams at angles ``a``: the kernel's arithmetic, term by term, for every beam and geom."""
    want = np.full(a.shape[0], np.inf)
    ca, sa = np.cos(a), np.sin(a)
    for g in geoms:
        xm, rel = d.geom_xmat[g], origin - d.geom_xpos[g]
        p = np.array([xm[k] * rel[0] + xm[3 + k] * rel[1] + xm[6 + k] * rel[2] for k in range(3)])
        u = [xm[k] * rot[0, 0] + xm[3 + k] * rot[1, 0] + xm[6 + k] * rot[2, 0] for k in range(3)]
        v = [xm[k] * rot[0, 1] + xm[3 + k] * rot[1, 1] + xm[6 + k] * rot[2, 1] for k in range(3)]
        for i in range(a.shape[0]):
            dl = np.array([u[k] * ca[i] + v[k] * sa[i] for k in range(3)])
            want[i] = min(want[i], ray_hit(m.geom_type[g], m.geom_size[g], p, dl, range_min))
    want[want > cutoff] = np.inf
    return want


def test_cast_equals_every_beam_tested_against_every_geom() -> None:
    """Obstacles in rows behind each other (most beams reach a far geom only through the skip) and a tilted scan."""
    sim = Simulation(make_mybot(noise=0.0), make_room(), seed=0, robot_pose=(-3.0, 0.2, 0.3))
    for k, (x, y) in enumerate([(-1.5, 0.0), (-0.5, 0.3), (0.5, -0.4), (1.5, 0.8), (-1.0, -1.5), (0.0, 1.5)]):
        sim.spawn(primitive_model("box", f"crate{k}", (0.3, 0.4, 0.5), x=x, y=y, yaw=0.3 * k))
        sim.spawn(primitive_model("cylinder", f"drum{k}", (0.15, 0.6), x=x + 0.6, y=y - 0.5))
    sim.step(20)
    m, d = sim.model, sim.data
    geoms = sim._ray_fast
    n = 720
    a = np.linspace(-math.pi, math.pi, n)
    for pitch in (0.0, 0.02):
        c, s = math.cos(pitch), math.sin(pitch)
        rot = d.site_xmat[sim._lidar_site[0]].reshape(3, 3) @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        origin = d.site_xpos[sim._lidar_site[0]].copy()
        got = np.empty(n)
        cast_planar(origin, rot, np.cos(a), np.sin(a), -math.pi, 2 * math.pi / (n - 1), geoms, m.geom_type,
                    m.geom_size, d.geom_xpos, d.geom_xmat, 0.1, 10.0, got)  # fmt: skip
        want = every_beam(m, d, geoms, origin, rot, a, 0.1, 10.0)
        assert np.isfinite(got).sum() > 600
        assert got.tobytes() == want.tobytes()


def test_box_and_cylinder_spans_hold_every_beam_that_hits_from_any_side() -> None:
    """Sensors all round a turned box and a cylinder, near and far, level and tilted, some abeam of a corner: every
    beam the cast returns is what testing every beam against both geoms returns."""
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><geom type="box" size="0.4 0.15 0.3" pos="0 0 0.3" euler="0 0 35"/>'
        '<geom type="cylinder" size="0.2 0.4" pos="1.2 0.5 0.4"/></worldbody></mujoco>'
    )
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    geoms = np.arange(2)
    n = 360
    a = -math.pi + np.arange(n) * (2 * math.pi / n)
    ca, sa = np.cos(a), np.sin(a)
    rng = np.random.default_rng(4)
    for k in range(16):
        r = 0.45 + 0.25 * k if k % 4 else 0.3  # every fourth from inside the box's corner circle
        bearing, yaw, tilt = rng.uniform(-math.pi, math.pi, 3)
        origin = np.array([r * math.cos(bearing), r * math.sin(bearing), 0.3])
        c, s, ct, st = math.cos(yaw), math.sin(yaw), math.cos(0.01 * tilt), math.sin(0.01 * tilt)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
            [[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]]
        )
        got = np.empty(n)
        cast_planar(origin, rot, ca, sa, -math.pi, 2 * math.pi / n, geoms, m.geom_type, m.geom_size, d.geom_xpos,
                    d.geom_xmat, 0.05, 8.0, got)  # fmt: skip
        want = every_beam(m, d, geoms, origin, rot, a, 0.05, 8.0)
        assert np.isfinite(got).sum() > 10
        assert got.tobytes() == want.tobytes(), k
