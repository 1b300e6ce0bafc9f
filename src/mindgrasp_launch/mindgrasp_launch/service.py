"""``LaunchService``: resolve a launch description with its arguments, then run it.

``LaunchService('demo', ['duration:=30']).run()`` creates the run directory, writes the resolved
parameters, arguments and provenance there, starts the recorder (``record:=true``) and every
process, and returns 0 when every process ended cleanly, 1 otherwise (a process that died and
was respawned counts as a failure).
"""

from __future__ import annotations

import datetime as dt
import logging
import os
import re
import signal
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mindgrasp_common.safe_files import DeferredWriter
from mindgrasp_launch import params as ros_params
from mindgrasp_launch import rundir
from mindgrasp_launch.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_launch.actions.execute_process import ProcessSpec
from mindgrasp_launch.actions.node import Node
from mindgrasp_launch.context import LaunchContext
from mindgrasp_launch.description import (
    LaunchDescription,
    collect_arguments,
    find_launch_file,
    load_launch_file,
)
from mindgrasp_launch.domain_check import check_domain_free
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.output import (
    Printer,
    configure_launch_logger,
    remove_handlers,
)
from mindgrasp_launch.run_extras import (
    COMMON_ARGUMENTS,
    RECORDER_EXECUTABLE,
    RECORDER_NAME,
    RECORDER_PACKAGE,
    duration_limit,
    record_enabled,
    recorder_outputs,
    recorder_parameters,
)
from mindgrasp_launch.run_report import write_run_report
from mindgrasp_launch.supervisor import ProcessResult, Supervisor

logger = logging.getLogger('launch')



def parse_launch_arguments(items: Sequence[str] | Mapping[str, Any]) -> dict[str, str]:
    """``['gui:=true', 'n:=3']`` (or a mapping) -> ``{'gui': 'true', 'n': '3'}``."""
    if isinstance(items, Mapping):
        return {str(k): str(v).lower() if isinstance(v, bool) else str(v)
                for k, v in items.items()}
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition(':=')
        if not sep or not name:
            msg = (f"launch argument {item!r} is not of the form name:=value (e.g. gui:=true); "
                   f"write it as name:=value.")
            raise LaunchError(msg)
        out[name] = value
    return out


def format_arguments(arguments: Sequence[DeclareLaunchArgument]) -> str:
    """The argument list as ``ros2 launch --show-args`` prints it."""
    lines = ["Arguments (pass arguments as '<name>:=<value>'):", '']
    for arg in arguments:
        lines.append(f"    '{arg.name}':")
        lines.append(f'        {arg.description}')
        if arg.choices:
            lines.append(f"        Valid choices are: {arg.choices}")
        default = arg.default_text()
        lines.append('        (required)' if default is None else f"        (default: {default!r})")
        lines.append('')
    return '\n'.join(lines)


@dataclass
class LaunchPlan:
    """A resolved launch: the processes to start and every launch argument's value."""

    name: str
    launch_file: Path | None
    arguments: dict[str, str]
    processes: list[ProcessSpec]
    record: bool
    duration: float | None

    def parameters_by_node(self) -> dict[str, dict[str, Any]]:
        """Resolved parameters keyed by fully qualified node name (``/<label>`` if unnamed)."""
        return {(p.fully_qualified_name or f'/{p.label}'): p.parameters
                for p in self.processes if p.is_node}


