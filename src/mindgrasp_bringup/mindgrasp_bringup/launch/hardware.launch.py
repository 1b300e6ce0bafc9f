"""Real hardware: an LSL amplifier and an external arm driver (no simulator), with acquisition,
classifier, vision and the grasp controller.

    mindgrasp launch hardware eeg_stream:=gNautilus eeg_source_id:=GN-2021.06.12 \\
        eeg_host:=amp-pc arm_driver:=my_arm_driver \\
        model:=models/alice.json               # her classifier (mindgrasp train classifier)
    mindgrasp launch hardware eeg_stream:=gNautilus eeg_source_id:=GN-2021.06.12 \\
        eeg_host:=local arm_driver:=/opt/arm/bin/driver \\
        arm_driver_args:="--ip 192.168.1.10" camera_driver:=my_camera_node \\
        model:=models/alice.json
    mindgrasp launch hardware eeg_stream:=gNautilus eeg_unpinned:=true \\
        arm_driver:=my_ros_pkg/arm_node \\
        model:=package://mindgrasp_classifier/models/default_classifier.json   # bench test only
    mindgrasp launch hardware eeg_stream:=gNautilus eeg_source_id:=GN-2021.06.12 \\
        eeg_host:=amp-pc arm_driver:=my_arm_driver \\
        model:=models/alice.json command_interface:=servo_twist    # the arm behind MoveIt Servo
    mindgrasp launch hardware eeg_stream:=gNautilus eeg_source_id:=GN-2021.06.12 \\
        eeg_host:=amp-pc arm_driver:=my_xarm_driver \\
        model:=models/alice.json robot:=xarm6     # the controller's kinematics: the lab's arm

The amplifier's stream is pinned: ``eeg_source_id:=`` and ``eeg_host:=`` (``local``: this host)
are required, so no other sender of the same stream name (another rig, a demo's virtual
amplifier) can drive the arm; ``eeg_unpinned:=true`` accepts any sender on purpose (a bench
test). Without them the launch is refused in one line before anything starts.

``model:=`` is required: a real person's EEG is never decoded by the classifier trained on the
simulated head unless it is named on purpose (the last line, for a bench test without a person).
The drivers are required nodes: if one ends, even with exit code 0, the launch stops every node and
ends with a non-zero exit code (``mindgrasp launch``; ``ros2 launch`` shuts down with its own code).

The arm driver must serve the arm contract of ros2_control's forward velocity controller:
subscribe /arm_controller/commands and /gripper_controller/commands (std_msgs/Float64MultiArray,
rad/s), publish /joint_states (sensor_msgs/JointState). With ``command_interface:=trajectory`` the
arm commands go to a JointTrajectoryController instead (trajectory_msgs/JointTrajectory on
/arm_controller/joint_trajectory), with ``command_interface:=servo_twist`` to MoveIt Servo
(geometry_msgs/TwistStamped on /servo_node/delta_twist_cmds, after
/servo_node/switch_command_type). The camera (the driver itself or
camera_driver) publishes /camera/color/image_raw (rgb8), /camera/depth/image_raw (32FC1, m) and
/camera/color/camera_info. Drivers are started as ROS nodes (``--ros-args -r __node:=...``).
"""

from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    IfCondition,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    NotEqualsSubstitution,
    classifier_nodes,
    command_interface_argument,
    config_files,
    driver_nodes,
    eeg_pin_arguments,
    eeg_pin_parameters,
    file_argument,
    fsm_node,
    robot_argument,
    run_directory_actions,
)


def generate_launch_description() -> LaunchDescription:
    from mindgrasp_common.robot_description import robot_choices

    return LaunchDescription([
        DeclareLaunchArgument('eeg_stream',
                              description='LSL stream name of the amplifier (as its streaming '
                                          'software names it)'),
        DeclareLaunchArgument('arm_driver',
                              description='arm driver: an executable on PATH, a path, '
                                          'package/executable (as ros2 run) or, with '
                                          'mindgrasp launch, a Python module (pkg.module, run '
                                          'with python -m)'),
        DeclareLaunchArgument('arm_driver_args', default_value='',
                              description='command-line arguments of the arm driver (shell '
                                          'quoting)'),
        # no default: the simulated head's classifier must never decode a person silently
        file_argument('model', default_value=None,
                      description="the person's classifier model (.json written by mindgrasp "
                                  'train classifier); for a bench test without a person, name '
                                  'the simulated head\'s on purpose: model:=package://'
                                  'mindgrasp_classifier/models/default_classifier.json'),
        DeclareLaunchArgument('require_ready_model', default_value='true',
                              choices=['true', 'false'],
                              description="refuse to drive the arm unless the model's "
                                          'calibration gate called the person ready (false: '
                                          'a bench test, or at your own risk)'),
        DeclareLaunchArgument('camera_driver', default_value='',
                              description='camera driver started like arm_driver (empty: the '
                                          'arm driver or another system publishes the camera)'),
        DeclareLaunchArgument('camera_driver_args', default_value='',
                              description='command-line arguments of the camera driver'),
        command_interface_argument(),
        robot_argument(description="the driver's arm, whose description the controller reads "
                                   f'(joints, limits, URDF kinematics, TCP, camera): '
                                   f'{robot_choices()}'),
        *eeg_pin_arguments(),   # eeg_source_id, eeg_host (or eeg_unpinned:=true): required
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        *driver_nodes('arm'),
        *driver_nodes('camera', condition=IfCondition(
            NotEqualsSubstitution(LaunchConfiguration('camera_driver'), ''))),
        Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
             parameters=[*config_files('eeg', 'hardware'),
                         {'stream_name': LaunchConfiguration('eeg_stream'),
                          **eeg_pin_parameters()}]),
        *classifier_nodes(config_files('classifier', 'hardware')),
        Node(package='mindgrasp_vision', executable='vision_node', name='vision',
             parameters=config_files('vision', 'hardware')),
        # the person's answer pair and thresholds come from the model; a model whose
        # calibration gate did not say ready is refused (require_ready_model, profile file)
        fsm_node(config_files('fsm', 'hardware'),
                 {'robot': LaunchConfiguration('robot'),
                  'classifier_model': LaunchConfiguration('model'),
                  'require_ready_model': LaunchConfiguration('require_ready_model')}),
    ])
