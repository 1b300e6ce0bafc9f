"""The one import point of launch files: the real ``launch``/``launch_ros`` when ROS 2 is sourced,
our launcher (:mod:`mindgrasp_launch`) otherwise.

Launch files import every action from here, so the same file runs under ``ros2 launch`` and under
``mindgrasp launch``, as node code imports ``from mindgrasp_ros import rclpy``::

    from mindgrasp_launch.launch_api import (DeclareLaunchArgument, LaunchConfiguration,
                                              LaunchDescription, Node, config_files)

Which one a name resolves to is decided when the launch file imports it:

- while our launcher loads a launch file (``mindgrasp launch``, :func:`own_launcher`): ours;
- else, when ``launch_ros`` is importable (ROS 2 sourced, e.g. under ``ros2 launch``): the real one;
- else: ours (plain Python without ROS 2).

Only launch_ros's own API is offered (same names, same keyword arguments), plus our helpers
(:func:`config_files`, :func:`classifier_nodes`, ...) that build launch_ros actions.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import os
import threading
from collections.abc import Iterator

_OWN = 'mindgrasp_launch'

#: name -> (module of the real launch / launch_ros, module of ours)
_SOURCES: dict[str, tuple[str, str]] = {
    'LaunchDescription': ('launch', _OWN),
    'DeclareLaunchArgument': ('launch.actions', _OWN),
    'ExecuteProcess': ('launch.actions', _OWN),
    'GroupAction': ('launch.actions', _OWN),
    'IncludeLaunchDescription': ('launch.actions', _OWN),
    'LogInfo': ('launch.actions', _OWN),
    'SetLaunchConfiguration': ('launch.actions', _OWN),
    'Shutdown': ('launch.actions', _OWN),
    'IfCondition': ('launch.conditions', _OWN),
    'UnlessCondition': ('launch.conditions', _OWN),
    'LaunchConfigurationEquals': ('launch.conditions', _OWN),
    'LaunchConfigurationNotEquals': ('launch.conditions', _OWN),
    'PythonLaunchDescriptionSource': ('launch.launch_description_sources', _OWN),
    'EnvironmentVariable': ('launch.substitutions', _OWN),
    'EqualsSubstitution': ('launch.substitutions', _OWN),
    'NotEqualsSubstitution': ('launch.substitutions', _OWN),
    'LaunchConfiguration': ('launch.substitutions', _OWN),
    'PathJoinSubstitution': ('launch.substitutions', _OWN),
    'PythonExpression': ('launch.substitutions', _OWN),
    'TextSubstitution': ('launch.substitutions', _OWN),
    'ThisLaunchFileDir': ('launch.substitutions', _OWN),
    'Node': ('launch_ros.actions', _OWN),
    'PushRosNamespace': ('launch_ros.actions', _OWN),
    'SetParameter': ('launch_ros.actions', _OWN),
    'SetRemap': ('launch_ros.actions', _OWN),
    # ours, with a real-launch twin
    'SplitArguments': ('mindgrasp_launch.launch_ros_extras', _OWN),
    'CameraSpec': ('mindgrasp_launch.launch_ros_extras', _OWN),
}

#: our helpers, the same under both launchers (they build actions through this module)
_HELPERS = {
    'config_files': 'mindgrasp_launch.params',
    'number_argument': 'mindgrasp_launch.number_argument',
    'file_argument': 'mindgrasp_launch.number_argument',
    'checked_argument': 'mindgrasp_launch.number_argument',
    'classifier_nodes': 'mindgrasp_launch.common',
    'eeg_source_arguments': 'mindgrasp_launch.common',
    'eeg_source_nodes': 'mindgrasp_launch.common',
    'eeg_pin_arguments': 'mindgrasp_launch.common',
    'eeg_pin_parameters': 'mindgrasp_launch.common',
    'virtual_amp_pin': 'mindgrasp_launch.common',
    'display_arguments': 'mindgrasp_launch.common',
    'display_nodes': 'mindgrasp_launch.common',
    'sim_scene_camera': 'mindgrasp_launch.common',
    'live_view_arguments': 'mindgrasp_launch.common',
    'live_view_nodes': 'mindgrasp_launch.common',
    'run_directory_actions': 'mindgrasp_launch.common',
    'driver_nodes': 'mindgrasp_launch.common',
    'fsm_node': 'mindgrasp_launch.common',
    'command_interface_argument': 'mindgrasp_launch.common',
    'robot_argument': 'mindgrasp_launch.common',
}

__all__ = ['own_launcher', 'using_real_launch', *_SOURCES, *_HELPERS]

_state = threading.local()


@contextlib.contextmanager
def own_launcher() -> Iterator[None]:
    """While our launcher imports a launch file and builds its description: our actions."""
    depth = getattr(_state, 'own_depth', 0)
    _state.own_depth = depth + 1
    try:
        yield
    finally:
        _state.own_depth = depth


def using_real_launch() -> bool:
    """Whether launch files get the real ``launch``/``launch_ros`` actions now.

    ``MINDGRASP_LAUNCH=own`` forces ours (e.g. to check a launch file without ROS 2).
    """
    if getattr(_state, 'own_depth', 0) or os.environ.get('MINDGRASP_LAUNCH', '') == 'own':
        return False
    try:
        return importlib.util.find_spec('launch_ros') is not None
    except (ImportError, ValueError):
        return False


def __getattr__(name: str) -> object:
    if name in _HELPERS:
        return getattr(importlib.import_module(_HELPERS[name]), name)
    if name not in _SOURCES:
        msg = f'module {__name__!r} has no attribute {name!r}'
        raise AttributeError(msg)
    real, own = _SOURCES[name]
    # not cached in globals(): the answer depends on who imports (ros2 launch or ours)
    return getattr(importlib.import_module(real if using_real_launch() else own), name)


def __dir__() -> list[str]:
    return sorted(__all__)
