"""05 — the paper's mapping step: SLAM while the robot explores the room by itself, then save the map.

Run:  python examples/05_map_room/run.py            (writes ./room_map/map.yaml, map.pgm)

It starts the shipped mapping launch (simulator + slam_gmapping with params/gmapping.yaml + frontier
exploration), as `navlab launch mapping` does. The same from the shell, with scores and a picture:
navlab map --world room --explore --out room_map
"""

import navlab
from navlab.grid import GridMap
from navlab.mapping import save_map

session = navlab.launch("mapping", world="room", robot="mybot", seed=0)  # as fast as the CPU allows
explorer = session.node("explore")
slam = session.node("slam_gmapping")

finished = session.executor.run_until(lambda: explorer.done, timeout=300.0)
print(f"exploration {'finished' if finished else 'timed out'} after {session.executor.now_ns / 1e9:.0f} simulated s")
grid: GridMap | None = slam.current_map()
assert grid is not None, "SLAM produced no map"
save_map(grid, "room_map/map.yaml")  # map_saver's format: 254 free, 0 occupied, 205 unknown
print(f"saved room_map/map.yaml: {grid.width} x {grid.height} cells at {grid.resolution} m")
x, y, yaw = session.node("gazebo").sim.base_pose2d()
print(f"robot ended at x={x:.2f} y={y:.2f} yaw={yaw:.2f} (world frame)")
