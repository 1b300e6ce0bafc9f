"""What every launch gets around its nodes: the run directory, the recorder and a duration limit.

``mindgrasp launch`` adds them to any launch file (:mod:`~mindgrasp_bringup.launch_system.service`);
under ``ros2 launch`` the profiles carry them as ordinary actions
(:func:`~mindgrasp_bringup.launch_system.common.run_directory_actions`,
:class:`mindgrasp_bringup.launch_ros_extras.RunDirectory`). Both read the same launch arguments
through the functions here, so ``record_topics:=...`` or ``duration:=30`` mean the same under both.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from mindgrasp_bringup.launch_system.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_bringup.launch_system.conditions import evaluate_bool
from mindgrasp_bringup.launch_system.errors import LaunchError

RECORDER_PACKAGE = 'mindgrasp_bringup'
RECORDER_EXECUTABLE = 'recorder_node'
RECORDER_NAME = 'recorder'

#: arguments every launch accepts (the launcher handles them; profiles may read them too)
COMMON_ARGUMENTS = (
    DeclareLaunchArgument(
        'record', default_value='true', choices=['true', 'false'],
        description='record every topic into <run dir>/bag (rosbag2, MCAP) with the recorder '
                    'node'),
    DeclareLaunchArgument(
        'record_topics', default_value='',
        description='topic names to record, separated by spaces or commas (empty: every topic, '
                    'or those matching record_regex)'),
    DeclareLaunchArgument(
        'record_regex', default_value='',
        description='record the topics matching this regular expression (empty: no filter)'),
    DeclareLaunchArgument(
        'duration', default_value='0',
        description='end the launch after this many seconds (0: run until Ctrl-C or until '
                    'every node has ended)'),
)
COMMON_NAMES = tuple(a.name for a in COMMON_ARGUMENTS)


def record_enabled(configurations: Mapping[str, str]) -> bool:
    """``record:=`` as a bool (a clear :class:`LaunchError` for anything but true/false)."""
    return evaluate_bool(configurations.get('record', 'true'), "launch argument 'record'")


def duration_limit(configurations: Mapping[str, str]) -> float | None:
    """``duration:=`` in seconds, ``None`` for 0 (no limit); a :class:`LaunchError` otherwise."""
    text = configurations.get('duration', '0')
    try:
        duration = float(text)
    except ValueError:
        duration = math.nan
    if not math.isfinite(duration) or duration < 0:
        msg = (f"launch argument 'duration' must be a number of seconds >= 0 (0: no limit), "
               f"got {text!r}.")
        raise LaunchError(msg)
    return duration if duration > 0 else None


def recorder_parameters(configurations: Mapping[str, str], bag: str) -> dict[str, Any]:
    """Parameters of the recorder node for ``record_topics:=`` / ``record_regex:=``."""
    parameters: dict[str, Any] = {'output': bag}
    topics = configurations.get('record_topics', '')
    if topics.strip():
        parameters['topics'] = [t for t in topics.replace(',', ' ').split() if t]
    regex = configurations.get('record_regex', '')
    if regex:
        parameters['regex'] = regex
    return parameters
