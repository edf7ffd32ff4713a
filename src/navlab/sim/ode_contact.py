"""Gazebo/ODE contact tags of a link → MuJoCo ``solref``/``solimp`` (pure numbers).

ODE turns a contact's stiffness ``kp`` (N/m) and damping ``kd`` (N s/m) into a spring-damper on the
penetration, integrated implicitly with Gazebo's physics step ``h`` (default 1 ms), whose implicit Euler
adds a damping ratio of about ``omega h / 2``. MuJoCo's positive ``solref`` = (time constant, damping ratio)
is that spring-damper per unit mass: ``k = 1 / (tc dr)^2``, ``b = 2 / tc`` (``solimp``'s ``dmax`` near 1), so
with the supported mass ``m`` per contact, ``omega = sqrt(kp / m)``, ``zeta = kd / (2 sqrt(kp m)) + omega h / 2``,
``dr = zeta`` and ``tc = 1 / (omega zeta)``. ``minDepth`` (the penetration ODE leaves uncorrected) sets the
width of ``solimp``'s impedance ramp. ``maxVel`` (the fastest ODE pushes a contact apart) has no MuJoCo
counterpart; MuJoCo's time constant bounds the same thing (the penetration divided by ``tc``).

Friction: MuJoCo's elliptic cone is the isotropic Coulomb friction of Gazebo's ``cone_model``; ``mu1`` along
``fdir1`` and ``mu2`` across it become the smaller of the two (MuJoCo's contact frame cannot follow ``fdir1``),
which is also what ODE applies to a wheel sliding along its diagonal.
"""

from __future__ import annotations

import math

from navlab.description import ContactTags

ODE_STEP = 0.001  # s: Gazebo's default max_step_size, the step whose implicit Euler damps ODE's contacts


#: Skid-steer wheels (measured, jackal_skid at a 2 ms step): MuJoCo's stiff default contact makes four wheels
#: that scrub sideways rock from side to side every few steps (two of the four contacts lost 2/3 of the time,
#: the robot turning at 0.09 of its command). A softer contact — impedance from 0.5, time constant >= 20 ms,
#: critically damped, its impedance ramp >= 2 mm wide — keeps all four down and turns at the Coulomb figure
#: (see tests/sim/test_skid_steer.py).
SKID_SOLREF_MIN = (0.03, 1.0)
SKID_SOLIMP_D0 = 0.5
SKID_SOLIMP_WIDTH = 0.002  # m: the impedance ramp's least width (1 mm still lets the robot hop)


def contact_solref(
    tags: ContactTags | None, mass: float, *, timestep: float, default: tuple[float, float], skid: bool = False
) -> tuple[float, float]:
    """MuJoCo ``solref`` (time constant s, damping ratio) of a contact carrying ``mass`` (kg) with ODE's
    ``kp``/``kd``; ``default`` without ``kp``. The time constant is kept >= 2 ``timestep`` (MuJoCo's stable range);
    ``skid``: a skid-steer wheel, kept at least as soft as SKID_SOLREF_MIN."""
    if tags is None or not tags.kp or mass <= 0:
        tc, zeta = default
    else:
        kp, kd = tags.kp, tags.kd or 0.0
        omega = math.sqrt(kp / mass)
        zeta = kd / (2.0 * math.sqrt(kp * mass)) + omega * ODE_STEP / 2.0
        tc = max(1.0 / (omega * zeta), 2.0 * timestep)
    if skid:
        return max(tc, SKID_SOLREF_MIN[0]), max(zeta, SKID_SOLREF_MIN[1])
    return tc, zeta


def contact_solimp(tags: ContactTags | None, *, default: tuple[float, ...], skid: bool = False) -> tuple[float, ...]:
    """MuJoCo ``solimp``: ``default`` (d0, dmax, width, midpoint, power), with the impedance ramp as wide as
    ``minDepth`` (m) when given; ``skid``: starting at SKID_SOLIMP_D0."""
    d0, dmax, width, mid, power = default
    if skid:
        d0 = min(d0, SKID_SOLIMP_D0)
    if tags is not None and tags.min_depth:
        width = max(tags.min_depth, 1e-5)
    if skid:
        width = max(width, SKID_SOLIMP_WIDTH)
    return d0, dmax, width, mid, power
    return d0, dmax, max(tags.min_depth, 1e-5), mid, power


def combined_mu(mu1: float | None, mu2: float | None) -> float | None:
    """The friction coefficient MuJoCo gets for a link's ``mu1``/``mu2`` (None: neither given)."""
    mus = [m for m in (mu1, mu2) if m is not None]
    return float(min(mus)) if mus else None
