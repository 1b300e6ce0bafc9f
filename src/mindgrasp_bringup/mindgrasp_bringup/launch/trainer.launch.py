"""MIndGrasp Trainer calibration: a green training robot moves, the user (or the virtual subject)
follows it with their own arm by motor imagery; prompts and EEG are recorded for training.

    mindgrasp launch trainer                          # virtual subject, simulated arms
    mindgrasp launch trainer robot:=xarm6 trials:=8   # both robots xArm6s
    mindgrasp launch trainer amp:=lsl eeg_stream:=MyAmp trials:=80 display:=fullscreen
    mindgrasp train classifier runs/<run>/bag         # then train on the recording

The launch ends when the trainer has run all its trials (or after duration:=S).
"""

from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    Shutdown,
    classifier_nodes,
    config_files,
    display_arguments,
    display_nodes,
    eeg_source_arguments,
    eeg_source_nodes,
    file_argument,
    number_argument,
    robot_argument,
    run_directory_actions,
    sim_scene_camera,
)


def generate_launch_description() -> LaunchDescription:
    from mindgrasp_common.robot_description import robot_choices

    seed = LaunchConfiguration('seed')
    robot = {'robot': LaunchConfiguration('robot')}
    return LaunchDescription([
        *eeg_source_arguments(),
        *display_arguments(),
        DeclareLaunchArgument('subject', default_value='follow',
                              choices=['noise', 'follow', 'pursue'],
                              description='virtual subject (amp:=virtual): follow imagines what '
                                          'the prompts ask'),
        number_argument('trials', default_value='40', minimum=1,
                        description='number of trials (a multiple of 4 balances classes)'),
        number_argument('seed', default_value='0', minimum=0,
                        description='seed of the trial order, scene and virtual subject'),
        DeclareLaunchArgument('gui', default_value='false', choices=['true', 'false'],
                              description='open the PyBullet window (needs a display)'),
        file_argument('model', default_value='',
                      description='classifier model (.json written by mindgrasp train '
                                  'classifier); empty: the one in '
                                  'config/param/classifier.yaml'),
        robot_argument(description="the user's arm and the training robot, a second copy of "
                                   f'it: {robot_choices()}'),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        *[Node(package='mindgrasp_sim', executable='sim_node', name='sim',
               parameters=[*config_files('sim'),
                           {'gui': LaunchConfiguration('gui'), 'seed': seed,
                            'trainer_robot': True, **robot, **scene}], condition=condition)
          for condition, scene in sim_scene_camera()],
        *eeg_source_nodes(config_files('eeg'), seed, LaunchConfiguration('subject')),
        *classifier_nodes(config_files('classifier')),
        Node(package='mindgrasp_vision', executable='vision_node', name='vision',
             parameters=config_files('vision')),
        Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
             parameters=[*config_files('fsm'), robot]),
        *display_nodes(config_files('trainer'), LaunchConfiguration('trials')),
        # last: it starts prompting once everything else runs, and its end ends the launch
        Node(package='mindgrasp_trainer', executable='trainer_node', name='trainer',
             parameters=[*config_files('trainer'),
                         {'n_trials': LaunchConfiguration('trials'), 'seed': seed, **robot}],
             on_exit=Shutdown(reason='the trainer ended')),
    ])
