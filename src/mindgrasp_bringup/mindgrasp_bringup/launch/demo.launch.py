"""The headless main demo: simulated arm and camera, virtual amplifier + virtual subject, EEG
acquisition, MI classifier, vision and the grasp controller, recorded to the run directory.

    mindgrasp launch demo                          # 3 grasp trials, then ends; runs/<UTC>_demo/
    mindgrasp launch demo trials:=0                # trials until Ctrl-C
    mindgrasp launch demo duration:=120 gui:=true targets:='blue cylinder, red cube' trials:=2
    mindgrasp launch demo display:=window           # with the participant's screen
    mindgrasp launch demo realism:=default          # noisy camera, miscalibrated, lagging arm
    mindgrasp launch demo live_view:=false          # without the Foxglove live view
    mindgrasp launch demo command_interface:=trajectory   # JointTrajectory (or servo_twist)
    mindgrasp launch demo --show-args
    ros2 launch mindgrasp_bringup demo.launch.py    # the same, in a sourced ROS 2 workspace

The task, as in the paper's set-locations experiment: the trial manager names the object to grasp
on /task/target (latched), where the virtual subject (subject:=pursue) reads what to imagine and
the simulator which grasp counts; after each grasp it resets the scene and starts the next trial.

Parameters: config/param/<package>.yaml of each package, then config/profiles/demo.yaml (the
demo's own settings), then the launch arguments below (later entries win).
"""


from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    Shutdown,
    classifier_nodes,
    command_interface_argument,
    config_files,
    display_arguments,
    display_nodes,
    file_argument,
    fsm_node,
    live_view_arguments,
    live_view_nodes,
    number_argument,
    robot_argument,
    run_directory_actions,
    sim_scene_camera,
    virtual_amp_pin,
)


def generate_launch_description() -> LaunchDescription:
    gui = LaunchConfiguration('gui')
    seed = LaunchConfiguration('seed')
    eeg_stream = LaunchConfiguration('eeg_stream')
    amp_pin, acquisition_pin = virtual_amp_pin()   # this run's amplifier only
    return LaunchDescription([
        DeclareLaunchArgument('gui', default_value='false', choices=['true', 'false'],
                              description='open the PyBullet window (needs a display)'),
        number_argument('seed', default_value='0', minimum=0,
                        description='seed of the scene, the virtual subject and the synthetic '
                                    'EEG (same seed, same run)'),
        robot_argument(),
        DeclareLaunchArgument('realism', default_value='none',
                              description='simulator realism: none, default or a profile YAML '
                                          'path (noisy camera, miscalibration, arm lag, object '
                                          'spread; mindgrasp_sim.realism), seeded by seed'),
        DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                              description='LSL stream name of the virtual amplifier (the '
                                          "acquisition is pinned to this run's amplifier by a "
                                          'source id made per run, so several demos may share '
                                          'it)'),
        DeclareLaunchArgument('subject', default_value='pursue',
                              choices=['noise', 'follow', 'pursue'],
                              description='virtual subject: noise (no imagery), follow (imagines '
                                          'what /trainer/prompt asks), pursue (imagines what '
                                          'brings the arm to /task/target)'),
        file_argument('model', default_value='',
                      description='classifier model (.json written by mindgrasp train '
                                  'classifier); empty: the one in '
                                  'config/param/classifier.yaml'),
        DeclareLaunchArgument('targets', default_value='red cube, blue cylinder, yellow sphere',
                              description='objects to grasp in turn, comma-separated ("red cube, '
                                          'blue sphere"); empty: drawn at random from the scene'),
        number_argument('trials', default_value='3', minimum=0,
                        description='grasp trials before the demo ends (0: until duration or '
                                    'Ctrl-C)'),
        command_interface_argument(),
        *display_arguments(),
        *live_view_arguments(),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        # 0 the trials: which object to grasp, reset between grasps
        Node(package='mindgrasp_experiments', executable='trial_manager_node', name='trial_manager',
             parameters=[*config_files('demo'),
                         {'targets': LaunchConfiguration('targets'),
                          'n_trials': LaunchConfiguration('trials'), 'seed': seed}],
             on_exit=Shutdown(reason='the trials are done')),
        # 1 simulator: arm, gripper, objects, RGB-D camera (the arm contract of ros2_control)
        *[Node(package='mindgrasp_sim', executable='sim_node', name='sim',
               parameters=[*config_files('sim', 'demo'),
                           {'gui': gui, 'seed': seed, 'realism': LaunchConfiguration('realism'),
                            'realism_seed': seed, 'robot': LaunchConfiguration('robot'),
                            **scene}],
               condition=condition) for condition, scene in sim_scene_camera()],
        # 2 virtual amplifier: synthetic EEG of the virtual subject as an LSL stream
        Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
             parameters=[*config_files('eeg', 'demo'),
                         {'stream_name': eeg_stream, 'seed': seed,
                          'subject_mode': LaunchConfiguration('subject'),
                          'robot': LaunchConfiguration('robot'), **amp_pin}]),
        # 3 acquisition: LSL inlet -> /eeg/raw, pinned to this run's amplifier (source id, host)
        Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
             parameters=[*config_files('eeg', 'demo'),
                         {'stream_name': eeg_stream, **acquisition_pin}]),
        # the participant's screen (display:=window|fullscreen|headless)
        *display_nodes(config_files('trainer'), LaunchConfiguration('trials')),
        # 4 classifier: /eeg/raw -> /bci/prediction
        *classifier_nodes(config_files('classifier', 'demo')),
        # 5 vision: camera -> /vision/detections, /vision/overlay
        Node(package='mindgrasp_vision', executable='vision_node', name='vision',
             parameters=config_files('vision', 'demo')),
        # 6 controller: predictions + detections -> arm and gripper commands
        fsm_node(config_files('fsm', 'demo'), {'robot': LaunchConfiguration('robot')}),
        # 7 live view for the experimenter: Foxglove at ws://localhost:8765
        *live_view_nodes(),
    ])
