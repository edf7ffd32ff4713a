"""03 — drive the simulated robot: cmd_vel in, odometry, ground truth and laser scans out.

Starts the MuJoCo simulator with Gazebo's plugins (the paper's mybot in room_obstacles), drives a
0.8 m square with a tiny open-loop "teleop" node, drops a cylinder into the room half-way (as the
paper adds obstacles after mapping), and saves a figure: the true path, the wheel-odometry path and
the last scan, plus a 3-D render of the room.

Run:  python examples/03_drive/run.py [--out drive.png] [--render room.png] [--seed 0]
"""

import argparse
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import navlab
from navlab import msgs
from navlab.core import Node
from navlab.sim import primitive_model

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default="drive.png", help="figure of the paths and the last scan")
parser.add_argument("--render", default="", help="also render the room to this PNG (needs EGL/OSMesa)")
parser.add_argument("--seed", type=int, default=0, help="seed of the sensor noise")
args = parser.parse_args()

SPEED, TURN_RATE, SIDE = 0.4, 1.0, 0.8  # m/s, rad/s, m
LATE_OBSTACLE = primitive_model("cylinder", "late_obstacle", (0.2, 0.6), x=-1.5, y=0.8)  # radius, length (m)


class SquareDriver(Node):
    """Open-loop teleop: forward SIDE metres, turn 90 degrees left, four times (10 Hz cmd_vel)."""

    def __init__(self) -> None:
        super().__init__("square_driver")  # rclpy's constructor: joins the run navlab.init() started
        self.cmd = self.create_publisher(msgs.Twist, "cmd_vel", 10)
        leg, turn = SIDE / SPEED, (math.pi / 2) / TURN_RATE
        self.plan = [(leg, SPEED, 0.0), (turn, 0.0, TURN_RATE)] * 4  # (seconds, v, w)
        self.ends = np.cumsum([p[0] for p in self.plan])
        self.create_timer(0.05, self.tick)

    def tick(self) -> None:
        t = self.get_clock().seconds()
        i = int(np.searchsorted(self.ends, t, side="right"))
        v, w = (self.plan[i][1], self.plan[i][2]) if i < len(self.plan) else (0.0, 0.0)
        self.cmd.publish(msgs.twist(v, w))


class Recorder(Node):
    """Keeps the ground-truth and odometry paths and the last scan."""

    def __init__(self) -> None:
        super().__init__("recorder")
        self.truth, self.odom, self.scan = [], [], None
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self.on_truth)
        self.create_subscription(msgs.Odometry, "odom", self.on_odom)
        self.create_subscription(msgs.LaserScan, "/mybot/laser/scan", self.on_scan)

    def on_truth(self, msg: object) -> None:
        self.truth.append(msgs.pose2d(msg.pose.pose))

    def on_odom(self, msg: object) -> None:
        self.odom.append(msgs.pose2d(msg.pose.pose))

    def on_scan(self, msg: object) -> None:
        self.scan = msg


start = (-0.4, -0.4, 0.0)
# rclpy.init() with the shipped sim launch (like `ros2 launch ... sim.launch.yaml world:=room_obstacles x:=-0.4 ...`)
ctx = navlab.init(launch="sim", world="room_obstacles", robot="mybot", x=start[0], y=start[1], seed=args.seed)
ex = ctx.executor
gazebo = ctx.session.node("gazebo")
SquareDriver()
rec = Recorder()

ex.run(7.0)
gazebo.spawn(LATE_OBSTACLE)  # the paper adds obstacles after the map is made
ex.run(7.0)

truth, odom = np.array(rec.truth), np.array(rec.odom)
odom_world = odom[:, :2] + np.array(start[:2])  # odometry starts at the spawn pose (odom frame = start)
x, y, yaw = gazebo.sim.base_pose2d()
error = math.dist(odom_world[-1], (x, y))
path = float(np.sum(np.linalg.norm(np.diff(truth[:, :2], axis=0), axis=1)))
print(f"drove {path:.2f} m in {ex.now_ns / 1e9:.1f} s; end pose x {x:.3f} y {y:.3f} yaw {math.degrees(yaw):.1f} deg")
print(f"wheel odometry is {error * 100:.1f} cm off the ground truth ({error / path:.1%} of the path)")

fig, ax = plt.subplots(figsize=(7, 6))
ax.plot(truth[:, 0], truth[:, 1], label="ground truth (/ground_truth/odom)", lw=2)
ax.plot(odom_world[:, 0], odom_world[:, 1], "--", label="wheel odometry (/odom)")
scan = rec.scan
ranges = np.asarray(scan.ranges, dtype=float)
angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges)) + yaw
ok = np.isfinite(ranges)
ax.scatter(x + ranges[ok] * np.cos(angles[ok]), y + ranges[ok] * np.sin(angles[ok]), s=2, c="k", label="last scan")
ax.set_aspect("equal")
ax.set_xlabel("x (m)")
ax.set_ylabel("y (m)")
ax.set_title("mybot driving a 0.8 m square in room_obstacles")
ax.legend(loc="upper right", fontsize=8)
fig.savefig(args.out, dpi=120)
print(f"wrote {args.out}")

if args.render:
    from navlab.sim import Simulation, render_image, save_png

    view = Simulation(gazebo.sim.robot, gazebo.sim.world, robot_pose=(x, y, yaw), visuals=True)
    view.spawn(LATE_OBSTACLE)
    save_png(render_image(view), args.render)
    print(f"wrote {args.render}")
