"""Node executables that launch files can name (``exec: amcl``), as ``module:Class`` paths.

Each class takes ``(executor, *, name=..., parameters=None, namespace="")``.
"""

NODES: dict[str, str] = {
    "talker": "navlab.core.demo_nodes:Talker",
    "listener": "navlab.core.demo_nodes:Listener",
    "amcl": "navlab.localization.amcl_node:Amcl",
    "map_server": "navlab.mapping.map_server:MapServer",
    "map_saver": "navlab.mapping.map_saver:MapSaver",
    "slam_gmapping": "navlab.mapping.slam_node:SlamGMapping",
    "gazebo": "navlab.sim.gazebo:GazeboSim",
    "explore": "navlab.drivers.explore:Explore",
    "teleop_twist_keyboard": "navlab.drivers.teleop:TeleopKeyboard",
    "route_follower": "navlab.drivers.routes:RouteFollower",
    "move_base": "navlab.navigation.move_base:MoveBase",
    "ekf_node": "navlab.localization.ekf_node:EkfNode",
    "ekf_localization_node": "navlab.localization.ekf_node:EkfNode",
    "velocity_smoother": "navlab.navigation.velocity_smoother:VelocitySmootherNode",
    "collision_monitor": "navlab.navigation.collision_monitor:CollisionMonitorNode",
    "pointcloud_to_laserscan_node": "navlab.navigation.pointcloud_to_laserscan:PointCloudToLaserScan",
}

#: launch files' ``$(robot KEY)``: a function of the ``robot`` argument (shipped name, file or
#: package:// URI) returning its base frame, scan topic and odom frame from its plugin tags
ROBOT_LAUNCH_VALUES = "navlab.description.loader:robot_launch_values"
