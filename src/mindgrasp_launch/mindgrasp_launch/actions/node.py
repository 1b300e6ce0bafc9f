"""``Node``: a ROS 2 node process, as ``launch_ros.actions.Node``."""

from __future__ import annotations

import importlib.util
import os
import shutil
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mindgrasp_launch import params as ros_params
from mindgrasp_launch.actions.execute_process import (
    ExecuteProcess,
    ProcessSpec,
    resolve_list,
)
from mindgrasp_launch.actions.group_action import join_namespace
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.substitutions import (
    SomeSubstitutions,
    Substitution,
    is_substitution,
    perform_substitutions,
    resolve_parameter_value,
)
from mindgrasp_ros.start import python_module_argv

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext

ParameterItem = str | Path | Substitution | Mapping[str, Any]


def find_module(module: str) -> bool:
    """Whether ``python -m module`` can run, without importing the module itself."""
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def node_module(package: str, executable: str) -> str | None:
    """The Python module of a node of one of our packages, as its console script names it.

    ``<package>.<executable>`` (``mindgrasp_fsm.fsm_node``), else one subpackage down
    (``mindgrasp_bringup.replay.replay_node``): where ``setup.py`` points the console script
    ``<executable> = <module>:main``. None when neither exists.
    """
    module = f'{package}.{executable}'
    if find_module(module):
        return module
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    for location in spec.submodule_search_locations:
        for sub in sorted(Path(location).iterdir()):
            if (sub / '__init__.py').is_file() and (sub / f'{executable}.py').is_file():
                return f'{package}.{sub.name}.{executable}'
    return None


def ament_executable(package: str, executable: str) -> str | None:
    """``<prefix>/lib/<package>/<executable>`` of a sourced ROS 2 workspace (``AMENT_PREFIX_PATH``),
    as ``ros2 run`` finds it; None when no prefix has it."""
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        candidate = Path(prefix) / 'lib' / package / executable
        if prefix and candidate.is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    return None


def resolve_program(package: str | None, executable: str) -> tuple[list[str], str | None, str |
                                                                                         None]:
    """The program of a node: ``(argv prefix, python module or None, problem or None)``.

    ``package`` + ``executable`` is the node module of our packages (:func:`node_module`), run as
    ``python -m``; failing that, the console script ``lib/<package>/<executable>`` of a sourced
    ROS 2 workspace (as ``ros2 run`` finds it), or an executable of that name on PATH.
    Without a package, ``executable`` is a path, a program on PATH, a dotted module name, or
    ``package/executable``: our module ``package.executable``, else ``ros2 run package executable``
    (a ROS 2 driver, when ROS 2 is sourced).
    """
    if package:
        module = node_module(package, executable)
        if module is not None:
            return python_module_argv(module), module, None
        found = ament_executable(package, executable) or shutil.which(executable)
        if found:
            return [found], None, None
        module = f'{package}.{executable}'
        problem = (f"the node module '{module}' does not exist (yet), so 'python -m {module}' "
                   f"cannot start: write or install it, check package= and executable=, or "
                   f"leave the node out.")
        return python_module_argv(module), module, problem
    path = Path(executable).expanduser()
    if os.sep in executable and path.is_file():
        if not os.access(path, os.X_OK):
            return [str(path)], None, (f"'{path}' is not executable: chmod +x it, or give its "
                                       f"interpreter with ExecuteProcess.")
        return [str(path.resolve())], None, None
    found = shutil.which(executable)
    if found:
        return [found], None, None
    if '.' in executable and '/' not in executable and find_module(executable):
        return python_module_argv(executable), executable, None
    pkg, sep, exe = executable.partition('/')
    if sep and pkg and exe and '/' not in exe:  # 'package/executable', as `ros2 run` takes it
        module = node_module(pkg, exe)
        if module is not None:
            return python_module_argv(module), module, None
        module = f'{pkg}.{exe}'
        ros2 = shutil.which('ros2')
        if ros2:
            return [ros2, 'run', pkg, exe], None, None
        problem = (f"'{executable}' is neither the Python module {module} nor runnable with "
                   f"'ros2 run' (ros2 is not on PATH): source your ROS 2 setup, or give the "
                   f"driver's full path.")
        return [executable], None, problem
    problem = (f"the executable '{executable}' was found neither on PATH nor as a Python "
               f"module: install it, give its full path, or fix the launch argument naming it.")
    return [executable], None, problem


