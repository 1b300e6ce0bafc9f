"""What every launch gets around its nodes: the run directory, the recorder and a duration limit.

``mindgrasp launch`` adds them to any launch file (:mod:`~mindgrasp_launch.service`);
under ``ros2 launch`` the profiles carry them as ordinary actions
(:func:`~mindgrasp_launch.common.run_directory_actions`,
:class:`mindgrasp_launch.launch_ros_extras.RunDirectory`). Both read the same launch arguments
through the functions here, so ``record_topics:=...`` or ``duration:=30`` mean the same under both.
"""

from __future__ import annotations

import datetime as dt
import logging
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_common.safe_files import DeferredWriter
from mindgrasp_launch import rundir
from mindgrasp_launch.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_launch.conditions import evaluate_bool
from mindgrasp_launch.errors import LaunchError

RECORDER_PACKAGE = 'mindgrasp_bag'
RECORDER_EXECUTABLE = 'recorder_node'
RECORDER_NAME = 'recorder'

#: arguments every launch accepts (the launcher handles them; profiles may read them too)
#: Topics left out of a run's bag by default: the frames the participant display and the Graz
#: prompter draw, from prompts, flips and states that the bag keeps. Uncompressed they were 99 %
#: of a 22-s Graz bag (benchmarks/bag_size.py). ``record_exclude_regex:=''`` records them too.
DEFAULT_RECORD_EXCLUDE = r'^/(display/image|trainer/display)$'

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
        'record_exclude_regex', default_value=DEFAULT_RECORD_EXCLUDE,
        description="do not record the topics matching this regular expression (default: the "
                    "frames of the participant display and the Graz prompter, which are drawn "
                    "from recorded prompts and states; empty: exclude nothing)"),
    DeclareLaunchArgument(
        'record_compression', default_value='zstd', choices=['none', 'zstd', 'lz4'],
        description='MCAP chunk compression of the bag (as ros2 bag record '
                    '--compression-format; zstd: about a third of the size for a few % of a '
                    'core)'),
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


def recorder_outputs(bag: str | Path) -> dict[str, str]:
    """Where the recorder of a run writes: the bag (``<run dir>/bag``) and the live parameter
    changes (``<run dir>/params/changes.jsonl``)."""
    return {'output': str(bag),
            'parameter_changes': str(Path(bag).parent / 'params' / 'changes.jsonl')}


def recorder_parameters(configurations: Mapping[str, str], bag: str) -> dict[str, Any]:
    """Parameters of the recorder node for ``record_topics:=``, ``record_regex:=``,
    ``record_exclude_regex:=`` and ``record_compression:=``; a profile's ``robot:=`` goes into
    the bag's metadata.yaml (``custom_data: robot``)."""
    parameters: dict[str, Any] = {
        **recorder_outputs(bag),
        'exclude_regex': configurations.get('record_exclude_regex', DEFAULT_RECORD_EXCLUDE),
        'compression': configurations.get('record_compression', 'zstd')}
    topics = configurations.get('record_topics', '')
    if topics.strip():
        parameters['topics'] = [t for t in topics.replace(',', ' ').split() if t]
    regex = configurations.get('record_regex', '')
    if regex:
        parameters['regex'] = regex
    robot = configurations.get('robot', '').strip()
    if robot:
        parameters['custom_data'] = [f'robot={robot}']
    return parameters


def _now() -> str:
    return dt.datetime.now(dt.timezone.utc).isoformat(timespec='seconds')


class RunFiles:
    """The files of a run directory whose processes another launcher runs (``ros2 launch``).

    ``launch.yaml``, ``launch_arguments.yaml`` and ``provenance.yaml`` when the launch starts;
    ``summary.yaml`` rewritten as each process ends (label, pid, exit code) and when the launch
    shuts down (the reason), so that it is complete whenever the launch stops.

    Parameters
    ----------
    path
        An existing run directory (:func:`rundir.create_run_dir`).
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.summary: dict[str, Any] = {'ended_utc': None, 'stop_reason': None, 'processes': []}
        # a full disk costs only this file: kept, copied to a fallback folder the log names
        self.files = DeferredWriter(path)

    def write_start(self, *, profile: str, launch_file: str | None, launcher: str,
                    command_line: Sequence[str], arguments: Mapping[str, str], record: bool,
                    duration: float | None, logs: str | None) -> None:
        """Write what the launch is: arguments, profile, command line, provenance."""
        rundir.write_yaml(self.path / 'launch_arguments.yaml', dict(sorted(arguments.items())),
                          header='launch arguments (given or default); rerun with name:=value')
        rundir.write_yaml(self.path / 'launch.yaml', {
            'profile': profile, 'launch_file': launch_file, 'launcher': launcher,
            'command_line': list(command_line), 'started_utc': _now(), 'record': record,
            'duration_s': duration, 'logs': logs})
        rundir.write_yaml(self.path / 'provenance.yaml', rundir.provenance())

    def process_ended(self, label: str, pid: int | None, returncode: int | None) -> None:
        """One process ended (``returncode`` as ``subprocess``: negative for a signal)."""
        self.summary['processes'].append({'label': label, 'pid': pid, 'returncode': returncode,
                                          'clean': returncode == 0})
        self._write_summary()

    def stopping(self, reason: str) -> None:
        """The launch is shutting down (``reason`` as the launcher gives it)."""
        self.summary['stop_reason'] = reason
        self._write_summary()

    def _write_summary(self) -> None:
        self.summary['ended_utc'] = _now()
        summary = dict(self.summary)
        for line in self.files.write(self.path, 'run summary', lambda folder: rundir.write_yaml(
                folder / 'summary.yaml', summary, header='rewritten as each process ends')):
            logging.getLogger('launch').error(line)
