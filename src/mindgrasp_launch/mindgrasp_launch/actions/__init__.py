"""Launch actions, one per module as in ``launch``/``launch_ros``."""

from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_launch.actions.execute_process import ExecuteProcess, ProcessSpec
from mindgrasp_launch.actions.group_action import GroupAction, PushRosNamespace
from mindgrasp_launch.actions.node import Node
from mindgrasp_launch.actions.set_launch_configuration import (
    LogInfo,
    SetLaunchConfiguration,
    SetParameter,
    SetRemap,
    Shutdown,
)

__all__ = ['Action', 'DeclareLaunchArgument', 'ExecuteProcess', 'GroupAction', 'LogInfo', 'Node',
           'ProcessSpec', 'PushRosNamespace', 'SetLaunchConfiguration', 'SetParameter',
           'SetRemap', 'Shutdown']
