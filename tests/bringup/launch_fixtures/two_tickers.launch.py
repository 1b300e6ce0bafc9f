"""Two plain processes that tick and end by themselves (launcher tests)."""

from mindgrasp_launch import (
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
)


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument('count', default_value='3', description='ticks of each process'),
        DeclareLaunchArgument('exit_code', default_value='0',
                              description='exit code of the second process'),
        DeclareLaunchArgument('rate', default_value='10.0', description='a parameter'),
        Node(package='launch_fixtures', executable='ticker', name='first', namespace='grp',
             arguments=['--count', LaunchConfiguration('count'), '--label', 'first'],
             parameters=[{'rate': LaunchConfiguration('rate'), 'tag': 'one'}],
             remappings=[('/chatter', '/chatter_first')]),
        Node(package='launch_fixtures', executable='ticker', name='second',
             arguments=['--count', LaunchConfiguration('count'), '--label', 'second',
                        '--exit-code', LaunchConfiguration('exit_code')]),
    ])
