"""The ROS 1 wire: navlab's runs as nodes on a real ROS 1 graph (master, XML-RPC, TCPROS, services).

``RosBridge(executor)`` offers a run's topics, tf, clock, parameters and services on ``$ROS_MASTER_URI``
(starting navlab's own master when none answers); ``Master`` is ``navlab roscore``.
Exports load lazily: declaring a verb's ``--ros`` option (``navlab.cli.ros``) imports neither numpy nor rosbags.
"""

from navlab.lazy import lazy_exports

_EXPORTS = {
    "Master": "navlab.ros1.master",
    "Ros1Error": "navlab.ros1.errors",
    "Ros1Types": "navlab.ros1.types",
    "RosBridge": "navlab.ros1.bridge",
    "connect_or_start_master": "navlab.ros1.bridge",
    "session_params": "navlab.ros1.bridge",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
