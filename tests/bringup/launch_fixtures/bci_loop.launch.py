"""The demo's BCI loop without the simulator and camera (fixture of the timing and live-change
tests): virtual amplifier -> acquisition -> classifier -> controller, recorded like any run.
With ``predictions:=N`` it ends by itself once N predictions were published (a ``mindgrasp topic
echo --times`` process with on_exit=Shutdown); with 0 it runs until stopped (or ``duration:=``).

    mindgrasp launch tests/bringup/launch_fixtures/bci_loop.launch.py predictions:=30

The controller has no arm, so it holds it stopped, yet it publishes a command every tick: enough
for the EEG sample -> command timing.
"""

import sys

import mindgrasp_launch.launch_api as la


def generate_launch_description() -> la.LaunchDescription:
    predictions = la.LaunchConfiguration('predictions')
    return la.LaunchDescription([
        *la.eeg_source_arguments(),
        la.DeclareLaunchArgument('model', default_value='', description='classifier model'),
        la.DeclareLaunchArgument('predictions', default_value='0',
                                 description='predictions to see before the launch ends (0: run '
                                             'until stopped)'),
        *la.eeg_source_nodes(la.config_files('eeg', 'demo'), seed=0, subject_mode='noise'),
        *la.classifier_nodes(la.config_files('classifier', 'demo')),
        la.Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
                parameters=la.config_files('fsm', 'demo')),
        la.ExecuteProcess(cmd=[sys.executable, '-m', 'mindgrasp_cli', 'topic', 'echo',
                               '/bci/prediction', 'mindgrasp_msgs/msg/MIPrediction', '--times',
                               predictions, '--field', 'class_index'],
                          name='enough_predictions',
                          on_exit=la.Shutdown(reason='enough predictions'),
                          condition=la.IfCondition(la.NotEqualsSubstitution(predictions, '0'))),
    ])
