"""Graz-BCI calibration: fixation cross, arrow cue, imagery, rest; no robot. The prompts and the
EEG are recorded so that the classifier can be trained on them.

    mindgrasp launch graz                             # virtual amplifier, virtual subject
    mindgrasp launch graz amp:=lsl eeg_stream:=MyAmp trials:=80
    mindgrasp launch graz feedback:=true              # classifier feedback bar (trained model)
    mindgrasp launch graz display:=window             # the participant's screen (pygame)
    mindgrasp launch graz robot:=xarm6                # the arm this calibration is for (recorded)

The launch ends when the prompter has run all its trials (or after duration:=S).
"""

from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    GroupAction,
    IfCondition,
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
)


def generate_launch_description() -> LaunchDescription:
    from mindgrasp_common.robot_description import robot_choices

    seed = LaunchConfiguration('seed')
    return LaunchDescription([
        *eeg_source_arguments(),
        *display_arguments(),
        number_argument('trials', default_value='40', minimum=1,
                        description='number of trials (a multiple of 4 balances classes)'),
        number_argument('seed', default_value='0', minimum=0,
                        description='seed of the cue order and the virtual subject'),
        DeclareLaunchArgument('feedback', default_value='false', choices=['true', 'false'],
                              description='run the classifier so the display shows a feedback '
                                          'bar (needs a trained model)'),
        file_argument('model', default_value='',
                      description='classifier model for feedback:=true (.json written '
                                  'by mindgrasp train classifier); empty: the one in '
                                  'config/param/classifier.yaml'),
        robot_argument(description='the arm this calibration is for: no arm moves in a Graz '
                                   "session; the value is recorded with the run's launch "
                                   f'arguments ({robot_choices()})'),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        *eeg_source_nodes(config_files('eeg'), seed, 'follow'),
        GroupAction(classifier_nodes(config_files('classifier')),
                    condition=IfCondition(LaunchConfiguration('feedback'))),
        *display_nodes(config_files('trainer'), LaunchConfiguration('trials')),
        Node(package='mindgrasp_trainer', executable='graz_node', name='graz_prompter',
             parameters=[*config_files('trainer'),
                         {'n_trials': LaunchConfiguration('trials'), 'seed': seed}],
             on_exit=Shutdown(reason='the Graz session ended')),
    ])
