"""06 — the paper's navigation step: move_base drives the robot to goals on a map (Figs. 9-12).

Starts the shipped navigation launch (simulator + map_server + amcl + move_base with the paper's
parameter files), sends goals the way actionlib's SimpleActionClient does and drops a cylinder on the
way that the map does not know.

Run:  python examples/06_navigate/run.py
The same from the shell, with pictures: navlab navigate --world room_obstacles --goal 4.3 1.0 0 --out nav
"""

import tempfile
from pathlib import Path

import navlab
from navlab.mapping import save_map
from navlab.world import load_world, true_map

# 1. a map of the empty room (what the mapping step of example 05 saves; here the world's true one)
map_yaml = Path(tempfile.mkdtemp()) / "room.yaml"
save_map(true_map(load_world("room"), (0.0, 0.0)), map_yaml)

# 2. navigate in the room WITH obstacles on that map: they were added after mapping, as in the paper
session = navlab.launch("navigation", world="room_obstacles", map=str(map_yaml), seed=0)
ex = session.executor
move_base = session.node("move_base")
ex.run(1.0)  # amcl's first estimate, the costmaps' first updates

for x, y, yaw in [(4.3, 1.0, 0.0), (-3.5, -0.5, 3.14)]:
    goal = move_base.send_goal(x, y, yaw)  # like actionlib: PENDING -> ACTIVE -> SUCCEEDED/ABORTED
    if x < 0:  # a cylinder appears on the way back; the obstacle layer sees it, navfn replans around it
        session.node("gazebo").spawn_primitive("cylinder", "late", (0.15, 0.6), x=-1.0, y=-0.45)
    ex.run_until(goal.done, timeout=90.0)
    truth = session.node("gazebo").sim.base_pose2d()
    print(
        f"goal ({x}, {y}): {goal.state} after {ex.now_ns / 1e9:.1f} simulated s {goal.reason}".rstrip()
        + f"; robot at ({truth[0]:.2f}, {truth[1]:.2f})"
    )
    print(f"  recoveries used: {move_base.recovery_log or 'none'}")

# 3. the global costmap and plan as rviz would show them
costmap = move_base.global_costmap.costmap
print(
    f"global costmap: {costmap.width} x {costmap.height} cells in {costmap.frame_id}; "
    f"{int((costmap.data >= 253).sum())} cells lethal or inscribed"
)
