"""The ROS 1 wire: navlab's runs as nodes on a real ROS 1 graph (master, XML-RPC, TCPROS, services).

``RosBridge(executor)`` offers a run's topics, tf, clock, parameters and services on ``$ROS_MASTER_URI``
(starting navlab's own master when none answers); ``Master`` is ``navlab roscore``.
"""

from navlab.ros1.bridge import RosBridge, connect_or_start_master, session_params
from navlab.ros1.errors import Ros1Error
from navlab.ros1.master import Master
from navlab.ros1.types import Ros1Types

__all__ = ["Master", "Ros1Error", "Ros1Types", "RosBridge", "connect_or_start_master", "session_params"]
