"""Fixture node: subscribes to ``chatter`` and ends with exit code 0 once it has heard
``expect`` messages starting with ``prefix``, or with exit code 1 after ``timeout`` s."""

from __future__ import annotations

import sys
import time
from typing import Any

from mindgrasp_ros.interfaces.std_msgs.msg import String

from mindgrasp_ros import rclpy


class Listener(rclpy.node.Node):
    """Counts the messages it hears."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('listener', **kwargs)
        self.declare_parameters('', [('expect', 5), ('prefix', 'hello'), ('timeout', 20.0)])
        self.expect = self.get_parameter('expect').value
        self.prefix = self.get_parameter('prefix').value
        self.timeout = self.get_parameter('timeout').value
        self.heard = 0
        self.create_subscription(String, 'chatter', self.chatter_callback, 10)
        self.started = time.monotonic()

    def chatter_callback(self, msg: String) -> None:
        self.get_logger().info(f'I heard: "{msg.data}"')
        if msg.data.startswith(self.prefix):
            self.heard += 1

    @property
    def done(self) -> bool:
        return self.heard >= self.expect or time.monotonic() - self.started > self.timeout


def main(args: list[str] | None = None) -> int:
    rclpy.init(args=args if args is not None else sys.argv)
    node = Listener()
    try:
        while rclpy.ok() and not node.done:
            rclpy.spin_once(node, timeout_sec=0.1)
    except KeyboardInterrupt:
        return 0
    finally:
        ok = node.heard >= node.expect
        if not ok:
            node.get_logger().error(f'heard only {node.heard} of {node.expect} messages')
        node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
