"""The simulator alone: arm, three-finger gripper, objects and the eye-in-hand RGB-D camera, with
the arm contract of a ros2_control forward velocity controller (drive it from outside).

    mindgrasp launch sim                                   # set locations, real time
    mindgrasp launch sim scene:=random_locations seed:=3 camera:=640x480@30
    mindgrasp launch sim time_mode:=fast                   # + /clock; others on use_sim_time
    mindgrasp launch sim trainer_robot:=true gui:=true duration:=60
    mindgrasp launch sim realism:=default realism_seed:=3  # a real camera's noise, a real arm's lag
    mindgrasp launch sim robot:=xarm6                      # UFactory xArm6 (or a robot YAML path)
    mindgrasp topic hz /joint_states                       # in another shell

Parameters: config/param/sim.yaml, then the launch arguments below.
"""

from mindgrasp_launch.launch_api import (
    CameraSpec,
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    config_files,
    number_argument,
    robot_argument,
    run_directory_actions,
)


def generate_launch_description() -> LaunchDescription:
    camera = LaunchConfiguration('camera')
    # "WxH@R" -> width, height, rate: parsed, never evaluated (the text is the user's)
    width, height, rate = (CameraSpec(camera, field) for field in ('width', 'height', 'rate'))
    return LaunchDescription([
        DeclareLaunchArgument('scene', default_value='set_locations',
                              description='scene name in config/scenes/ or a scene YAML path'),
        number_argument('seed', default_value='0', minimum=0,
                        description='layout seed of random scenes'),
        DeclareLaunchArgument('time_mode', default_value='realtime',
                              choices=['realtime', 'fast', 'lockstep'],
                              description='realtime (wall clock), fast (as fast as possible, '
                                          'publishes /clock) or lockstep (advances on /sim/step)'),
        DeclareLaunchArgument('camera', default_value='128x128@10',
                              description='camera resolution and rate, WIDTHxHEIGHT@HZ'),
        DeclareLaunchArgument('trainer_robot', default_value='false', choices=['true', 'false'],
                              description='also simulate the green training robot '
                                          '(/trainer_robot/...)'),
        DeclareLaunchArgument('gui', default_value='false', choices=['true', 'false'],
                              description='open the PyBullet window (needs a display)'),
        DeclareLaunchArgument('realism', default_value='none',
                              description='sensor noise and physical spread: none, default or a '
                                          'profile YAML path (mindgrasp_sim.realism)'),
        number_argument('realism_seed', default_value='0', minimum=0,
                        description='seed of the realism draws'),
        robot_argument(),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        Node(package='mindgrasp_sim', executable='sim_node', name='sim',
             parameters=[*config_files('sim'),
                         {'scene': LaunchConfiguration('scene'),
                          'seed': LaunchConfiguration('seed'),
                          'time_mode': LaunchConfiguration('time_mode'),
                          'camera_width': width, 'camera_height': height, 'camera_rate': rate,
                          'trainer_robot': LaunchConfiguration('trainer_robot'),
                          'gui': LaunchConfiguration('gui'),
                          'realism': LaunchConfiguration('realism'),
                          'realism_seed': LaunchConfiguration('realism_seed'),
                          'robot': LaunchConfiguration('robot')}]),
    ])
