"""A small alternative controller: turns the arm left until an object is centred, then holds.

It publishes /fsm/state as the MIndGrasp controller does (1 searching, 2 centred) so that the
trial manager records its states. With ``raise_after`` > 0 its control callback raises after
that many seconds (to test how a failing node is reported).
"""

from __future__ import annotations

import sys

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, FsmState
from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

from mindgrasp_ros import rclpy


class SimpleController(rclpy.node.Node):
    def __init__(self, **kwargs) -> None:
        super().__init__('simple_controller', **kwargs)
        self.raise_after = float(self.declare_parameter('raise_after', 0.0).value)
        self.arm = self.create_publisher(Float64MultiArray, '/arm_controller/commands', 10)
        latched = rclpy.qos.QoSProfile(
            depth=1, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
            durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
        self.state_pub = self.create_publisher(FsmState, '/fsm/state', latched)
        self.create_subscription(DetectionArray, '/vision/detections', self.detections_callback,
                                 10)
        self.centred = False
        self.state = 0
        self.start = self.get_clock().now().nanoseconds * 1e-9
        self.create_timer(0.02, self.control_callback)

    def detections_callback(self, msg: DetectionArray) -> None:
        if msg.object_of_interest >= 0 and msg.image_width:
            d = msg.detections[msg.object_of_interest]
            self.centred = abs(d.centre_x / msg.image_width - 0.5) < 0.1

    def control_callback(self) -> None:
        now = self.get_clock().now().nanoseconds * 1e-9
        if self.raise_after > 0 and now - self.start > self.raise_after:
            raise RuntimeError('simulated controller fault')
        state = 2 if self.centred else 1
        self.arm.publish(Float64MultiArray(data=[0.0 if self.centred else 0.4, 0.0, 0.0, 0.0,
                                                 0.0, 0.0]))
        if state != self.state:
            self.state = state
            self.state_pub.publish(FsmState(state=state, state_name='simple'))


def main(args=None) -> int:
    rclpy.init(args=args)
    node = SimpleController()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
