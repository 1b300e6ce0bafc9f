"""The experiment engine: a launch profile's own nodes, composed in one process on simulated time.

:func:`lockstep_components` resolves a launch (profile or file, with its arguments) into the
nodes to compose, as ``mindgrasp launch`` would start them, with the lock-step substitutions of
:data:`LOCKSTEP_NODES`: LSL runs on wall time, so the virtual amplifier publishes ``/eeg/raw``
itself (``output:=ros``) and the LSL acquisition node is left out. :func:`run_trial` builds a
fresh :class:`~mindgrasp_ros.composition.LockstepRunner` graph for one trial (the trial manager
told to run just that trial, every seed derived from ``(seed, trial)``), advances the clock in
steps of ``step_s`` until the trial manager is done, and returns the trial manager's record. A
fresh graph per trial makes a trial's record depend on ``(seed, trial)`` only, whichever worker
runs it.

A node that raises inside the loop fails the trial with the node's name and error
(``failure='node_error'``); the experiment goes on with the next trial.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.records import TrialRecord

__all__ = ['LOCKSTEP_NODES', 'LockstepComponent', 'TrialRun', 'lockstep_components',
           'run_lockstep', 'run_trial', 'trial_seed']

#: node module -> None (left out in lock-step, with the reason) or parameters set in lock-step
LOCKSTEP_NODES: dict[str, str | dict[str, Any]] = {
    'mindgrasp_eeg.acquisition_node': 'LSL runs on wall time; the virtual amplifier publishes '
                                      '/eeg/raw itself in lock-step',
    'mindgrasp_bringup.bag.recorder_node': 'lock-step runs write records, not bags',
    'mindgrasp_eeg.virtual_amp_node': {'output': 'ros'},
}
#: nodes whose ``seed`` parameter is set per trial
SEEDED_NODES = ('mindgrasp_eeg.virtual_amp_node', 'mindgrasp_experiments.oracle_subject_node',
                'mindgrasp_sim.sim_node')
TRIAL_MANAGER = 'mindgrasp_experiments.trial_manager_node'


@dataclass
class LockstepComponent:
    """A node of the composed graph: its label, module and ROS arguments."""

    label: str
    module: str
    ros_args: list[str]
    parameters: dict[str, Any] = field(default_factory=dict)


def trial_seed(seed: int, trial: int) -> int:
    """The seed of the nodes in ``trial`` (31 bits), from the experiment seed and the trial."""
    return (int(seed) * 1_000_003 + int(trial)) % (2 ** 31 - 1)


def lockstep_components(launch: str | Path, arguments: Sequence[str] | Mapping[str, Any],
                        params_dir: Path, *, overlay: str | Path | None = None,
                        log: Any = None) -> list[LockstepComponent]:
    """The nodes of ``launch`` (a profile or a launch file) to compose in lock-step.

    ``overlay``: a user's launch file whose nodes replace the profile's nodes of the same name
    (another classifier, another controller) or are added. Parameter files of every node are
    written to ``params_dir``. Raises :class:`ExperimentError` with the launcher's message.
    """
    from mindgrasp_bringup.launch_system import LaunchError, LaunchService, rundir
    from mindgrasp_bringup.launch_system import params as ros_params

    args = dict(arguments) if isinstance(arguments, Mapping) else \
        dict(a.split(':=', 1) for a in arguments)
    args['record'] = 'false'
    try:
        service = LaunchService(launch, args)
        plan = service.plan()
        processes = list(plan.processes)
        if overlay is not None:
            user = LaunchService(overlay, {k: v for k, v in args.items()
                                           if k in {a.name for a in LaunchService(
                                               overlay).declared_arguments()}} | {
                                               'record': 'false'})
            extra = user.plan().processes
            names = {p.label for p in extra}
            processes = [p for p in processes if p.label not in names] + list(extra)
    except LaunchError as exc:
        raise ExperimentError(str(exc)) from None
    out = []
    for spec in processes:
        if not spec.is_node:
            msg = (f"'{spec.label}' is not a node ({spec.program[:1]}); lock-step composes "
                   'Python node modules only: leave it out of the launch file.')
            raise ExperimentError(msg)
        if spec.module is None:
            msg = (f"'{spec.label}' is not a Python node module, so it cannot be composed in "
                   'lock-step; give it as Node(package=..., executable=...) of a Python '
                   'package.')
            raise ExperimentError(msg)
        rule = LOCKSTEP_NODES.get(spec.module)
        if isinstance(rule, str):
            if log is not None:
                log(f"lock-step: '{spec.label}' left out ({rule}).")
            continue
        params = dict(spec.parameters)
        if isinstance(rule, dict):
            params.update(rule)
        path = params_dir / f'{spec.label}.yaml'
        rundir.write_yaml(path, ros_params.dump_parameters({'/**': params}),
                          header=f'parameters of {spec.label} (lock-step)')
        if spec.arguments:
            msg = (f"'{spec.label}' has command-line arguments {spec.arguments}; composed nodes "
                   'take ROS arguments only: give them as parameters.')
            raise ExperimentError(msg)
        cmd = spec.command(path)
        ros_args = cmd[cmd.index('--ros-args') + 1:]
        out.append(LockstepComponent(spec.label, spec.module, ros_args, params))
    return out


@dataclass
class TrialRun:
    """One trial's record and what it cost."""

    record: TrialRecord
    sim_s: float             # simulated seconds, set-up included
    wall_s: float
    cpu_s: float             # CPU seconds of this process
    node_s: dict[str, float] = field(default_factory=dict)   # wall s in each node's callbacks
    build_s: float = 0.0     # wall s to construct the graph


