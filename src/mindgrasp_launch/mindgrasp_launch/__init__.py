"""The launcher of MIndGrasp-ROS, in the manner of ``launch`` / ``launch_ros``.

Launch files (``src/mindgrasp_bringup/launch/<profile>.launch.py``) import from here::

    from mindgrasp_launch import (DeclareLaunchArgument, LaunchConfiguration,
                                                 LaunchDescription, Node)

    def generate_launch_description():
        return LaunchDescription([
            DeclareLaunchArgument('gui', default_value='false', description='PyBullet GUI'),
            Node(package='mindgrasp_sim', executable='sim_node', name='sim',
                 parameters=[{'gui': LaunchConfiguration('gui')}]),
        ])

Layers: ``substitutions``/``conditions`` (values resolved at launch), ``actions/`` (one action
per module), ``description`` (launch files, includes), ``service`` (resolve + run directory),
``supervisor`` (processes, output, signals), ``composed`` (one-process mode).
"""

from mindgrasp_launch.actions import (
    Action,
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    LogInfo,
    Node,
    ProcessSpec,
    PushRosNamespace,
    SetLaunchConfiguration,
    SetParameter,
    SetRemap,
    Shutdown,
)
from mindgrasp_launch.conditions import (
    IfCondition,
    LaunchConfigurationEquals,
    LaunchConfigurationNotEquals,
    UnlessCondition,
)
from mindgrasp_launch.context import LaunchContext
from mindgrasp_launch.description import (
    IncludeLaunchDescription,
    LaunchDescription,
    PythonLaunchDescriptionSource,
    find_launch_file,
    load_launch_file,
    profiles,
)
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.params import config_files
from mindgrasp_launch.service import LaunchService
from mindgrasp_launch.substitutions import (
    CameraSpec,
    EnvironmentVariable,
    EqualsSubstitution,
    LaunchConfiguration,
    NotEqualsSubstitution,
    PathJoinSubstitution,
    PythonExpression,
    SplitArguments,
    TextSubstitution,
    ThisLaunchFileDir,
)

__all__ = [
    'Action', 'CameraSpec', 'DeclareLaunchArgument', 'EnvironmentVariable', 'EqualsSubstitution',
    'ExecuteProcess', 'GroupAction', 'IfCondition', 'IncludeLaunchDescription',
    'LaunchConfiguration', 'LaunchConfigurationEquals', 'LaunchConfigurationNotEquals',
    'LaunchContext', 'LaunchDescription', 'LaunchError', 'LaunchService', 'LogInfo', 'Node',
    'NotEqualsSubstitution',
    'PathJoinSubstitution', 'ProcessSpec', 'PushRosNamespace', 'PythonExpression',
    'PythonLaunchDescriptionSource', 'SetLaunchConfiguration', 'SetParameter', 'SetRemap',
    'Shutdown', 'SplitArguments', 'TextSubstitution',
    'ThisLaunchFileDir', 'UnlessCondition', 'config_files', 'find_launch_file',
    'load_launch_file', 'profiles',
]
