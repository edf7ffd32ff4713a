"""04b — the paper's pipeline: map the room with SLAM, save the map, then localize on it with AMCL.

Both steps start the shipped launch files (mapping, then localization) and add a route driver and a
ground-truth monitor as nodes, as `navlab map` and `navlab localize` do. Takes about 20 s. The map and
the figure go to out/examples/04_localize/.
"""

from __future__ import annotations

import json
from pathlib import Path

from navlab.drivers import RouteFollower
from navlab.experiments import DEFAULT_ROUTE, plot_result, run_localization, start_run
from navlab.mapping import save_map

OUT = Path("out/examples/04_localize")

# 1. mapping mode: the mapping launch without exploration; drive one loop of the route (steered on
#    ground truth) while slam_gmapping builds the map
run = start_run("mapping", world="room_obstacles", seed=0, explore="false")
run.add(RouteFollower, parameters={"waypoints": [list(w) for w in DEFAULT_ROUTE], "pose_topic": "/ground_truth/odom"})
run.run(70.0)
grid = run.node("slam_gmapping").current_map()
assert grid is not None, "SLAM produced no map"
save_map(grid, OUT / "slam_map.yaml")  # map_saver's YAML + PGM

# 2. navigation mode: the localization launch (map_server serves the saved map, amcl localizes on it)
result = run_localization("room_obstacles", OUT / "slam_map.yaml", duration=60.0, seed=0)
print(json.dumps(result.summary, indent=1))
print("figure:", plot_result(result, OUT / "localize_on_slam_map.png"))
