"""One process runs until stopped, another dies with exit code 5 after a few lines: the launch
must report the death with its last lines, stop the other and exit with 1."""

from mindgrasp_launch import LaunchDescription, Node


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        Node(package='launch_fixtures', executable='ticker', name='survivor',
             arguments=['--count', '0', '--period', '0.1', '--label', 'survivor']),
        Node(package='launch_fixtures', executable='ticker', name='crasher',
             arguments=['--count', '3', '--exit-code', '5', '--label', 'crasher']),
    ])
