"""A talker and a listener in a namespace (fixture of the launcher tests).

Parameters reach both through --params-file (prefix), the listener's topic through a remapping.
"""

from mindgrasp_launch import (
    DeclareLaunchArgument,
    GroupAction,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    PushRosNamespace,
)


def generate_launch_description() -> LaunchDescription:
    prefix = LaunchConfiguration('prefix')
    return LaunchDescription([
        DeclareLaunchArgument('prefix', default_value='greetings',
                              description='text the talker sends and the listener expects'),
        DeclareLaunchArgument('count', default_value='60', description='messages to send'),
        DeclareLaunchArgument('expect', default_value='5', description='messages to hear'),
        GroupAction([
            PushRosNamespace('demo'),
            Node(package='launch_fixtures', executable='talker', name='talker',
                 parameters=[{'prefix': prefix, 'count': LaunchConfiguration('count'),
                              'period': 0.05}],
                 remappings=[('chatter', 'conversation')]),
            Node(package='launch_fixtures', executable='listener', name='listener',
                 parameters=[{'prefix': prefix, 'expect': LaunchConfiguration('expect'),
                              'timeout': 30.0}],
                 remappings=[('chatter', '/demo/conversation')]),
        ]),
    ])