def _failed_record(trial: int, manager_params: Mapping[str, Any], failure: str,
                   reason: str) -> TrialRecord:
    return TrialRecord(trial=trial, protocol=str(manager_params.get('protocol', '')),
                       subject=str(manager_params.get('subject', '')),
                       seed=int(manager_params.get('seed', 0)), failure=failure, reason=reason)


def run_trial(components: Sequence[LockstepComponent], trial: int, *, seed: int,
              step_s: float = 0.02, max_sim_s: float = 7200.0, log_level: str = 'info'
              ) -> TrialRun:
    """Run ``trial`` in a fresh lock-step graph of ``components``; returns its record.

    The trial manager (``mindgrasp_experiments.trial_manager_node``) must be among the
    components; it is told ``first_trial:=trial n_trials:=1``.
    """
    from mindgrasp_ros.composition import LockstepRunner, NodeCallbackError, load_node_class

    managers = [c for c in components if c.module == TRIAL_MANAGER]
    if len(managers) != 1:
        msg = (f'A lock-step experiment needs exactly one trial manager ({TRIAL_MANAGER}); '
               f'this launch has {len(managers)}.')
        raise ExperimentError(msg)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    _set_log_level(log_level)
    runner = LockstepRunner(start_time_s=1.0)
    manager = None
    record: TrialRecord | None = None
    build_s = 0.0
    try:
        for comp in components:
            extra: list[str] = []
            if comp.module == TRIAL_MANAGER:
                extra += ['-p', f'first_trial:={trial}', '-p', 'n_trials:=1', '-p',
                          "records_dir:=''"]
            elif comp.module in SEEDED_NODES:
                extra += ['-p', f'seed:={trial_seed(seed, trial)}']
            try:
                node = runner.add(load_node_class(comp.module),
                                  ros_args=[*comp.ros_args, *extra])
            except NodeCallbackError as exc:
                record = _failed_record(trial, managers[0].parameters, 'node_error',
                                        f'{exc.node}: {type(exc.error).__name__}: {exc.error}')
                break
            except Exception as exc:
                record = _failed_record(trial, managers[0].parameters, 'node_error',
                                        f'{comp.label}: {type(exc).__name__}: {exc}')
                break
            if comp.module == TRIAL_MANAGER:
                manager = node
        build_s = time.perf_counter() - wall0
        if record is None:
            assert manager is not None
            try:
                limit = runner.time_s + max_sim_s
                while not manager.done and runner.time_s < limit:
                    runner.step(step_s)
                if manager.records:
                    record = manager.records[0]
                elif manager.error is not None:
                    record = _failed_record(trial, managers[0].parameters, 'node_error',
                                            f'trial_manager: {manager.error}')
                else:
                    manager.finish_interrupted(f'no end after {max_sim_s:g} simulated s',
                                               'timeout')
                    record = manager.records[0] if manager.records else _failed_record(
                        trial, managers[0].parameters, 'timeout', 'no trial started')
            except NodeCallbackError as exc:
                reason = f'{exc.node}: {type(exc.error).__name__}: {exc.error}'
                manager.finish_interrupted(reason, 'node_error')
                record = manager.records[-1] if manager.records else _failed_record(
                    trial, managers[0].parameters, 'node_error', reason)
        sim_s = runner.time_s - 1.0
        node_s = dict(runner.node_time)
        node_s['(executor)'] = runner.collect_time
    finally:
        runner.close()
    return TrialRun(record=record, sim_s=sim_s, wall_s=time.perf_counter() - wall0,
                    cpu_s=time.process_time() - cpu0, node_s=node_s, build_s=build_s)


def _set_log_level(level: str) -> None:
    """Every node logger of this process at ``level`` (as ``--ros-args --log-level``)."""
    from mindgrasp_ros import using_real_rclpy

    if using_real_rclpy():  # pragma: no cover - needs a ROS 2 installation
        from rclpy.logging import LoggingSeverity, set_logger_level

        set_logger_level('', getattr(LoggingSeverity, level.upper()))
        return
    from mindgrasp_ros.runtime.logging import set_logger_level

    set_logger_level('', level)


def run_lockstep(components: Sequence[LockstepComponent], *, step_s: float = 0.02,
                 duration_s: float = 0.0, log: Any = print) -> int:
    """``mindgrasp launch <profile> --lockstep``: compose every node, step until a node is done
    (``done``), ``duration_s`` simulated seconds (> 0) or Ctrl-C. Returns 1 when a node raised
    or reports an ``error``, else 0."""
    from mindgrasp_ros.composition import LockstepRunner, NodeCallbackError, load_node_class

    runner = LockstepRunner(start_time_s=1.0)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    code = 0
    try:
        nodes = [runner.add(load_node_class(c.module), ros_args=c.ros_args) for c in components]
        end = runner.time_s + duration_s if duration_s > 0 else math.inf
        while runner.time_s < end and not any(getattr(n, 'done', False) for n in nodes):
            runner.step(step_s)
        errors = [(n.get_name(), n.error) for n in nodes if getattr(n, 'error', None)]
        for name, error in errors:
            log(f'[{name}] ERROR: {error}')
        code = 1 if errors else 0
    except NodeCallbackError as exc:
        log(f'[{exc.node}] ERROR: {type(exc.error).__name__}: {exc.error}')
        code = 1
    except KeyboardInterrupt:
        pass
    finally:
        wall = time.perf_counter() - wall0
        sim = runner.time_s - 1.0
        cpu = time.process_time() - cpu0
        log(f'lock-step: simulated {sim:.1f} s in {wall:.1f} s wall time (real-time factor '
            f'{sim / max(wall, 1e-9):.1f}, {cpu / max(sim, 1e-9):.3f} CPU s per simulated s).')
        runner.close()
    return code
