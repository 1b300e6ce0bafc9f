"""Replay a recorded run as an experiment on its recorded data, and compare with what happened.

    mindgrasp launch replay bag:=runs/<run>                   # classifier on the recorded EEG
    mindgrasp launch replay bag:=runs/<run> controller:=true  # and the controller, open loop
    mindgrasp launch replay bag:=runs/<run> model:=my_model.json
    mindgrasp launch replay bag:=runs/<run> controller:=true robot:=xarm6   # another arm's limits

The classifier (and the controller) run lock-step on the bag's clock in the replay process:
every recorded input at its recorded time, the same node classes as live. The replay writes a
comparison report to runs/<run>/replays/<time>/ (report.md, comparison.json, predictions.csv,
states.csv, timeline.png, replayed_bag/); with the run's model and parameters the predictions
agree 100 %. Same as ``mindgrasp replay RUN``. For a plain real-time playback into live nodes,
use ``mindgrasp bag play``.
"""

from mindgrasp_launch.launch_api import (
    DeclareLaunchArgument,
    LaunchConfiguration,
    LaunchDescription,
    Node,
    Shutdown,
    file_argument,
    robot_argument,
    run_directory_actions,
)


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument('bag', description='the run directory (runs/<run>) or its bag '
                                                 'folder (runs/<run>/bag)'),
        DeclareLaunchArgument('controller', default_value='false', choices=['true', 'false'],
                              description='re-run the controller too (open loop: the camera '
                                          'and joint states are the recorded ones)'),
        file_argument('model', default_value='',
                      description='classifier model (.json written by mindgrasp train '
                                  'classifier); empty: the one the run used'),
        DeclareLaunchArgument('output', default_value='',
                              description='report directory; empty: <run>/replays/<time>'),
        DeclareLaunchArgument('allow_damaged', default_value='false',
                              choices=['true', 'false'],
                              description='accept a damaged bag (its readable part is '
                                          'replayed either way; without this the replay ends '
                                          'with exit code 1)'),
        robot_argument(default='', description='the arm of the re-run controller: a shipped '
                                               'robot or a robot description YAML path; empty: '
                                               'the one the run used'),
        *run_directory_actions(),  # ros2 launch: run directory, recorder, duration
        Node(package='mindgrasp_bringup', executable='replay_node', name='replay',
             parameters=[{'bag': LaunchConfiguration('bag'),
                          'controller': LaunchConfiguration('controller'),
                          'model': LaunchConfiguration('model'),
                          'output': LaunchConfiguration('output'),
                          'robot': LaunchConfiguration('robot'),
                          'allow_damaged': LaunchConfiguration('allow_damaged')}],
             on_exit=Shutdown(reason='the replay ended')),
    ])
