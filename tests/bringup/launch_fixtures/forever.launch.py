"""Processes that run until the launch stops them; ``stubborn:=true`` adds one that ignores
SIGINT (the launcher must escalate to SIGTERM)."""

from mindgrasp_launch import (
    DeclareLaunchArgument,
    IfCondition,
    LaunchConfiguration,
    LaunchDescription,
    Node,
)


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument('stubborn', default_value='false', choices=['true', 'false'],
                              description='add a process that ignores SIGINT'),
        Node(package='launch_fixtures', executable='ticker', name='alpha',
             arguments=['--count', '0', '--period', '0.1', '--label', 'alpha']),
        Node(package='launch_fixtures', executable='ticker', name='beta',
             arguments=['--count', '0', '--period', '0.1', '--label', 'beta']),
        Node(package='launch_fixtures', executable='ticker', name='stubborn',
             arguments=['--count', '0', '--period', '0.1', '--ignore-sigint', '--label',
                        'stubborn'],
             condition=IfCondition(LaunchConfiguration('stubborn'))),
    ])
