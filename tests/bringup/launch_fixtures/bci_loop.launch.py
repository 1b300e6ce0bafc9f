"""The live BCI loop without the simulator (fixture of the timing tests): virtual amplifier ->
acquisition -> classifier -> controller, recorded; it ends by itself once ``predictions``
predictions were published (a ``mindgrasp topic echo --times`` process with on_exit=Shutdown).

The controller has no arm, so it holds it stopped, yet it publishes a command every tick: enough
for the EEG sample -> command timing.
"""

import sys

from mindgrasp_bringup.launch_system import (
    DeclareLaunchArgument,
    ExecuteProcess,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    Shutdown,
    config_files,
)


def generate_launch_description() -> LaunchDescription:
    stream = LaunchConfiguration('eeg_stream')
    return LaunchDescription([
        DeclareLaunchArgument('eeg_stream', default_value='mg-bci-loop',
                              description='LSL name of the virtual amplifier (unique per test)'),
        DeclareLaunchArgument('predictions', default_value='40',
                              description='predictions to see before the launch ends'),
        Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
             parameters=[*config_files('eeg'), {'stream_name': stream, 'seed': 0,
                                                'subject_mode': 'noise'}]),
        Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
             parameters=[*config_files('eeg'), {'stream_name': stream}]),
        Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
             parameters=config_files('classifier')),
        Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
             parameters=config_files('fsm')),
        ExecuteProcess(cmd=[sys.executable, '-m', 'mindgrasp_bringup', 'topic', 'echo',
                            '/bci/prediction', 'mindgrasp_msgs/msg/MIPrediction', '--times',
                            LaunchConfiguration('predictions'), '--field', 'class_index'],
                       name='enough_predictions', on_exit=Shutdown(reason='enough predictions')),
    ])
