"""The experiment engine: a launch profile's own nodes, composed in one process on simulated time.

:func:`lockstep_components` resolves a launch (profile or file, with its arguments) into the
nodes to compose, as ``mindgrasp launch`` would start them, with the lock-step traits each node
class declares (:class:`~mindgrasp_ros.node_traits.NodeTraits`): LSL runs on wall time, so the
virtual amplifier publishes ``/eeg/raw`` itself (``output:=ros``) and the LSL acquisition node is
left out. :func:`run_trial` builds a fresh :class:`~mindgrasp_ros.composition.LockstepRunner`
graph for one trial (the trial manager, the node whose traits say so, told to run just that
trial; every parameter a node's traits name as seeded set to a seed derived from
``(seed, trial)``), advances the clock in
steps of ``step_s`` until the trial manager is done, and returns the trial manager's record. A
fresh graph per trial makes a trial's record depend on ``(seed, trial)`` only, whichever worker
runs it.

A node that raises inside the loop fails the trial with the node's name and error
(``failure='node_error'``); the experiment goes on with the next trial.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_bringup.launch_system import LaunchError
from mindgrasp_bringup.launch_system.lockstep import (
    LockstepComponent,
    run_lockstep,
    set_log_level,
)
from mindgrasp_bringup.launch_system.lockstep import (
    lockstep_components as _lockstep_components,
)
from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.records import TrialRecord
from mindgrasp_ros.composition import load_node_class
from mindgrasp_ros.node_traits import NodeTraits, traits_of

__all__ = ['LockstepComponent', 'TrialRun', 'is_trial_manager', 'lockstep_components',
           'run_lockstep', 'run_trial', 'trial_seed']


def _traits(component: LockstepComponent) -> NodeTraits:
    return traits_of(load_node_class(component.module))


def is_trial_manager(component: LockstepComponent) -> bool:
    """Whether the component's node class is a trial manager (its traits say so)."""
    return _traits(component).trial_manager


def lockstep_components(launch: str | Path, arguments: Sequence[str] | Mapping[str, Any],
                        params_dir: Path, *, overlay: str | Path | None = None,
                        log: Any = None) -> list[LockstepComponent]:
    """:func:`mindgrasp_bringup.launch_system.lockstep.lockstep_components` without the
    recorder (an experiment writes records, not a bag per trial), raising
    :class:`ExperimentError` with the launcher's message."""
    try:
        return _lockstep_components(launch, arguments, params_dir, overlay=overlay, log=log)
    except LaunchError as exc:
        raise ExperimentError(str(exc)) from None


def trial_seed(seed: int, trial: int) -> int:
    """The seed of the nodes in ``trial`` (31 bits), from the experiment seed and the trial."""
    return (int(seed) * 1_000_003 + int(trial)) % (2 ** 31 - 1)


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

    Exactly one component must be a trial manager (:func:`is_trial_manager`); it is told
    ``first_trial:=trial n_trials:=1``.
    """
    from mindgrasp_ros.composition import LockstepRunner, NodeCallbackError
    from mindgrasp_ros.node_main import error_text, is_done

    managers = [c for c in components if is_trial_manager(c)]
    if len(managers) != 1:
        msg = ('A lock-step experiment needs exactly one trial manager (a node whose class '
               f'declares NodeTraits(trial_manager=True)); this launch has {len(managers)}.')
        raise ExperimentError(msg)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    set_log_level(log_level)
    runner = LockstepRunner(start_time_s=0.0)   # nodes start with the clock at 0: no jump
    manager = None
    record: TrialRecord | None = None
    build_s = 0.0
    try:
        for comp in components:
            extra: list[str] = []
            traits = _traits(comp)
            if traits.trial_manager:
                extra += ['-p', f'first_trial:={trial}', '-p', 'n_trials:=1', '-p',
                          "records_dir:=''"]
            for name in traits.seed_parameters:
                extra += ['-p', f'{name}:={trial_seed(seed, trial)}']
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
            if traits.trial_manager:
                manager = node
        build_s = time.perf_counter() - wall0
        if record is None:
            assert manager is not None
            try:
                limit = runner.time_s + max_sim_s
                while not is_done(manager) and runner.time_s < limit:
                    runner.step(step_s)
                if manager.records:
                    record = manager.records[0]
                elif error_text(manager) is not None:
                    record = _failed_record(trial, managers[0].parameters, 'node_error',
                                            f'trial_manager: {error_text(manager)}')
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
        sim_s = runner.time_s
        node_s = dict(runner.node_time)
        node_s['(executor)'] = runner.collect_time
    finally:
        runner.close()
    return TrialRun(record=record, sim_s=sim_s, wall_s=time.perf_counter() - wall0,
                    cpu_s=time.process_time() - cpu0, node_s=node_s, build_s=build_s)


