"""Fixture node: publishes ``std_msgs/String`` '<prefix> <i>' on ``chatter`` and ends after
``count`` messages (``python -m launch_fixtures.talker --ros-args -p count:=20``)."""

from __future__ import annotations

import sys
from typing import Any

from mindgrasp_ros.interfaces.std_msgs.msg import String

from mindgrasp_ros import rclpy


class Talker(rclpy.node.Node):
    """Publishes ``count`` messages, one every ``period`` s."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('talker', **kwargs)
        self.declare_parameters('', [('count', 20), ('period', 0.1), ('prefix', 'hello')])
        self.count = self.get_parameter('count').value
        self.prefix = self.get_parameter('prefix').value
        self.publisher = self.create_publisher(String, 'chatter', 10)
        self.create_timer(self.get_parameter('period').value, self.timer_callback)
        self.sent = 0
        self.done = False

    def timer_callback(self) -> None:
        if self.sent >= self.count:
            self.done = True
            return
        self.publisher.publish(String(data=f'{self.prefix} {self.sent}'))
        self.get_logger().info(f'Publishing: "{self.prefix} {self.sent}"')
        self.sent += 1


def main(args: list[str] | None = None) -> int:
    rclpy.init(args=args if args is not None else sys.argv)
    node = Talker()
    try:
        while rclpy.ok() and not node.done:
            rclpy.spin_once(node, timeout_sec=0.1)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
