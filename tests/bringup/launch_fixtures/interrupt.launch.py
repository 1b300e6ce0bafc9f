"""A process that stops on KeyboardInterrupt, as rclpy nodes do (it installs no SIGINT handler)."""

from mindgrasp_launch import LaunchDescription, Node


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        Node(package='launch_fixtures', executable='ticker', name='gamma',
             arguments=['--count', '0', '--period', '0.1', '--label', 'gamma',
                        '--keyboard-interrupt']),
    ])
