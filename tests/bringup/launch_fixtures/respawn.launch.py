"""A process that crashes once (exit code 3) and is respawned, next to a normal one."""

from mindgrasp_launch import (
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
)


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument('marker', description='file created by the first, crashing run'),
        DeclareLaunchArgument('respawn', default_value='true', choices=['true', 'false'],
                              description='respawn the crashing process'),
        Node(package='launch_fixtures', executable='ticker', name='phoenix',
             arguments=['--count', '4', '--crash-once', LaunchConfiguration('marker'),
                        '--label', 'phoenix'],
             respawn=LaunchConfiguration('respawn'), respawn_delay=0.2),
        Node(package='launch_fixtures', executable='ticker', name='steady',
             arguments=['--count', '10', '--period', '0.1', '--label', 'steady']),
    ])
