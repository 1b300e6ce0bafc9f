"""An experiment as an object: configuration in, results out, as MOABB's evaluations.

    from mindgrasp_experiments.experiment import Experiment

    results = Experiment('set_locations', subject='eegmmidb:1', trials=18, accuracy=1.0,
                         workers=2, trial_timeout_s=240).run('runs/s001')
    results.summary['correct_and_successful_rate'], results.summary['wrong_grasp_rate']

``mindgrasp experiment set-locations | random-locations`` parse their arguments into an
:class:`Experiment` and print its :class:`Results`; ``mindgrasp experiment sweep`` runs one
:class:`Experiment` per point. So every command writes the same run directory (records.csv,
records.parquet, summary.json, report.md, plots), under the names of
:func:`~mindgrasp_experiments.summary.summarise`, and ``--json`` prints
:meth:`Results.figures` (or, for a sweep, a list of points under the same names).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.engine import TrialRun
from mindgrasp_experiments.records import TrialRecord
from mindgrasp_ros.graph.spec import NodeSpec

__all__ = ['Experiment', 'Results']


def _stderr(line: str) -> None:
    print(line, file=sys.stderr)


@dataclasses.dataclass(frozen=True)
class Experiment:
    """One protocol's trials with one subject, each trial a fresh lock-step graph of the
    experiment launch profile's nodes seeded from ``(seed, trial)``.

    Parameters
    ----------
    protocol : str
        ``'set_locations'`` or ``'random_locations'``.
    subject : str
        ``noise``, ``virtual``, ``oracle``, ``autonomous`` (random locations),
        ``eegmmidb:<n>`` or a replay subject file (real EEG), ``virtual:FILE.yaml`` (the
        virtual subject on a head fitted by ``mindgrasp eeg fit-virtual``, calibrated on it
        first: :mod:`~mindgrasp_experiments.fitted_subject`).
    trials, seed, workers : int
        Trials 1..``trials``; the same seed gives the same records whatever ``workers``.
    accuracy : float | None
        The pursuing subject's probability of imagining the right class (set locations).
    params : Mapping[str, Any]
        ``{'node.parameter': value}`` set for every trial (checked against the profile's
        parameter files and the node classes' ranges before any trial runs).
    robot, realism, launch : str | None
        Robot description, realism profile, a launch file whose nodes replace or join the
        profile's (``None``: the profile's defaults).
    step_s, trial_timeout_s, stall_timeout_s : float
        Lock-step clock step, trial timeout and controller stall timeout (simulated s).
    ray : str | None
        Run the trials as Ray tasks at this address (``auto``: a local instance).
    """

    protocol: str
    subject: str = 'virtual'
    trials: int = 20
    seed: int = 0
    workers: int = 1
    accuracy: float | None = None
    params: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    robot: str | None = None
    realism: str | None = None
    launch: str | None = None
    step_s: float = 0.02
    trial_timeout_s: float = 600.0
    stall_timeout_s: float = 120.0
    ray: str | None = None

    def launch_arguments(self, subject_args: Mapping[str, str]) -> dict[str, str]:
        """The experiment profile's launch arguments, given the subject's
        (:func:`~mindgrasp_experiments.subject_launch.subject_launch_args`)."""
        args = {**subject_args, 'protocol': self.protocol, 'seed': str(self.seed), 'trials': '1'}
        for name in ('accuracy', 'realism', 'robot'):
            if getattr(self, name) is not None:
                args[name] = str(getattr(self, name))
        return args

    def components(self, run_dir: Path, subject_args: Mapping[str, str],
                   log: Callable[[str], None] = print) -> list[NodeSpec]:
        """The nodes of one trial, their parameter files written to ``run_dir/params``, with
        the trial manager's timeouts and :attr:`params` applied."""
        from mindgrasp_experiments.engine import is_trial_manager, lockstep_components
        from mindgrasp_experiments.sweep import apply_params, check_params

        comps = lockstep_components('experiment', self.launch_arguments(subject_args),
                                    run_dir / 'params', overlay=self.launch, log=log)
        timeouts = {'stall_timeout': float(self.stall_timeout_s),
                    'trial_timeout': float(self.trial_timeout_s)}
        if subject_args.get('subject', self.subject) != self.subject:
            # a replay or fitted subject runs as the virtual one: the records name the person
            timeouts['subject'] = str(self.subject)
        comps = [c.with_parameters(timeouts) if is_trial_manager(c) else c for c in comps]
        from mindgrasp_experiments.fitted_subject import head_params

        # a fitted subject's head first, so that --param can still override a setting of it
        params = {**head_params(self.subject), **self.params}
        typed = check_params([(*full.split('.', 1), [value]) for full, value in params.items()],
                             comps)
        return apply_params(comps, {f'{node}.{name}': values[0]
                                    for node, name, values in typed}, run_dir / 'params')

    def run(self, run_dir: str | Path | None = None, *,
            subject_args: Mapping[str, str] | None = None, command: str | None = None,
            log: Callable[[str], None] = print, warn: Callable[[str], None] = _stderr,
            on_start: Callable[[], None] | None = None,
            on_trial: Callable[[Sequence[TrialRun]], None] | None = None) -> Results:
        """Run the trials; write the run directory as they finish; return the results.

        ``run_dir``: default ``runs/<UTC time>_<protocol>/``. ``subject_args``: the subject's
        launch arguments when already made (a sweep calibrates each replay subject once).
        ``log`` gets the launch's lines, ``warn`` one line per file that could not be written
        (the records stay in a fallback copy); ``on_start`` is called once the graph is checked,
        before the first trial, and ``on_trial`` with the runs so far after each trial.
        Ctrl-C ends the run early: the finished trials are written and ``interrupted`` is set.
        Raises :class:`ExperimentError` (one sentence with the fix) before any trial runs.
        """
        from mindgrasp_common.safe_files import DeferredWriter
        from mindgrasp_eeg import EEGError
        from mindgrasp_experiments.records import write_records
        from mindgrasp_experiments.report import write_run
        from mindgrasp_experiments.subject_launch import subject_launch_args
        from mindgrasp_experiments.summary import calibration_accuracy_of, summarise
        from mindgrasp_experiments.workers import run_trials
        from mindgrasp_launch import LaunchError
        from mindgrasp_launch.rundir import create_run_dir

        try:
            out = create_run_dir(self.protocol, run_dir, option='--out')
            if subject_args is None:
                subject_args = subject_launch_args(self.subject, out)
        except (LaunchError, EEGError) as exc:
            raise ExperimentError(str(exc)) from None
        components = self.components(out, subject_args, log)
        gate = _model_gate(subject_args.get('model', ''))
        if gate and gate.get('verdict') != 'ready':
            # experiments run anyway (the report puts the prediction beside the outcome)
            warn(f"the calibration gate did not call this subject ready "
                 f"({gate.get('verdict')}: {gate.get('reason', '')}); running anyway, recorded "
                 'in summary.json.')
        if on_start is not None:
            on_start()
        runs: list[TrialRun] = []
        interrupted = False
        wall0, cpu0 = time.perf_counter(), time.process_time()
        # on disk as they finish: nothing is lost on a crash; a full disk costs one line, the
        # records stay in memory and in a fallback copy until the run directory takes them
        files = DeferredWriter(out)
        try:
            for trial_run in run_trials(components, list(range(1, self.trials + 1)),
                                        seed=self.seed, workers=self.workers,
                                        step_s=self.step_s, ray=self.ray):
                runs.append(trial_run)
                done = [r.record for r in runs]
                for line in files.write(out, 'trial records',
                                        lambda folder, done=done: write_records(done, folder)):
                    warn(line)
                if on_trial is not None:
                    on_trial(runs)
        except KeyboardInterrupt:
            interrupted = True
            warn(f'Interrupted: writing the {len(runs)} finished trial(s).')
        wall = time.perf_counter() - wall0
        sim = sum(r.sim_s for r in runs)
        # CPU of this process and of the worker processes (the parent mostly waits with workers)
        cpu = sum(r.cpu_s for r in runs) + (time.process_time() - cpu0 if self.workers > 1
                                             else 0.0)
        node_s: dict[str, float] = {}
        for r in runs:
            for name, sec in r.node_s.items():
                node_s[name] = node_s.get(name, 0.0) + sec
        records = sorted((r.record for r in runs), key=lambda rec: rec.trial)
        info = {
            'command': command or f'Experiment({self.protocol!r}, subject={self.subject!r})',
            'protocol': self.protocol, 'subject': self.subject, 'seed': self.seed,
            'accuracy': self.accuracy, 'params': dict(self.params), 'workers': self.workers,
            'ray': self.ray, 'realism': self.realism, 'robot': self.robot,
            'subject_args': dict(subject_args),     # the decoder (model) and EEG it ran with
            'trials_requested': self.trials, 'interrupted': interrupted,
            'launch_overlay': self.launch, 'step_s': self.step_s,
            'trial_timeout_s': self.trial_timeout_s, 'stall_timeout_s': self.stall_timeout_s,
            'sim_s': sim, 'wall_s': wall, 'cpu_s': cpu,
            'real_time_factor': sim / wall if wall > 0 else math.nan,
            'cpu_s_per_sim_s': cpu / sim if sim > 0 else math.nan,
            'build_s': sum(r.build_s for r in runs), 'node_s': node_s,
        }
        written: dict[str, dict] = {}
        calibration = calibration_accuracy_of(out)   # from the run's parameters
        lines = files.write(out, 'run report', lambda folder: written.update(
            doc=write_run(folder, records, info, calibration)))
        lines += files.close()
        for line in lines:
            warn(line)
        doc = written.get('doc') or {'summary': summarise(records, calibration)}
        return Results(run_dir=out, records=records, runs=runs, summary=doc['summary'],
                       info=info, interrupted=interrupted, unwritten=bool(files.pending))


