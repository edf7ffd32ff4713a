"""05 — the paper's mapping step: SLAM while the robot explores the room by itself, then save the map.

Run:  python examples/05_map_room/run.py            (writes ./room_map/map.yaml, map.pgm, map.png)

The same from the shell: navlab map --world room --explore --out room_map
"""

from navlab.core import Executor
from navlab.mapping import GridMap, save_map
from navlab.mapping.explore_node import Explore
from navlab.mapping.slam_node import SlamGMapping
from navlab.sim.gazebo import launch_sim

ex = Executor(seed=0)  # simulated time, as fast as the CPU allows
gazebo = launch_sim(ex, world="room", robot="mybot")  # MuJoCo + diff_drive + lidar plugins
slam = SlamGMapping(ex, parameters={"base_frame": "chassis", "scan_topic": "/mybot/laser/scan",
                                    "linearUpdate": 0.5, "temporalUpdate": 2.0, "lskip": 4})
with ex.node_context(remappings={"scan": "/mybot/laser/scan"}):  # like <remap> in a launch file
    explorer = Explore(ex, parameters={"robot_base_frame": "chassis"})

finished = ex.run_until(lambda: explorer.done, timeout=300.0)
print(f"exploration {'finished' if finished else 'timed out'} after {ex.now_ns / 1e9:.0f} simulated s")
assert slam.grid is not None
save_map(slam.grid, "room_map/map.yaml")  # map_saver's format: 254 free, 0 occupied, 205 unknown
grid: GridMap = slam.grid
print(f"saved room_map/map.yaml: {grid.width} x {grid.height} cells at {grid.resolution} m")
x, y, yaw = gazebo.sim.base_pose2d()
print(f"robot ended at x={x:.2f} y={y:.2f} yaw={yaw:.2f} (world frame)")
