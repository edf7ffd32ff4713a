"""``/collisions``: what the robot bumps into, from the simulator's contacts (Gazebo's bumper plugin's role).

Publishes a ``std_msgs/String`` naming the touched models (comma-separated) at ``rate`` Hz while the robot
touches anything but the floor, and nothing while it touches nothing; ``collisions`` counts contact episodes.
"""

from __future__ import annotations

from navlab import msgs
from navlab.sim.plugins import SimPlugin


class CollisionPlugin(SimPlugin):
    """Reports the robot's contacts with world models on ``/collisions`` (see the module docstring)."""

    default_name = "collisions"

    def setup(self) -> None:
        rate = float(self.declare_parameter("rate", 20.0))
        self.touching: list[str] = []
        self.collisions = 0  # episodes: from touching nothing to touching something
        self.pub = self.create_publisher(msgs.String, "/collisions", 10)
        self.create_timer(1.0 / rate, self.update)

    def update(self) -> None:
        """Check the contacts now."""
        now = self.sim.robot_collisions()
        if now and not self.touching:
            self.collisions += 1
        self.touching = now
        if now:
            self.pub.publish(msgs.String(data=",".join(now)))
