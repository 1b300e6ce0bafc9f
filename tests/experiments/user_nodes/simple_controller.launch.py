"""My own controller in place of the MIndGrasp one (the node named fsm is replaced)."""

from mindgrasp_launch.launch_api import LaunchDescription, Node


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        Node(package='user_nodes', executable='simple_controller_node', name='fsm'),
    ])