class Node(ExecuteProcess):
    """A ROS 2 node: ``Node(package='mindgrasp_sim', executable='sim_node', name='sim', ...)``.

    parameters: parameter files (paths or substitutions) and dicts, applied in order (later
    wins); the entries of a file that match the node's name are merged into one parameter file
    the node gets with ``--params-file``. remappings: ``[(from, to)]``. arguments: command-line
    arguments before ``--ros-args``; ros_arguments: extra arguments after it (``--log-level``).
    """

    def __init__(self, *, executable: SomeSubstitutions, package: SomeSubstitutions | None = None,
                 name: SomeSubstitutions | None = None,
                 namespace: SomeSubstitutions | None = None,
                 parameters: Iterable[ParameterItem] | None = None,
                 remappings: Iterable[tuple[SomeSubstitutions, SomeSubstitutions]] | None = None,
                 arguments: Iterable[SomeSubstitutions] | None = None,
                 ros_arguments: Iterable[SomeSubstitutions] | None = None,
                 **kwargs: Any) -> None:
        super().__init__(cmd=[executable], **kwargs)
        self.package = package
        self.executable = executable
        self.node_name = name
        self.node_namespace = namespace
        self.parameters = list(parameters or [])
        for item in self.parameters:
            if not isinstance(item, (str, Path, Substitution, Mapping, list)):
                msg = (f'parameters=[...] items must be parameter file paths or dicts, got '
                       f'{type(item).__name__} {item!r}.')
                raise LaunchError(msg)
        self.remappings = []
        for pair in remappings or []:
            if not (isinstance(pair, (tuple, list)) and len(pair) == 2):
                msg = f'remappings must be (from, to) pairs, got {pair!r}.'
                raise LaunchError(msg)
            self.remappings.append(tuple(pair))
        self.arguments = list(arguments or [])
        self.ros_arguments = list(ros_arguments or [])

    def execute(self, context: LaunchContext) -> None:
        package = None if self.package is None else perform_substitutions(context, self.package)
        executable = perform_substitutions(context, self.executable)
        name = None if self.node_name is None else perform_substitutions(context, self.node_name)
        if name is not None and (not name or '/' in name or ' ' in name):
            msg = f"node name {name!r} is invalid: a ROS node name has no '/' or spaces."
            raise LaunchError(msg)
        namespace = join_namespace(
            context.ros_namespace,
            '' if self.node_namespace is None else perform_substitutions(context,
                                                                         self.node_namespace))
        program, module, problem = resolve_program(package, executable)
        spec = ProcessSpec(
            label=name or Path(executable).name.split('.')[-1], program=program,
            arguments=resolve_list(context, self.arguments), is_node=True, package=package,
            executable=executable, module=module, node_name=name, namespace=namespace,
            remappings=[*context.global_remappings,
                        *((perform_substitutions(context, a), perform_substitutions(context, b))
                          for a, b in self.remappings)],
            ros_arguments=resolve_list(context, self.ros_arguments), problem=problem,
            composable=module is not None, **self.common_fields(context))
        spec.parameters, spec.parameter_files = self._resolve_parameters(context, spec)
        context.processes.append(spec)

    def _resolve_parameters(self, context: LaunchContext, spec: ProcessSpec,
                            ) -> tuple[dict[str, Any], list[str]]:
        fqn = spec.fully_qualified_name
        who = fqn or f"'{spec.label}'"
        merged: dict[str, Any] = ros_params.flatten(context.global_parameters)
        files: list[str] = []
        for item in self.parameters:
            if isinstance(item, Mapping):
                resolved = {perform_substitutions(context, k) if is_substitution(k) else str(k):
                            resolve_parameter_value(context, v) for k, v in item.items()}
                merged.update(ros_params.flatten(resolved))
                continue
            path = Path(perform_substitutions(context, item)).expanduser()
            if context.launch_file is not None and not path.is_absolute() and not path.exists():
                path = context.launch_file.parent / path
            files.append(str(path))
            for key, values in ros_params.load_parameter_file(path).items():
                if ros_params.node_matches(key, fqn):
                    merged.update(values)
        return {k: ros_params.check_value(who, k, v) for k, v in merged.items()}, files