class LaunchService:
    """Resolve and run a launch description.

    Args:
        description: a profile name, a ``*.launch.py`` path or a :class:`LaunchDescription`.
        launch_arguments: ``['name:=value', ...]`` or a mapping.
        run_dir: the run directory (default ``runs/<UTC timestamp>_<profile>/``).
        runs_root: where default run directories go (default ``$MINDGRASP_RUNS_DIR`` or runs/).
        composed: run the node modules in one process (``mindgrasp_ros.graph``).
        sigint_timeout, sigterm_timeout: s before escalating to SIGTERM, then SIGKILL.
        argv: the command line, stored in the run directory.
        graph_check: s to look for another graph's ``/sim`` or ``/fsm`` on the ROS domain
            before anything starts (:mod:`.domain_check`; 0: not looked for).
    """

    def __init__(self, description: str | Path | LaunchDescription,
                 launch_arguments: Sequence[str] | Mapping[str, Any] = (), *,
                 run_dir: str | Path | None = None, runs_root: str | Path | None = None,
                 composed: bool = False, sigint_timeout: float = 10.0,
                 sigterm_timeout: float = 5.0, printer: Printer | None = None,
                 argv: Sequence[str] | None = None, graph_check: float = 1.0) -> None:
        if isinstance(description, LaunchDescription):
            self.description = description
            self.launch_file = description.source
            self.name = self.launch_file.name.removesuffix('.launch.py') if self.launch_file \
                else 'launch'
        else:
            self.launch_file = find_launch_file(description)
            self.name = (str(description) if self.launch_file.parent.name == 'launch'
                         and not str(description).endswith('.py')
                         else self.launch_file.name.removesuffix('.launch.py'))
            self.description = load_launch_file(self.launch_file)
        self.given = parse_launch_arguments(launch_arguments)
        self.run_dir_option = run_dir
        self.runs_root = runs_root
        self.composed = composed
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.printer = printer
        self.argv = list(argv) if argv is not None else list(sys.argv)
        self.graph_check = graph_check
        self.run_dir: Path | None = None
        self.results: list[ProcessResult] = []
        self.stop_reason: str | None = None
        self.interrupted_by: int | None = None

    # -- arguments -----------------------------------------------------------------------------
    def declared_arguments(self) -> list[DeclareLaunchArgument]:
        """Arguments of the description (includes too), then the common ones."""
        declared = collect_arguments(self.description)
        return [*declared.values(), *(a for a in COMMON_ARGUMENTS if a.name not in declared)]

    def _check_given(self) -> None:
        valid = {a.name: a for a in self.declared_arguments()}
        unknown = [name for name in self.given if name not in valid]
        if unknown:
            listing = ', '.join(
                f'{a.name} (default {a.default_text()!r})' if a.default_value is not None
                else f'{a.name} (required)' for a in valid.values())
            msg = (f"unknown launch argument{'s' if len(unknown) > 1 else ''} "
                   f"{', '.join(repr(u) for u in unknown)} for '{self.name}': valid arguments "
                   f"are {listing}.")
            raise LaunchError(msg)

    # -- resolving -----------------------------------------------------------------------------
    def plan(self, *, strict: bool = True) -> LaunchPlan:
        """Resolve every substitution and condition; raises :class:`LaunchError` on problems.

        ``strict=False`` returns the plan even when a process cannot start (its ``problem``
        says why), e.g. to show what a profile would start.
        """
        self._check_given()
        missing = [e for e in self.description.entities
                   if isinstance(e, DeclareLaunchArgument) and e.default_value is None
                   and e.condition is None and e.name not in self.given]
        if len(missing) > 1:
            listing = '; '.join(f'{a.name}:=<value> ({a.description})' for a in missing)
            msg = f"launch '{self.name}' needs these arguments, which were not given: {listing}."
            raise LaunchError(msg)
        context = LaunchContext(launch_configurations=dict(self.given),
                                launch_file=self.launch_file)
        for argument in COMMON_ARGUMENTS:
            argument.visit(context)
        self.description.visit(context)
        record = record_enabled(context.launch_configurations)
        duration = duration_limit(context.launch_configurations)
        processes = list(context.processes)
        if record:
            processes.insert(0, self._recorder(context))
        self._unique_labels(processes)
        problems = [f"  - {p.label}: {p.problem}" for p in processes if p.problem]
        if problems and strict:
            msg = (f"launch '{self.name}' cannot start:\n" + '\n'.join(problems))
            if record and processes[0].problem:
                msg += '\n  (record:=false launches without the recorder.)'
            raise LaunchError(msg)
        arguments = {a.name: context.launch_configurations.get(a.name)
                     for a in self.declared_arguments()
                     if a.name in context.launch_configurations}
        return LaunchPlan(name=self.name, launch_file=self.launch_file, arguments=arguments,
                          processes=processes, record=record, duration=duration)

    def _recorder(self, context: LaunchContext) -> ProcessSpec:
        # the bag's path is set when the run directory exists
        parameters = recorder_parameters(context.launch_configurations, '<run dir>/bag')
        inner = LaunchContext(launch_configurations=dict(context.launch_configurations))
        Node(package=RECORDER_PACKAGE, executable=RECORDER_EXECUTABLE, name=RECORDER_NAME,
             parameters=[parameters]).visit(inner)
        spec = inner.processes[0]
        spec.daemon = True
        if spec.problem:
            spec.problem = (f"record:=true needs the recorder node "
                            f"'{RECORDER_PACKAGE}.{RECORDER_EXECUTABLE}', which does not exist "
                            f"(yet). Install it, or launch with record:=false.")
        return spec

    @staticmethod
    def _unique_labels(processes: list[ProcessSpec]) -> None:
        seen: dict[str, int] = {'launch': 1}  # logs/launch.log is the launcher's
        for spec in processes:
            spec.label = re.sub(r'[^A-Za-z0-9_.-]+', '_', spec.label).strip('.') or 'process'
            base = spec.label
            seen[base] = seen.get(base, 0) + 1
            if seen[base] > 1:
                spec.label = f'{base}-{seen[base]}'

    def commands(self, plan: LaunchPlan, run_dir: Path | None) -> list[list[str]]:
        """Full command line of each process (parameter files inside ``run_dir``)."""
        out = []
        for spec in plan.processes:
            params_file = None
            if spec.is_node and spec.parameters:
                params_file = (run_dir or Path('<run dir>')) / 'params' / f'{spec.label}.yaml'
            out.append(spec.command(params_file))
        return out

    # -- running -------------------------------------------------------------------------------
    def _write_run_dir(self, plan: LaunchPlan, commands: list[list[str]], run_dir: Path) -> None:
        for spec in plan.processes:
            if spec.is_node and spec.parameters:
                rundir.write_yaml(run_dir / 'params' / f'{spec.label}.yaml',
                                  ros_params.dump_parameters({'/**': spec.parameters}),
                                  header=f'parameters of {spec.label}, resolved by the launcher')
        rundir.write_yaml(run_dir / 'params.yaml',
                          ros_params.dump_parameters(plan.parameters_by_node()),
                          header=f"resolved parameters of every node of '{plan.name}' "
                                 f"(ROS 2 parameter file)")
        rundir.write_yaml(run_dir / 'launch_arguments.yaml', plan.arguments,
                          header='launch arguments (given or default); rerun with name:=value')
        rundir.write_yaml(run_dir / 'launch.yaml', {
            'profile': plan.name,
            'launch_file': None if plan.launch_file is None else str(plan.launch_file),
            'command_line': self.argv,
            'started_utc': dt.datetime.now(dt.timezone.utc).isoformat(timespec='seconds'),
            'composed': self.composed,
            'record': plan.record,
            'duration_s': plan.duration,
            'processes': [self._describe(spec, cmd) for spec, cmd in zip(plan.processes,
                                                                         commands, strict=False)],
        })
        rundir.write_yaml(run_dir / 'provenance.yaml', rundir.provenance())

    @staticmethod
    def _describe(spec: ProcessSpec, command: list[str]) -> dict[str, Any]:
        item: dict[str, Any] = {'label': spec.label, 'command': command}
        if spec.is_node:
            item.update({'node': spec.fully_qualified_name, 'package': spec.package,
                         'executable': spec.executable, 'module': spec.module,
                         'parameter_files': spec.parameter_files,
                         'remappings': [list(r) for r in spec.remappings]})
        if spec.respawn:
            item['respawn'] = True
        return item

    def run(self) -> int:
        """Run the launch; 0 when every process ended cleanly, 1 otherwise; 128 + the signal
        (130 Ctrl-C/SIGINT, 143 SIGTERM, 129 SIGHUP) when a signal stopped it and every process
        stopped cleanly."""
        plan = self.plan()  # problems are reported before anything is created
        # a second graph on this domain (another demo's /sim or /fsm): refused, nothing created
        check_domain_free((p.fully_qualified_name for p in plan.processes if p.is_node),
                          self.graph_check)
        run_dir = rundir.create_run_dir(self.name, self.run_dir_option, self.runs_root)
        self.run_dir = run_dir
        if plan.record:
            plan.processes[0].parameters.update(recorder_outputs(run_dir / 'bag'))
        handlers = configure_launch_logger(run_dir / 'logs' / 'launch.log')
        try:
            processes = plan.processes
            try:
                commands = self.commands(plan, run_dir)
                self._write_run_dir(plan, commands, run_dir)
            except OSError as exc:   # before anything starts: a run that cannot be redone
                msg = (f'cannot write the run directory {run_dir} ({exc.strerror or exc}): free '
                       'space on its disk or give --run-dir on another one.')
                raise LaunchError(msg) from None
            logger.info("run directory: %s", run_dir)
            if self.composed:
                from mindgrasp_launch.composed import compose

                processes, commands = compose(processes, commands, run_dir)
            env = dict(os.environ)
            env['MINDGRASP_RUN_DIR'] = str(run_dir)
            supervisor = Supervisor(list(zip(processes, commands, strict=True)), run_dir / 'logs',
                                    sigint_timeout=self.sigint_timeout,
                                    sigterm_timeout=self.sigterm_timeout,
                                    duration=plan.duration, printer=self.printer, env=env)
            self.results = supervisor.run()
            self.stop_reason = supervisor.stop_reason
            # a process that died is a failure even when respawn brought it back: the run lost
            # that node's work for a while (a controller, a recorder), so it is not clean
            code = 0 if all(r.clean and not r.restarts for r in self.results) else 1
            interrupted = self.interrupted_by = supervisor.interrupted_by
            if interrupted is not None and code == 0:
                code = 128 + int(interrupted)   # as a shell reports it: 130 SIGINT, 143 SIGTERM
            self._write_summary(run_dir, code)
            write_run_report(run_dir, self.name)
            if interrupted is not None and code != 1:
                logger.warning('the launch was interrupted (%s) before its end; every process '
                               'stopped cleanly, what ran is recorded. Run directory: %s',
                               signal.Signals(interrupted).name, run_dir)
            elif code == 0:
                logger.info('every process ended cleanly; run directory: %s', run_dir)
            else:
                bad = ', '.join(
                    f'{r.label} ({r.how}, '
                    f'{"no exit code" if r.returncode is None else r.returncode}'
                    + (f'; died and was respawned {r.restarts} time(s)' if r.restarts else '')
                    + ')' for r in self.results if not r.clean or r.restarts)
                logger.error('the launch ended with failures: %s. Logs: %s', bad,
                             run_dir / 'logs')
            return code
        finally:
            remove_handlers(handlers)

    def _write_summary(self, run_dir: Path, code: int) -> None:
        summary = {
            'ended_utc': dt.datetime.now(dt.timezone.utc).isoformat(timespec='seconds'),
            'exit_code': code,
            'clean': code == 0,
            # the signal that stopped the launch before its end (exit code 128 + its number)
            'interrupted_by': (None if self.interrupted_by is None
                               else signal.Signals(self.interrupted_by).name),
            'stop_reason': self.stop_reason,
            # clean: the process ended cleanly and never died (a respawned process is not clean)
            'processes': [{'label': r.label, 'returncode': r.returncode,
                           'clean': r.clean and not r.restarts, 'how': r.how,
                           'restarts': r.restarts, 'pid': r.pid}
                          for r in self.results],
        }
        # a full disk costs only this file: a copy goes to a fallback folder the log names
        files = DeferredWriter(run_dir)
        lines = files.write(run_dir, 'run summary',
                            lambda folder: rundir.write_yaml(folder / 'summary.yaml', summary))
        for line in lines:
            logger.error(line)
