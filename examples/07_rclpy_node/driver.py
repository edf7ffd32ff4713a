"""07 — a node written for rclpy, run unchanged on navlab: drives forward until the lidar sees a wall 0.6 m ahead.

Run:  navlab run examples/07_rclpy_node/driver.py --launch sim world:=room --duration 10
(`import rclpy` and `geometry_msgs.msg` come from navlab unless a real ROS 2 installation provides them.)
"""

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.qos import QoSProfile
from sensor_msgs.msg import LaserScan


class Driver(Node):
    def __init__(self):
        super().__init__("driver")
        self.declare_parameter("speed", 0.3)
        self.speed = self.get_parameter("speed").get_parameter_value().double_value
        self.pub = self.create_publisher(Twist, "cmd_vel", QoSProfile(depth=10))
        self.sub = self.create_subscription(LaserScan, "/mybot/laser/scan", self.on_scan, 10)
        self.timer = self.create_timer(0.1, self.tick)
        self.closest = float("inf")

    def on_scan(self, msg):
        self.closest = float(min(msg.ranges))

    def tick(self):
        msg = Twist()
        msg.linear.x = self.speed if self.closest > 0.6 else 0.0
        self.pub.publish(msg)


def main(args=None):
    rclpy.init(args=args)
    node = Driver()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
