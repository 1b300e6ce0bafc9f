"""The live BCI loop without the simulator (fixture of the timing tests): virtual amplifier ->
acquisition -> classifier -> controller, recorded; it ends by itself once ``predictions``
predictions were published (a ``mindgrasp topic echo --times`` process with on_exit=Shutdown).

The controller has no arm, so it holds it stopped, yet it publishes a command every tick: enough
for the EEG sample -> command timing.
"""

import sys

import mindgrasp_bringup.launch_system as ls


def _node(package: str, executable: str, *parameters: object) -> ls.Node:
    """A node of the loop named after its executable (``acquisition_node`` -> eeg_acquisition)."""
    name = {'acquisition_node': 'eeg_acquisition'}.get(executable,
                                                       executable.removesuffix('_node'))
    return ls.Node(package=package, executable=executable, name=name, parameters=list(parameters))


def generate_launch_description() -> ls.LaunchDescription:
    stream = ls.LaunchConfiguration('eeg_stream')
    eeg = ls.config_files('eeg')
    return ls.LaunchDescription([
        ls.DeclareLaunchArgument('eeg_stream', default_value='mg-bci-loop',
                                 description='LSL name of the virtual amplifier (unique per test)'),
        ls.DeclareLaunchArgument('predictions', default_value='40',
                                 description='predictions to see before the launch ends'),
        _node('mindgrasp_eeg', 'virtual_amp_node', *eeg,
              {'stream_name': stream, 'seed': 0, 'subject_mode': 'noise'}),
        _node('mindgrasp_eeg', 'acquisition_node', *eeg, {'stream_name': stream}),
        _node('mindgrasp_classifier', 'classifier_node', *ls.config_files('classifier')),
        _node('mindgrasp_fsm', 'fsm_node', *ls.config_files('fsm')),
        ls.ExecuteProcess(cmd=[sys.executable, '-m', 'mindgrasp_bringup', 'topic', 'echo',
                               '/bci/prediction', 'mindgrasp_msgs/msg/MIPrediction', '--times',
                               ls.LaunchConfiguration('predictions'), '--field', 'class_index'],
                          name='enough_predictions',
                          on_exit=ls.Shutdown(reason='enough predictions')),
    ])
