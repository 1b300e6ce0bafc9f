"""Our launch extensions as real ``launch`` entities, for launch files run by ``ros2 launch``.

Imported only through :mod:`mindgrasp_launch.launch_api` when the real ``launch`` is in use.
"""

from __future__ import annotations

import shlex
import shutil
import sys
from pathlib import Path
from typing import Any

import launch.logging
from launch.action import Action
from launch.actions import LogInfo, RegisterEventHandler, Shutdown, TimerAction
from launch.event_handlers import OnProcessExit, OnShutdown
from launch.launch_context import LaunchContext
from launch.some_substitutions_type import SomeSubstitutionsType
from launch.substitution import Substitution
from launch.substitutions.substitution_failure import SubstitutionFailure
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions
from launch_ros.actions import Node

from mindgrasp_launch import rundir
from mindgrasp_launch.actions.node import find_module
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.run_extras import (
    RECORDER_EXECUTABLE,
    RECORDER_NAME,
    RECORDER_PACKAGE,
    RunFiles,
    duration_limit,
    record_enabled,
    recorder_parameters,
)


class CameraSpec(Substitution):
    """One field (``'width'``, ``'height'`` or ``'rate'``) of a ``WIDTHxHEIGHT@HZ`` text: parsed
    by :func:`mindgrasp_launch.launch_args.parse_camera`, never evaluated."""

    def __init__(self, value: SomeSubstitutionsType, field: str) -> None:
        super().__init__()
        self.value = normalize_to_list_of_substitutions(value)
        self.field = field

    def describe(self) -> str:
        return f'CameraSpec({" + ".join(s.describe() for s in self.value)}, {self.field!r})'

    def perform(self, context: LaunchContext) -> str:
        from mindgrasp_launch.launch_args import CAMERA_FIELDS, parse_camera

        try:
            values = parse_camera(perform_substitutions(context, self.value))
        except ValueError as exc:
            raise SubstitutionFailure(str(exc)) from None
        return str(values[CAMERA_FIELDS.index(self.field)])


class SplitArguments(Substitution):
    """``arguments=[SplitArguments(LaunchConfiguration('driver_args'))]``.

    ``launch`` passes each item of ``arguments`` as one argument, so under ``ros2 launch`` this
    substitution holds at most one argument; several need ``mindgrasp launch`` (which splits them
    with shell quoting), or a node built when the launch runs, as :func:`driver_node` does.
    """

    def __init__(self, value: SomeSubstitutionsType) -> None:
        super().__init__()
        self.value = normalize_to_list_of_substitutions(value)

    def describe(self) -> str:
        return f'SplitArguments({" + ".join(s.describe() for s in self.value)})'

    def perform(self, context: LaunchContext) -> str:
        text = perform_substitutions(context, self.value)
        if len(text.split()) > 1:
            msg = (f'{text!r} holds several arguments, which ros2 launch passes as one: run this '
                   f'profile with mindgrasp launch, or start the driver with its own launch file.')
            raise SubstitutionFailure(msg)
        return text.strip()


_MARK = 'mindgrasp_run_directory'  # in the launch's globals once a run directory exists