def _model_gate(model: str) -> dict:
    """The calibration gate of a classifier model (its JSON ``gate``; {} without one)."""
    import json

    from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

    if not model:
        return {}
    try:
        path = resolve_path(model, 'mindgrasp_classifier', ('.json',))
        path = path if path.suffix == '.json' else path.with_name(path.name + '.json')
        gate = json.loads(path.read_text(encoding='utf-8')).get('gate')
    except (OSError, ValueError, AttributeError, ResourceNotFoundError):
        return {}
    return gate if isinstance(gate, dict) else {}


@dataclasses.dataclass
class Results:
    """What an :class:`Experiment` produced.

    Attributes
    ----------
    run_dir : Path
        The run directory (records, summary.json, report.md, plots, parameters).
    records : list[TrialRecord]
        One record per finished trial, by trial number.
    runs : list[TrialRun]
        Per trial: simulated s, wall s, CPU s, callback time per node.
    summary : dict
        :func:`~mindgrasp_experiments.summary.summarise` of the records (rates, Wilson 95 %
        intervals, times, information transfer rate, online and calibration accuracy).
    info : dict
        The configuration and the run's cost (wall s, real-time factor, CPU s per sim s).
    interrupted : bool
        Ctrl-C ended the run before its last trial.
    unwritten : bool
        Some file could not be written to the run directory (a fallback copy holds it).
    """

    run_dir: Path
    records: list[TrialRecord]
    runs: list[TrialRun]
    summary: dict
    info: dict
    interrupted: bool = False
    unwritten: bool = False

    def figures(self) -> dict[str, Any]:
        """The ``--json`` object: the summary with the run's paths and cost (JSON-safe)."""
        from mindgrasp_experiments.report import finite

        return finite({**self.summary, 'run_dir': str(self.run_dir),
                       'report_path': str(self.run_dir / 'report.md'),
                       'real_time_factor': self.info['real_time_factor'],
                       'cpu_s_per_sim_s': self.info['cpu_s_per_sim_s'],
                       'wall_s': self.info['wall_s'], 'sim_s': self.info['sim_s'],
                       'interrupted': self.interrupted})

