"""EEG only: the acquisition node against any LSL EEG stream (optionally with a virtual amplifier).

    mindgrasp launch eeg eeg_stream:=MyAmp                 # a real amplifier's LSL stream
    mindgrasp eeg play eegbci:1:4 --name eegmmidb &        # any LSL EEG source, e.g. EEGMMIDB
    mindgrasp launch eeg eeg_stream:=eegmmidb marker_stream:=auto   # + its eegmmidb-markers
    mindgrasp launch eeg virtual_amp:=true subject:=noise  # with the virtual amplifier
    mindgrasp launch eeg --show-args

Pin a real amplifier with source_id:= and hostname:= (the node logs both when it connects);
with virtual_amp:=true the acquisition is pinned to the run's own virtual amplifier (a source id
made per run). The acquisition node publishes /eeg/raw and /eeg/status; the run directory
records them. With adapt:=true (the default here) the node adopts the stream's channel count,
rate and names with a warning; adapt:=false holds the stream to config/param/eeg.yaml (32 ch,
250 Hz, g.Nautilus names). With marker_stream:=auto (``<eeg_stream>-markers``) or
marker_stream:=NAME the node also relays that LSL marker stream (the amplifier's triggers) to
/eeg/markers, which the run records.
"""

from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    IfCondition,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    UnlessCondition,
    config_files,
    number_argument,
    run_directory_actions,
    virtual_amp_pin,
)


def generate_launch_description() -> LaunchDescription:
    eeg_stream = LaunchConfiguration('eeg_stream')
    duration = LaunchConfiguration('duration')
    virtual = LaunchConfiguration('virtual_amp')
    amp_pin, acquisition_pin = virtual_amp_pin()
    return LaunchDescription([
        DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                              description='LSL name of the EEG stream to acquire'),
        DeclareLaunchArgument('stream_type', default_value='',
                              description="LSL type to match as well (e.g. 'EEG'); empty: any"),
        DeclareLaunchArgument('source_id', default_value='',
                              description='LSL source_id to match as well; empty: any (with '
                                          "virtual_amp:=true: the run's own amplifier)"),
        DeclareLaunchArgument('hostname', default_value='',
                              description="the sender's host to match as well (local: this "
                                          'host); empty: any'),
        DeclareLaunchArgument('adapt', default_value='true', choices=['true', 'false'],
                              description="adopt the stream's channel count/rate/names (with a "
                                          'warning) instead of failing on a mismatch'),
        DeclareLaunchArgument('marker_stream', default_value='none',
                              description='LSL marker stream to relay to /eeg/markers: none, '
                                          'auto (<eeg_stream>-markers) or its name'),
        DeclareLaunchArgument('virtual_amp', default_value='false', choices=['true', 'false'],
                              description='also start the virtual amplifier as eeg_stream'),
        DeclareLaunchArgument('subject', default_value='noise',
                              choices=['noise', 'follow', 'pursue'],
                              description='virtual subject mode (with virtual_amp:=true)'),
        number_argument('seed', default_value='0', minimum=0,
                        description='virtual subject/EEG seed'),
        number_argument('duration', default_value='0.0', kind=float, minimum=0,
                        description='seconds until the nodes end by themselves (0: never)'),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
             condition=IfCondition(virtual),
             parameters=[*config_files('eeg'),
                         {'stream_name': eeg_stream, 'seed': LaunchConfiguration('seed'),
                          'subject_mode': LaunchConfiguration('subject'),
                          'duration': duration, **amp_pin}]),
        # with the virtual amplifier: pinned to it (a source id made for this run, this host)
        *[Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
               condition=condition,
               parameters=[*config_files('eeg'),
                           {'stream_name': eeg_stream,
                            'stream_type': LaunchConfiguration('stream_type'),
                            'source_id': LaunchConfiguration('source_id'),
                            'hostname': LaunchConfiguration('hostname'),
                            'adapt_to_stream': LaunchConfiguration('adapt'),
                            'marker_stream': LaunchConfiguration('marker_stream'),
                            'duration': duration, **pin}])
          for condition, pin in ((IfCondition(virtual), acquisition_pin),
                                 (UnlessCondition(virtual), {}))],
    ])
