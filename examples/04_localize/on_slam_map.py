"""04b — the paper's pipeline: map the room with SLAM, save the map, then localize on it with AMCL.

Takes about 20 s. The map and the figure go to out/examples/04_localize/.
"""

from __future__ import annotations

import json
from pathlib import Path

from navlab.core import Executor
from navlab.localization.run import DEFAULT_ROUTE, GroundTruthRoute, plot_result, run_localization
from navlab.mapping.mapfile import save_map
from navlab.mapping.slam_node import SlamGMapping
from navlab.sim.gazebo import launch_sim

OUT = Path("out/examples/04_localize")

# 1. mapping mode: drive one loop of the route while slam_gmapping builds the map
ex = Executor(seed=0)
launch_sim(ex, world="room_obstacles")
with ex.node_context(remappings={"scan": "/mybot/laser/scan"}):
    slam = SlamGMapping(ex, parameters={"base_frame": "chassis"})
GroundTruthRoute(ex, DEFAULT_ROUTE)
ex.run(70.0)
grid = slam.current_map()
assert grid is not None, "SLAM produced no map"
save_map(grid, OUT / "slam_map.yaml")  # map_saver's YAML + PGM

# 2. navigation mode: map_server serves the saved map, amcl localizes the robot on it
result = run_localization("room_obstacles", OUT / "slam_map.yaml", duration=60.0, seed=0)
print(json.dumps(result.summary, indent=1))
print("figure:", plot_result(result, OUT / "localize_on_slam_map.png"))
