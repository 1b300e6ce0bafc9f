"""The demo's BCI loop without the simulator and camera (fixture of the live-change tests):
virtual amplifier -> acquisition -> classifier -> controller, recorded like any run.

    mindgrasp launch tests/bringup/launch_fixtures/bci_loop_recorded.launch.py eeg_stream:=NAME
"""

import mindgrasp_bringup.launch_api as la


def generate_launch_description() -> la.LaunchDescription:
    eeg = [*la.config_files('eeg', 'demo'), {'stream_name': la.LaunchConfiguration('eeg_stream')}]
    return la.LaunchDescription([
        la.DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                                 description='LSL name of the virtual amplifier (unique per test)'),
        la.DeclareLaunchArgument('model', default_value='', description='classifier model'),
        *[la.Node(package='mindgrasp_eeg', executable=f'{name}_node', name=label, parameters=eeg)
          for name, label in (('virtual_amp', 'virtual_amp'), ('acquisition', 'eeg_acquisition'))],
        *la.classifier_nodes(la.config_files('classifier', 'demo')),
        la.Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
                parameters=la.config_files('fsm', 'demo')),
    ])
