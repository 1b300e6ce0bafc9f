"""A small node run in a separate process by the tests of mindgrasp_ros.

Usage: python ros_peer.py ROLE [--ros-args ...]
Roles: talker (String on 'chatter' every 20 ms; QoS from parameters), echo (re-publishes
'chatter' on 'echo'), params (declares parameters, serves std_srvs/SetBool on 'toggle'),
latched (publishes 3 messages transient-local on 'latched' then idles).
"""

import sys

from mindgrasp_ros.interfaces.std_msgs.msg import String
from mindgrasp_ros.interfaces.std_srvs.srv import SetBool

from mindgrasp_ros import rclpy


def qos(node: rclpy.node.Node) -> rclpy.qos.QoSProfile:
    reliable = node.declare_parameter('reliable', True).value
    transient = node.declare_parameter('transient_local', False).value
    return rclpy.qos.QoSProfile(
        depth=node.declare_parameter('depth', 10).value,
        reliability=rclpy.qos.ReliabilityPolicy.RELIABLE if reliable
        else rclpy.qos.ReliabilityPolicy.BEST_EFFORT,
        durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL if transient
        else rclpy.qos.DurabilityPolicy.VOLATILE)


def main() -> None:
    role = sys.argv[1]
    rclpy.init(args=sys.argv)
    node = rclpy.node.Node(f'peer_{role}')
    count = [0]
    if role == 'talker':
        pub = node.create_publisher(String, 'chatter', qos(node))

        def tick() -> None:
            count[0] += 1
            pub.publish(String(data=f'hello {count[0]}'))

        node.create_timer(0.02, tick)
    elif role == 'echo':
        pub = node.create_publisher(String, 'echo', 10)
        node.create_subscription(String, 'chatter', lambda m: pub.publish(String(data=m.data)),
                                 qos(node))
    elif role == 'params':
        node.declare_parameter('gain', 1.0)
        node.declare_parameter('name', 'none')
        node.declare_parameter('nested.level', 0)
        node.declare_parameter('channels', ['C3'])
        state = {'on': False}

        def toggle(request: SetBool.Request, response: SetBool.Response) -> SetBool.Response:
            state['on'] = bool(request.data)
            response.success = True
            response.message = f'on={state["on"]} gain={node.get_parameter("gain").value}'
            return response

        node.create_service(SetBool, 'toggle', toggle)
    elif role == 'latched':
        pub = node.create_publisher(String, 'latched', qos(node))
        for i in range(3):
            pub.publish(String(data=f'latched {i}'))
    else:
        raise SystemExit(f'unknown role {role!r}')
    print('ready', flush=True)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
