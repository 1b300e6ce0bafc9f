"""``ExecuteProcess``: any command, and :class:`ProcessSpec`, what the launcher starts."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.actions.set_launch_configuration import Shutdown
from mindgrasp_launch.conditions import evaluate_bool
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.substitutions import (
    SomeSubstitutions,
    SplitArguments,
    perform_substitutions,
)

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext

OUTPUTS = ('screen', 'log', 'both')


@dataclass
class ProcessSpec:
    """One process to start, with every substitution resolved.

    ``program`` + ``arguments`` come first; a ROS node then gets ``--ros-args`` followed by its
    name and namespace remaps, ``--params-file <file>`` (written by the launcher into the run
    directory from ``parameters``), ``ros_arguments`` and its remappings, as ``ros2 launch`` does.
    """

    label: str
    program: list[str]
    arguments: list[str] = field(default_factory=list)
    is_node: bool = False
    package: str | None = None
    executable: str | None = None
    module: str | None = None             #: Python module run with ``python -m``, if any
    node_name: str | None = None
    namespace: str = ''
    parameters: dict[str, Any] = field(default_factory=dict)   #: dotted name -> value
    parameter_files: list[str] = field(default_factory=list)
    remappings: list[tuple[str, str]] = field(default_factory=list)
    ros_arguments: list[str] = field(default_factory=list)
    cwd: str | None = None
    env: dict[str, str] | None = None      #: full environment (None: the launcher's)
    additional_env: dict[str, str] = field(default_factory=dict)
    shell: bool = False
    output: str = 'screen'
    respawn: bool = False
    respawn_delay: float = 0.0             #: s
    respawn_max_retries: int = -1          #: -1: no limit
    shutdown_on_exit: bool = False
    #: its end stops the launch as a failure, whatever its exit code (ROS 1's required="true"):
    #: a driver that exits 0 at once must not leave a run without an arm
    required: bool = False
    sigterm_timeout: float | None = None   #: s after SIGINT before SIGTERM (None: launcher's)
    sigkill_timeout: float | None = None   #: s after SIGTERM before SIGKILL (None: launcher's)
    problem: str | None = None             #: why it cannot start (e.g. missing module)
    daemon: bool = False                   #: stopped when every other process has ended
    composable: bool = False               #: a node module that composed mode can load
    #: composed container: logger name ('ns.node') -> label, to prefix and split its output
    logger_labels: dict[str, str] = field(default_factory=dict)

    @property
    def fully_qualified_name(self) -> str | None:
        """``/namespace/name`` when the node name is known."""
        if not self.node_name:
            return None
        return f'{self.namespace}/{self.node_name}' if self.namespace else f'/{self.node_name}'

    def command(self, params_file: str | Path | None = None) -> list[str]:
        """The full command line (``params_file``: the resolved parameters of this node)."""
        cmd = [*self.program, *self.arguments]
        if not self.is_node:
            return cmd
        ros = []
        if self.node_name:
            ros += ['-r', f'__node:={self.node_name}']
        if self.namespace:
            ros += ['-r', f'__ns:={self.namespace}']
        if params_file is not None:
            ros += ['--params-file', str(params_file)]
        ros += list(self.ros_arguments)
        for src, dst in self.remappings:
            ros += ['-r', f'{src}:={dst}']
        return [*cmd, '--ros-args', *ros] if ros else cmd


def resolve_list(context: LaunchContext, values: Iterable[SomeSubstitutions] | None) -> list[str]:
    """Resolve each item of a list of substitutions to one string (``SplitArguments``: to
    several)."""
    out: list[str] = []
    for value in values or []:
        if isinstance(value, SplitArguments):
            out.extend(value.perform_list(context))
        else:
            out.append(perform_substitutions(context, value))
    return out


def resolve_env(context: LaunchContext,
                env: Mapping[SomeSubstitutions, SomeSubstitutions] | Iterable | None,
                ) -> dict[str, str] | None:
    """Resolve an environment mapping (or list of pairs)."""
    if env is None:
        return None
    items = env.items() if isinstance(env, Mapping) else env
    return {perform_substitutions(context, k): perform_substitutions(context, v)
            for k, v in items}


def check_output(output: str) -> str:
    """Validate ``output=``."""
    if output not in OUTPUTS:
        msg = f"output={output!r} is not supported: use one of {', '.join(OUTPUTS)}."
        raise LaunchError(msg)
    return output


class ExecuteProcess(Action):
    """Start an arbitrary command, e.g. ``ExecuteProcess(cmd=['rviz2'], name='rviz')``."""

    def __init__(self, *, cmd: Iterable[SomeSubstitutions], name: SomeSubstitutions | None = None,
                 cwd: SomeSubstitutions | None = None,
                 env: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
                 additional_env: Mapping[SomeSubstitutions, SomeSubstitutions] | None = None,
                 shell: bool = False, output: str = 'screen',
                 respawn: bool | SomeSubstitutions = False,
                 respawn_delay: float | SomeSubstitutions = 0.0, respawn_max_retries: int = -1,
                 on_exit: Shutdown | None = None, sigterm_timeout: float | None = None,
                 sigkill_timeout: float | None = None, required: bool = False,
                 **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.cmd = list(cmd)
        if not self.cmd:
            raise LaunchError('ExecuteProcess: cmd is empty; give the command as a list.')
        self.name = name
        self.cwd = cwd
        self.env = env
        self.additional_env = additional_env
        self.shell = shell
        self.output = check_output(output)
        self.respawn = respawn
        self.respawn_delay = respawn_delay
        self.respawn_max_retries = int(respawn_max_retries)
        if on_exit is not None and not isinstance(on_exit, Shutdown):
            raise LaunchError('on_exit: only on_exit=Shutdown() is supported.')
        self.on_exit = on_exit
        self.required = bool(required)
        self.sigterm_timeout = sigterm_timeout
        self.sigkill_timeout = sigkill_timeout

    def common_fields(self, context: LaunchContext) -> dict[str, Any]:
        """Fields shared by processes and nodes."""
        return {
            'cwd': None if self.cwd is None else perform_substitutions(context, self.cwd),
            'env': resolve_env(context, self.env),
            'additional_env': resolve_env(context, self.additional_env) or {},
            'shell': self.shell, 'output': self.output,
            'respawn': (self.respawn if isinstance(self.respawn, bool)
                        else evaluate_bool(perform_substitutions(context, self.respawn),
                                           'respawn')),
            'respawn_delay': self._delay(context),
            'respawn_max_retries': self.respawn_max_retries,
            'shutdown_on_exit': self.on_exit is not None or self.required,
            'required': self.required,
            'sigterm_timeout': self.sigterm_timeout, 'sigkill_timeout': self.sigkill_timeout,
        }

    def _delay(self, context: LaunchContext) -> float:
        text = (str(self.respawn_delay) if isinstance(self.respawn_delay, (int, float))
                else perform_substitutions(context, self.respawn_delay))
        try:
            delay = float(text)
        except ValueError:
            delay = -1.0
        if delay < 0:
            msg = f'respawn_delay must be a number of seconds >= 0, got {text!r}.'
            raise LaunchError(msg)
        return delay

    def execute(self, context: LaunchContext) -> None:
        cmd = resolve_list(context, self.cmd)
        if self.shell:
            cmd = [' '.join(cmd)]
        label = (perform_substitutions(context, self.name) if self.name is not None
                 else Path(cmd[0].split()[0]).name)
        context.processes.append(ProcessSpec(label=label, program=cmd,
                                             **self.common_fields(context)))