class RunDirectory(Action):
    """What ``mindgrasp launch`` adds around a launch file, as one action for ``ros2 launch``.

    When executed it creates the run directory (``run_dir:=PATH``, else
    ``$MINDGRASP_RUNS_DIR`` or ``runs/`` + ``<UTC time>_<launch file name>``), writes
    ``launch.yaml``, ``launch_arguments.yaml`` and ``provenance.yaml`` there, sets
    ``MINDGRASP_RUN_DIR`` for the nodes launched after it and the launch configuration
    ``run_dir``, has the nodes log to stderr as rclpy's do (``RCUTILS_LOGGING_USE_STDOUT=0``),
    and then launches the recorder into ``<run dir>/bag`` (``record:=true``) and a
    timer that shuts the launch down after ``duration:=`` seconds. ``summary.yaml`` gets each
    process's exit code as it ends, and the shutdown reason. Put it after the launch arguments
    and before the first node, so that the recorder starts first. A second one in the same launch
    (an included profile) reuses the first one's directory and recorder.
    """

    def execute(self, context: LaunchContext) -> list[Any] | None:
        configurations = context.launch_configurations
        if context.get_locals_as_dict().get(_MARK) is not None:
            return None  # an outer profile made the run directory, and records
        # every value is checked before anything is created or started; ros2 launch prints a
        # LaunchError's text on one line and ends
        record = record_enabled(configurations)
        duration = duration_limit(configurations)
        launch_file = context.get_locals_as_dict().get('current_launch_file_path')
        profile = Path(launch_file).name.removesuffix('.launch.py') if launch_file else 'launch'
        path = rundir.create_run_dir(profile, configurations.get('run_dir') or None)
        context.extend_globals({_MARK: path})
        configurations['run_dir'] = str(path)
        context.environment['MINDGRASP_RUN_DIR'] = str(path)
        # ros2 launch shows a node's stderr only (output='log'); rcutils logs every level to
        # stderr, our runtime INFO to stdout unless told otherwise: the nodes' progress then
        # reaches the screen as an rclpy node's does (a value the user set is kept)
        context.environment.setdefault('RCUTILS_LOGGING_USE_STDOUT', '0')
        files = RunFiles(path)
        # ros2 launch keeps the nodes' output in its own log directory
        logs = getattr(launch.logging.launch_config, 'log_dir', None)
        files.write_start(profile=profile, launch_file=launch_file, launcher='ros2 launch',
                          command_line=sys.argv, arguments=configurations, record=record,
                          duration=duration, logs=str(logs) if logs else None)
        launch.logging.get_logger('launch').info(f'run directory: {path}')
        entities: list[Any] = [
            RegisterEventHandler(OnProcessExit(on_exit=lambda event, _: files.process_ended(
                event.process_name, event.pid, event.returncode))),
            RegisterEventHandler(OnShutdown(on_shutdown=lambda event, _: files.stopping(
                event.reason))),
        ]
        if record:
            entities.insert(0, Node(
                package=RECORDER_PACKAGE, executable=RECORDER_EXECUTABLE, name=RECORDER_NAME,
                parameters=[recorder_parameters(configurations, str(path / 'bag'))]))
        if duration is not None:
            entities.append(TimerAction(period=duration, actions=[
                Shutdown(reason=f'duration:={duration:g} s elapsed')]))
        return entities


def driver_executable(text: str, argument: str) -> str:
    """The program ``ros2 launch`` runs for a driver named in a launch argument: a path, a
    program on PATH, or ``package/executable`` (``lib/<package>/<executable>`` of the sourced
    workspaces, as ``ros2 run``). A Python module (``pkg.module``, which ``mindgrasp launch``
    runs with ``python -m``) is refused with the fix, as is a name found nowhere."""
    path = Path(text).expanduser()
    if path.is_file():
        return str(path)
    if text and shutil.which(text):
        return text
    pkg, sep, exe = text.partition('/')
    if sep and pkg and exe and '/' not in exe:
        from ament_index_python.packages import PackageNotFoundError, get_package_prefix

        try:
            program = Path(get_package_prefix(pkg)) / 'lib' / pkg / exe
        except PackageNotFoundError:
            msg = (f"{argument}:={text}: package '{pkg}' is not in the sourced workspaces; "
                   f"source its install/setup.bash, or give the driver's path.")
            raise LaunchError(msg) from None
        if not program.is_file():
            msg = f"{argument}:={text}: package '{pkg}' has no executable {program}."
            raise LaunchError(msg)
        return str(program)
    if '.' in text and find_module(text):
        msg = (f"{argument}:={text} is a Python module, which ros2 launch cannot start as a node "
               f"executable: give package/executable or a path, or use mindgrasp launch.")
        raise LaunchError(msg)
    msg = (f"{argument}:={text!r} was found neither as a path, on PATH, nor as "
           f"package/executable: install the driver, or give its path.")
    raise LaunchError(msg)


def driver_node(context: LaunchContext, role: str) -> list[Any]:
    """Body of an ``OpaqueFunction``: the ``<role>_driver`` node, started from the program
    ``<role>_driver:=`` names with ``<role>_driver_args:=`` split by shell rules (no argument at
    all when it is empty), built when the launch runs because only then is the number of
    arguments known."""
    configurations = context.launch_configurations
    executable = driver_executable(configurations.get(f'{role}_driver', ''), f'{role}_driver')
    text = configurations.get(f'{role}_driver_args', '')
    try:
        arguments = shlex.split(text)
    except ValueError as exc:
        msg = f'{role}_driver_args:={text!r} cannot be split into arguments ({exc}): check quotes.'
        raise LaunchError(msg) from None
    # a required node, launch's way: its end shuts the launch down
    return [Node(executable=executable, name=f'{role}_driver', arguments=arguments,
                 on_exit=[LogInfo(msg=f'the {role} driver ended; stopping the launch'),
                          Shutdown(reason=f'the {role} driver ended')])]
