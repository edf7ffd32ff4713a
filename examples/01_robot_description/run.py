"""01 — the robot and its world: load the paper's xacro robot and SDF room, print what the simulator
will get, and draw the room's true occupancy with the robot's footprint.

Run:  python examples/01_robot_description/run.py [--world room_obstacles] [--out room.png]
"""

import argparse
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from navlab import resources
from navlab.description import load_robot
from navlab.world import load_world, occupancy

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--world", default="room_obstacles", help="shipped world name or .world file")
parser.add_argument("--out", default="robot_and_world.png", help="PNG to write")
args = parser.parse_args()

# 1. The robot: mybot.xacro includes mybot.gazebo through $(find mybot_description).
robot = load_robot(resources.robot("mybot"))
print(f"robot {robot.name}: root link {robot.root_link}")
for link in robot.links.values():
    g = link.collisions[0].geometry
    print(f"  {link.name:<13} {g.kind:<9} {g.size}  {link.inertial.mass:g} kg")
dd = robot.diff_drive
print(
    f"diff drive: separation {dd.wheel_separation} m, wheel diameter {dd.wheel_diameter} m, "
    f"torque {dd.max_torque} N m, {dd.command_topic} -> {dd.odometry_topic} ({dd.robot_base_frame})"
)
lidar = robot.lidars[0]
print(
    f"lidar: {lidar.samples} beams at {lidar.update_rate} Hz, {lidar.range_min}-{lidar.range_max} m "
    f"-> {lidar.topic} [{lidar.frame_id}]"
)

# 2. The world: an SDF file with included ground plane and sun, walls and obstacles.
world = load_world(resources.world(args.world) if "." not in args.world else args.world)
print(f"world {world.name}: {len(world.models)} models, step {world.max_step_size} s")

# 3. The true occupancy at lidar height (what a perfect map would show), 5 cm cells.
bounds = (-5.5, -4.5, 5.5, 4.5)
grid = occupancy(world, 0.05, bounds)
print(f"occupied: {grid.mean():.1%} of {grid.shape[1]} x {grid.shape[0]} cells")

fig, ax = plt.subplots(figsize=(7, 6))
ax.imshow(grid, origin="lower", extent=(bounds[0], bounds[2], bounds[1], bounds[3]), cmap="Greys")
r = robot.links["chassis"].collisions[0].geometry.size[0]
ax.add_patch(plt.Circle((0, 0), r, color="tab:orange", label=f"{robot.name} (r {r} m)"))
ax.add_patch(
    plt.Circle(
        (0, 0), lidar.range_min, fill=False, ls="--", color="tab:red", label=f"lidar min range {lidar.range_min} m"
    )
)
ax.arrow(0, 0, 0.4 * math.cos(0), 0.4 * math.sin(0), width=0.03, color="k")
ax.set(xlabel="x (m)", ylabel="y (m)", title=f"{world.name}: true occupancy at 0.05-0.5 m")
ax.legend(loc="upper left", fontsize=8)
fig.savefig(args.out, dpi=100, bbox_inches="tight")
print(f"wrote {args.out}")
