"""Launch actions, one per module as in ``launch``/``launch_ros``."""

from mindgrasp_bringup.launch_system.actions.action import Action
from mindgrasp_bringup.launch_system.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_bringup.launch_system.actions.execute_process import ExecuteProcess, ProcessSpec
from mindgrasp_bringup.launch_system.actions.group_action import GroupAction, PushRosNamespace
from mindgrasp_bringup.launch_system.actions.node import Node
from mindgrasp_bringup.launch_system.actions.set_launch_configuration import (
    LogInfo,
    SetLaunchConfiguration,
    SetParameter,
    SetRemap,
    Shutdown,
)

__all__ = ['Action', 'DeclareLaunchArgument', 'ExecuteProcess', 'GroupAction', 'LogInfo', 'Node',
           'ProcessSpec', 'PushRosNamespace', 'SetLaunchConfiguration', 'SetParameter',
           'SetRemap', 'Shutdown']
