"""04 — localize the robot with AMCL on a map.

Part 1 runs the particle filter alone in a synthetic room (no simulator): watch the particle
cloud collapse from a uniform spread onto the true pose. Part 2 runs the whole stack (MuJoCo
simulation + map_server + amcl) in room_obstacles.world and prints the error against ground truth.
Pictures go to out/examples/04_localize/.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from navlab.experiments import plot_result, run_localization
from navlab.localization import Amcl, AmclParams, room_field, simulated_scan

OUT = Path("out/examples/04_localize")
OUT.mkdir(parents=True, exist_ok=True)

# --- part 1: the particle filter alone ----------------------------------------------------------
field = room_field()  # an 8 m x 6 m room with three boxes, 5 cm cells
rng = np.random.default_rng(0)  # the laser's noise
amcl = Amcl(field, AmclParams(odom_model_type="diff-corrected"), rng=np.random.default_rng(1))
amcl.global_localization()  # 5000 particles spread over the free space

fig, axes = plt.subplots(1, 3, figsize=(15, 4))
snapshots = {0: axes[0], 10: axes[1], 50: axes[2]}
x, y, yaw = 1.0, 1.0, 0.0  # the true pose; odometry == truth here
for step in range(51):
    if step in snapshots:
        ax = snapshots[step]
        ax.imshow(field.occupied, origin="lower", cmap="Greys", extent=(-0.2, 8.2, -0.2, 6.2))
        ax.set_xlim(-0.2, 8.2)
        ax.set_ylim(-0.2, 6.2)
        ax.plot(amcl.particles[:, 0], amcl.particles[:, 1], ".", ms=1, color="tab:red")
        ax.plot(x, y, "o", color="tab:green")
        ax.set_title(f"step {step}: {amcl.n_particles} particles")
    if step == 50:
        break
    scan = simulated_scan(field, (x, y, yaw), rng)
    amcl.update((x, y, yaw), scan)  # odometry pose (here the odom frame = the map frame)
    x += 0.1  # drive 5 m along the room
ex, ey, eth = amcl.pose_from_odom((x, y, yaw))  # latest map->odom applied to the odometry now
print(f"synthetic room: estimate ({ex:.2f}, {ey:.2f}, {eth:.2f}) vs truth ({x:.2f}, {y:.2f}, {yaw:.2f})")
fig.tight_layout()
fig.savefig(OUT / "particles.png", dpi=90)

# --- part 2: the whole stack in the simulator ----------------------------------------------------
result = run_localization(
    "room_obstacles", global_localization=True, duration=30.0, seed=0, amcl_params={"odom_model_type": "diff-corrected"}
)
for key in ("converged_s", "position_error_mean_m", "yaw_error_mean_deg", "rtf"):
    print(f"{key}: {result.summary[key]}")
print("figure:", plot_result(result, OUT / "localize.png"))
