"""The ROS 1 wire: navlab's runs as nodes on a real ROS 1 graph (master, XML-RPC, TCPROS, services).

``RosBridge(executor)`` offers a run's topics, tf, clock, parameters and services on ``$ROS_MASTER_URI``
(starting navlab's own master when none answers); ``Master`` is ``navlab roscore``.
Exports load lazily: declaring a verb's ``--ros`` option (``navlab.cli.ros``) imports neither numpy nor rosbags.
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.ros1.bridge import RosBridge, connect_or_start_master, session_params
    from navlab.ros1.errors import Ros1Error
    from navlab.ros1.live import LiveRun
    from navlab.ros1.master import Master
    from navlab.ros1.net import host_port, master_uri
    from navlab.ros1.types import Ros1Types


_EXPORTS = {
    "Master": "navlab.ros1.master",
    "Ros1Error": "navlab.ros1.errors",
    "Ros1Types": "navlab.ros1.types",
    "RosBridge": "navlab.ros1.bridge",
    "connect_or_start_master": "navlab.ros1.bridge",
    "session_params": "navlab.ros1.bridge",
    "LiveRun": "navlab.ros1.live",
    "host_port": "navlab.ros1.net",
    "master_uri": "navlab.ros1.net",
}
__all__ = [
    "LiveRun",
    "Master",
    "Ros1Error",
    "Ros1Types",
    "RosBridge",
    "connect_or_start_master",
    "host_port",
    "master_uri",
    "session_params",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
