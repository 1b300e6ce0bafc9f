"""The experiment engine: a launch profile's own nodes, composed in one process on simulated time.

:func:`lockstep_components` resolves a launch (profile or file, with its arguments) into the
nodes to compose, as ``mindgrasp launch`` would start them, with the lock-step traits each node
class declares (:class:`~mindgrasp_ros.node_traits.NodeTraits`): LSL runs on wall time, so the
virtual amplifier publishes ``/eeg/raw`` itself (``output:=ros``) and the LSL acquisition node is
left out. :func:`run_trial` runs one trial as a fresh graph of the one graph host
(:class:`~mindgrasp_ros.graph.host.GraphRunner` under the ``Lockstep`` scheduler), each node
given :func:`trial_parameters` (the trial manager, the node whose traits say so, told to run
just that trial; every parameter a node's traits name as seeded set to a seed derived from
``(seed, trial)``), advances the clock in steps of ``step_s`` until the trial manager is done,
and returns the trial manager's record. A fresh graph per trial makes a trial's record depend
on ``(seed, trial)`` only, whichever worker runs it.

A node that raises inside the loop fails the trial with the node's name and error
(``failure='node_error'``); the experiment goes on with the next trial.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.records import TrialRecord
from mindgrasp_launch import LaunchError
from mindgrasp_launch.lockstep import (
    lockstep_components as _lockstep_components,
)
from mindgrasp_launch.lockstep import run_lockstep, set_log_level
from mindgrasp_ros.graph.spec import NodeSpec
from mindgrasp_ros.node_traits import NodeTraits

__all__ = ['NodeSpec', 'TrialRun', 'is_trial_manager', 'lockstep_components', 'run_lockstep',
           'run_trial', 'trial_parameters', 'trial_seed']


def is_trial_manager(component: NodeSpec) -> bool:
    """Whether the component's node class is a trial manager (its traits say so)."""
    return component.traits.trial_manager


def lockstep_components(launch: str | Path, arguments: Sequence[str] | Mapping[str, Any],
                        params_dir: Path, *, overlay: str | Path | None = None,
                        log: Any = None) -> list[NodeSpec]:
    """:func:`mindgrasp_launch.lockstep.lockstep_components` without the
    recorder (an experiment writes records, not a bag per trial), raising
    :class:`ExperimentError` with the launcher's message."""
    try:
        return _lockstep_components(launch, arguments, params_dir, overlay=overlay, log=log)
    except LaunchError as exc:
        raise ExperimentError(str(exc)) from None


def trial_seed(seed: int, trial: int) -> int:
    """The seed of the nodes in ``trial`` (31 bits), from the experiment seed and the trial."""
    return (int(seed) * 1_000_003 + int(trial)) % (2 ** 31 - 1)


def trial_parameters(traits: NodeTraits, trial: int, seed: int) -> dict[str, Any]:
    """What a node of ``trial`` is given on top of its parameters: the trial's seed in every
    parameter its traits name as seeded; the trial manager runs just that trial, writing no
    files (the engine keeps its record)."""
    params: dict[str, Any] = dict.fromkeys(traits.seed_parameters, trial_seed(seed, trial))
    if traits.trial_manager:
        params.update(first_trial=trial, n_trials=1, records_dir='')
    return params


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


def _outcome(manager: Any, info: Mapping[str, Any], trial: int, max_sim_s: float) -> TrialRecord:
    """The trial manager's record once the loop ended (its failure, or a timeout)."""
    from mindgrasp_ros.node_main import error_text

    if manager.records:
        return manager.records[0]
    if error_text(manager) is not None:
        return _failed_record(trial, info, 'node_error', f'trial_manager: {error_text(manager)}')
    manager.finish_interrupted(f'no end after {max_sim_s:g} simulated s', 'timeout')
    return manager.records[0] if manager.records else _failed_record(
        trial, info, 'timeout', 'no trial started')


def run_trial(components: Sequence[NodeSpec], trial: int, *, seed: int,
              step_s: float = 0.02, max_sim_s: float = 7200.0, log_level: str = 'info'
              ) -> TrialRun:
    """Run ``trial`` in a fresh lock-step graph of ``components``; returns its record.

    Exactly one component must be a trial manager (:func:`is_trial_manager`); every node gets
    :func:`trial_parameters`. A node that raises fails the trial (``failure='node_error'``).
    """
    from mindgrasp_ros.graph import NodeCallbackError
    from mindgrasp_ros.graph.host import GraphRunner, Lockstep
    from mindgrasp_ros.node_main import is_done

    traits = [c.traits for c in components]
    managers = [c for c, t in zip(components, traits, strict=True) if t.trial_manager]
    if len(managers) != 1:
        msg = ('A lock-step experiment needs exactly one trial manager (a node whose class '
               f'declares NodeTraits(trial_manager=True)); this launch has {len(managers)}.')
        raise ExperimentError(msg)
    info = managers[0].parameters
    wall0, cpu0 = time.perf_counter(), time.process_time()
    set_log_level(log_level)
    scheduler = Lockstep(step_s)                # nodes start with the clock at 0: no jump
    manager = record = None
    with GraphRunner(scheduler) as graph:
        for comp, node_traits in zip(components, traits, strict=True):
            try:
                node = graph.add(comp.with_parameters(trial_parameters(node_traits, trial, seed)))
            except NodeCallbackError as exc:
                record = _failed_record(trial, info, 'node_error',
                                        f'{exc.node}: {type(exc.error).__name__}: {exc.error}')
                break
            except Exception as exc:    # each node package raises its own error type
                record = _failed_record(trial, info, 'node_error',
                                        f'{comp.label}: {type(exc).__name__}: {exc}')
                break
            manager = node if node_traits.trial_manager else manager
        build_s = time.perf_counter() - wall0
        if record is None:
            try:
                graph.spin_until(lambda: is_done(manager), max_sim_s)
                record = _outcome(manager, info, trial, max_sim_s)
            except NodeCallbackError as exc:
                reason = f'{exc.node}: {type(exc.error).__name__}: {exc.error}'
                manager.finish_interrupted(reason, 'node_error')
                record = manager.records[-1] if manager.records else _failed_record(
                    trial, info, 'node_error', reason)
        sim_s = scheduler.time_s
        node_s = {**scheduler.runner.node_time, '(executor)': scheduler.runner.collect_time}
    return TrialRun(record=record, sim_s=sim_s, wall_s=time.perf_counter() - wall0,
                    cpu_s=time.process_time() - cpu0, node_s=node_s, build_s=build_s)
