"""A controller that raises 2 s into each trial."""

from mindgrasp_launch.launch_api import LaunchDescription, Node


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        Node(package='user_nodes', executable='simple_controller_node', name='fsm',
             parameters=[{'raise_after': 2.0}]),
    ])
