"""Replay a recorded session: bag play feeds the classifier and the controller again (e.g. to try
another classifier model or controller setting on the same EEG and camera data).

    mindgrasp launch replay bag:=runs/<run>/bag
    mindgrasp launch replay bag:=runs/<run>/bag rate:=2.0 vision:=true
    mindgrasp launch replay bag:=runs/<run>/bag clock:=true    # nodes on the bag's time

The recorded outputs of the nodes that run again (/bci/prediction, /fsm/state, arm and gripper
commands; /vision/* with vision:=true) are not played, so they come only from the new run. The
launch ends when the bag has been played (loop:=true: until Ctrl-C or duration:=S).
"""

from mindgrasp_bringup.launch_api import (
    DeclareLaunchArgument,
    IfCondition,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    SetParameter,
    Shutdown,
    UnlessCondition,
    classifier_nodes,
    config_files,
)

RERUN = '^/(bci/prediction|fsm/|arm_controller/|gripper_controller/'


def generate_launch_description() -> LaunchDescription:
    vision = LaunchConfiguration('vision')

    def player(exclude: str, condition: object) -> Node:
        return Node(package='mindgrasp_bringup', executable='player_node', name='bag_player',
                    parameters=[{'bag': LaunchConfiguration('bag'),
                                 'rate': LaunchConfiguration('rate'),
                                 'loop': LaunchConfiguration('loop'),
                                 'delay': LaunchConfiguration('delay'),
                                 'clock': LaunchConfiguration('clock'),
                                 'exclude_regex': exclude}],
                    on_exit=Shutdown(), condition=condition)

    return LaunchDescription([
        DeclareLaunchArgument('bag', description='the bag directory (e.g. runs/<run>/bag)'),
        DeclareLaunchArgument('rate', default_value='1.0', description='playback speed factor'),
        DeclareLaunchArgument('loop', default_value='false', choices=['true', 'false'],
                              description='play the bag again and again'),
        DeclareLaunchArgument('delay', default_value='1.0',
                              description='seconds to wait before playing, so the nodes '
                                          'discover the player first'),
        DeclareLaunchArgument('vision', default_value='false', choices=['true', 'false'],
                              description='run the vision node again on the recorded camera '
                                          'images (false: play the recorded detections)'),
        DeclareLaunchArgument('model', default_value='',
                              description='classifier model (.json written by mindgrasp train '
                                          'classifier); empty: the one in '
                                          'config/params/classifier.yaml'),
        DeclareLaunchArgument('clock', default_value='false', choices=['true', 'false'],
                              description='the player publishes /clock from the bag and the '
                                          'nodes run on it (use_sim_time)'),
        SetParameter('use_sim_time', LaunchConfiguration('clock')),
        *classifier_nodes(config_files('classifier', 'replay')),
        Node(package='mindgrasp_vision', executable='vision_node', name='vision',
             parameters=config_files('vision', 'replay'), condition=IfCondition(vision)),
        Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
             parameters=config_files('fsm', 'replay')),
        # last, so the nodes above are up when the first message is played
        player(RERUN + '|vision/)', IfCondition(vision)),
        player(RERUN + ')', UnlessCondition(vision)),
    ])
