"""``navlab bench amcl``: time of one AMCL filter update (2,000 particles, 60 beams, one core).

The robot drives a loop in the synthetic 8 m × 6 m room (5 cm cells); each measured update applies
the odometry motion model, weights every particle with the likelihood-field model and resamples
every second update (ROS's resample_interval 2). The particle count is pinned by setting
min_particles = max_particles = 2000. Scans are ray-cast outside the timed region.
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any

import numpy as np

from navlab.localization import Amcl, AmclParams, room_field, simulated_scan

N_PARTICLES = 2000
N_BEAMS = 60


def _loop_pose(k: int) -> tuple[float, float, float]:
    """Pose k on a 1.1 m-radius circle around (4, 3.2) in free space, 0.25 m apart, facing along it."""
    a = 0.25 * k / 1.1
    return 4.0 + 1.1 * math.cos(a), 3.2 + 1.1 * math.sin(a), float((a + 1.5 * math.pi) % (2 * math.pi) - math.pi)


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Measure ``n`` updates after warm-up (Numba compiled, filter converged); return ms percentiles."""
    seed = int(getattr(args, "seed", 0))
    n = 300
    field = room_field()
    rng = np.random.default_rng(seed)
    params = AmclParams(min_particles=N_PARTICLES, max_particles=N_PARTICLES, laser_max_beams=N_BEAMS)
    amcl = Amcl(field, params, rng=np.random.default_rng(seed + 1))
    amcl.set_initial_pose(*_loop_pose(0))
    times = []
    for k in range(n + 20):
        pose = _loop_pose(k)
        scan = simulated_scan(field, pose, rng)
        odom = (pose[0] - 4.0, pose[1] - 3.2, pose[2])  # odom frame offset from map; exact odometry
        t0 = time.perf_counter()
        updated = amcl.update(odom, scan)
        dt = time.perf_counter() - t0
        if k >= 20 and updated:
            times.append(dt * 1e3)
    t = np.array(times)
    err = math.dist(amcl.pose_from_odom(odom)[:2], pose[:2])
    return {
        "update_ms_p50": round(float(np.percentile(t, 50)), 3),
        "update_ms_p95": round(float(np.percentile(t, 95)), 3),
        "particles": amcl.n_particles,
        "beams": N_BEAMS,
        "updates": len(times),
        "final_error_m": round(err, 4),
    }
