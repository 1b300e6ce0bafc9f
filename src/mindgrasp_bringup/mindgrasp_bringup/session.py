"""Calibration sessions: the phases of a plan run in order, each one recorded launch, with the
classifier retrained between phases, all kept in one subject folder.

The plan (a YAML file, ``plans/graded.yaml`` is the paper's graded protocol) and its phases are
:mod:`mindgrasp_bringup.session_plan`'s.

Which node of a phase's launch prompts its trials, is the participant's screen or the virtual
participant, the session asks the node classes (:class:`~mindgrasp_ros.node_traits.NodeTraits`
of the nodes the launch resolves to,
:func:`~mindgrasp_bringup.session_plan.phase_nodes`), so it names no node itself.

The subject folder::

    subjects/<ID>/<session>/
        session.yaml            the plan, and per phase: status, run folder, model, figures
        01_graz/                the phase's run directory (bag, logs, params, display PNGs)
        models/after_01_graz.json/.npz
        report.yaml, report.md  accuracy per phase, Trainer distances per trial, grasp figures

An interrupted phase is moved aside (``01_graz.interrupted-1``) and run again on resume; finished
phases are kept. Each phase runs the launcher in this process (``LaunchService``, or
``launch_lockstep``), so a launch that cannot start reaches the session as a
:class:`SessionError` with its one-line reason.

With the virtual subject and no display (``mindgrasp session calibrate``, or ``session run --amp
virtual --display off``) nothing waits on the wall clock, so each phase runs ``mindgrasp launch
--lockstep``: the same nodes and recorder composed on simulated time, as fast as the machine
allows; a phase's ``duration`` then counts simulated seconds. A real amplifier or a display keeps
real time.
"""

from __future__ import annotations

import contextlib
import csv
import datetime as dt
import math
import os
from collections.abc import Iterator, Mapping
from functools import partial
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_bringup.session_plan import (
    LABEL_TOPICS,
    Phase,
    Plan,
    SessionError,
    check_subject,
    named_nodes,
    phase_nodes,
    prompters,
)
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.topics import TASK_RESULT, TASK_TARGET

__all__ = ['Session']


def _now() -> str:
    return dt.datetime.now(dt.timezone.utc).strftime('%Y-%m-%dT%H:%M:%SZ')


class Session:
    """A subject's session folder and the loop over its plan's phases.

    Parameters
    ----------
    root : Path
        Folder of all subjects (``subjects``).
    subject : str
        Subject ID (a folder name).
    session : str
        Session name (a folder name), e.g. a date.
    launch_args : dict
        Launch arguments for every phase (``amp``, ``eeg_stream``, ``display``, ``seed``, ...).
    """

    def __init__(self, root: Path, subject: str, session: str,
                 launch_args: dict[str, str] | None = None) -> None:
        self.subject = check_subject(subject)
        self.session = check_subject(session)
        self.dir = Path(root) / self.subject / self.session
        self.launch_args = dict(launch_args or {})
        self.log_path = self.dir / 'session.yaml'

    # ------------------------------------------------------------------ log
    def read_log(self) -> dict[str, Any]:
        if not self.log_path.is_file():
            msg = (f'There is no session to resume in {self.dir} (no session.yaml); start one '
                   f'with mindgrasp session run --subject {self.subject} --plan graded.')
            raise SessionError(msg)
        return yaml.safe_load(self.log_path.read_text(encoding='utf-8'))

    def write_log(self, log: dict[str, Any]) -> None:
        tmp = self.log_path.with_suffix('.yaml.tmp')
        tmp.write_text(yaml.safe_dump(log, sort_keys=False), encoding='utf-8')
        os.replace(tmp, self.log_path)

    def start(self, plan: Plan) -> dict[str, Any]:
        """Create the folder and session.yaml for ``plan``; refuses an existing session."""
        if self.log_path.exists():
            msg = (f'The session {self.dir} exists already; continue it with mindgrasp session '
                   f'resume --subject {self.subject} --session {self.session}, or name a new '
                   'one with --session.')
            raise SessionError(msg)
        self.dir.mkdir(parents=True, exist_ok=True)
        log = {'subject': self.subject, 'session': self.session, 'plan': plan.source,
               'launch_args': self.launch_args, 'started': _now(),
               'phases': [{'name': p.name, 'kind': p.kind, 'status': 'pending'}
                          for p in plan.phases]}
        self.write_log(log)
        return log

    # ------------------------------------------------------------------ loop
    def run(self, plan: Plan, log: dict[str, Any], out=print) -> int:
        """Run every phase that is not done; returns 0 when all are done."""
        self.launch_args = {**log.get('launch_args', {}), **self.launch_args}
        model = ''
        for i, (phase, entry) in enumerate(zip(plan.phases, log['phases'], strict=True),
                                           start=1):
            if entry['status'] == 'done':
                model = entry.get('model', model) or model
                continue
            run_dir = self.dir / f'{i:02d}_{phase.name}'
            if run_dir.exists():   # an interrupted attempt: keep it, run the phase again
                k = 1
                while run_dir.with_name(f'{run_dir.name}.interrupted-{k}').exists():
                    k += 1
                run_dir.rename(run_dir.with_name(f'{run_dir.name}.interrupted-{k}'))
                out(f'Phase {phase.name}: the interrupted attempt is kept as '
                    f'{run_dir.name}.interrupted-{k}; running it again.')
            entry.update(status='running', run_dir=run_dir.name, started=_now(),
                         model_used=model)
            self.write_log(log)
            out(f'[{i}/{len(plan.phases)}] {phase.name}: {phase.kind}, {phase.trials} trials'
                f"{', feedback' if phase.feedback else ''}"
                f"{', model ' + model if model else ''} -> {run_dir}")
            scale = next((float(e['certainty_q75']) for e in reversed(log['phases'][:i - 1])
                          if e.get('model') == model and 'certainty_q75' in e), 0.0)
            args = self._phase_arguments(phase, run_dir, model)
            try:
                nodes = phase_nodes(phase.profile, args)
                code = self._launch(phase, run_dir, args, nodes, i, scale)
            except SessionError as err:   # the launch refused to start: nothing ran
                entry.update(status='failed', error=str(err), ended=_now())
                self.write_log(log)
                out(str(err))
                return 1
            entry.update(exit_code=code, ended=_now())
            code, note = _phase_outcome(
                run_dir, code, prompters(nodes, phase.kind))
            if note:
                entry['note'] = note
                out(f'Phase {phase.name}: {note}')
            if code != 0:
                entry['status'] = 'failed'
                self.write_log(log)
                out(f'Phase {phase.name} failed (exit code {code}); see {run_dir}/logs. Resume '
                    f'with mindgrasp session resume --subject {self.subject} --session '
                    f'{self.session}.')
                return 1
            entry.update(self._phase_figures(phase, run_dir))
            if phase.train:
                try:
                    entry.update(self._retrain(plan, log, i))
                except SessionError as err:
                    entry['status'] = 'failed'
                    entry['error'] = str(err)
                    self.write_log(log)
                    out(str(err))
                    return 1
                model = entry['model']
                out(f'  retrained on {entry["train_runs"]} run(s): cross-validated accuracy '
                    f'{100 * entry["cv_accuracy"]:.1f} % -> {model}')
            entry['status'] = 'done'
            self.write_log(log)
        log['ended'] = _now()
        self.write_log(log)
        report = self.write_report(log)
        out(report)
        return 0

    @property
    def lockstep(self) -> bool:
        """True when the phases run in lock-step: the virtual subject and no display, so
        nothing ties the session to the wall clock (an LSL amplifier streams in real time, and
        a person looks at the display)."""
        return (self.launch_args.get('amp', 'virtual') == 'virtual'
                and self.launch_args.get('display', 'off') == 'off')

    def _phase_arguments(self, phase: Phase, run_dir: Path, model: str) -> dict[str, str]:
        """The launch arguments of ``phase`` (``name:=value`` of ``mindgrasp launch``)."""
        args = {**self.launch_args}
        args.update(trials=str(phase.trials))
        display = args.get('display', 'off')
        if display != 'off':
            args.update(display_png_dir=str(run_dir / 'display'),
                        display_label=f'{phase.name} ({phase.kind})')
        if model:
            args['model'] = str(self.dir / model)
        if phase.kind == 'graz':
            args['feedback'] = 'true' if phase.feedback else 'false'
            if not phase.feedback:
                args.pop('model', None)
        if phase.kind == 'trainer':
            args.pop('feedback', None)
        if phase.kind == 'test':
            args.setdefault('targets', '')
            args.setdefault('subject', 'pursue')
            args.setdefault('live_view', 'false')   # the experimenter opts in (a port each)
        if phase.kind != 'test':
            args.pop('targets', None)
            if args.get('subject') == 'pursue':
                args.pop('subject')
        if phase.duration > 0:
            args['duration'] = str(phase.duration)
        args.update(phase.args)
        return args

    def _launch(self, phase: Phase, run_dir: Path, args: dict[str, str],
                nodes: Mapping[str, NodeTraits], index: int,
                certainty_scale: float = 0.0) -> int:
        """Run the phase's launch with ``args`` in this process, as ``mindgrasp launch`` runs it
        (its nodes in processes of their own, or composed in lock-step on simulated time);
        ``nodes``: its nodes (:func:`phase_nodes`). Returns the launch's exit code; a launch
        that cannot start raises :class:`SessionError` with its one-line reason, and Ctrl-C (or
        SIGTERM) that stopped it raises ``KeyboardInterrupt``."""
        from mindgrasp_launch import LaunchError, LaunchService
        from mindgrasp_launch.lockstep import launch_lockstep

        display = args.get('display', 'off')
        params_files = None
        params = {name: dict(values) for name, values in phase.params.items()}
        screens = named_nodes(nodes, lambda t: t.participant_screen)

        def default(names: list[str], parameter: str, value: Any) -> None:
            for name in names:
                params.setdefault(name, {}).setdefault(parameter, value)

        if display != 'off':
            # the participant display's PNG per prompt phase is the record of the screen; frames
            # on topics would fill the bag (1.8 MB each), and the prompter's own screen is unused
            default(screens, 'image_rate', 0.0)
            default(prompters(nodes, phase.kind, 'display_rate'), 'display_rate', 0.0)
        if certainty_scale > 0:
            default(screens, 'max_certainty', round(certainty_scale, 4))
        if self.lockstep:
            # nobody can look at the prompter's own screen: no frames to render and record
            default(prompters(nodes, phase.kind, 'display_rate'), 'display_rate', 0.0)
        if display == 'headless':  # frames for the record, not for a person: 10 Hz is plenty
            default(screens, 'rate', 10.0)
        # the first trial starts once EEG flows (the amplifier may start late on a busy machine)
        default(prompters(nodes, phase.kind, 'wait_for_eeg'), 'wait_for_eeg', True)
        for name in prompters(nodes, phase.kind, 'log_file'):
            params.setdefault(name, {})['log_file'] = str(run_dir / 'trainer_trials.csv')
        if params:
            pfile = self.dir / f'params_{index:02d}_{phase.name}.yaml'
            pfile.write_text(yaml.safe_dump({n: {'ros__parameters': v} for n, v in
                                             params.items()}, sort_keys=False), encoding='utf-8')
            params_files = str(pfile)
        # the command that redoes the phase, kept in its launch.yaml
        argv = ['mindgrasp', 'launch', phase.profile, *(['--lockstep'] if self.lockstep else []),
                '--run-dir', str(run_dir), *(f'{k}:={v}' for k, v in args.items())]
        with _environment('MINDGRASP_PARAMS_FILES', params_files):
            try:
                service = LaunchService(phase.profile, args, run_dir=run_dir, argv=argv)
                code = (launch_lockstep(service, log=partial(print, flush=True))
                        if self.lockstep else service.run())
            except LaunchError as exc:
                msg = f'Phase {phase.name} cannot launch {phase.profile}: {exc}'
                raise SessionError(msg) from None
        if (service.stop_reason or '').endswith(' received'):   # SIGINT, SIGTERM, SIGHUP
            raise KeyboardInterrupt
        return code

    # ------------------------------------------------------------------ figures
    def _retrain(self, plan: Plan, log: dict[str, Any], upto: int) -> dict[str, Any]:
        from mindgrasp_classifier.data import load_inputs
        from mindgrasp_classifier.errors import ClassifierError
        from mindgrasp_classifier.training import TrainingConfig, train

        t = plan.training
        runs = [self.dir / e['run_dir'] for p, e in zip(plan.phases[:upto], log['phases'],
                                                        strict=False)
                if p.train and e.get('run_dir')]
        name = log['phases'][upto - 1]['name']
        cfg = TrainingConfig(pipeline=t.get('pipeline', 'mdm'), tmin=float(t.get('tmin', 0.5)),
                             tmax=float(t.get('tmax', 2.5)), cv_folds=max(int(t.get('cv', 5)), 2),
                             min_trials=int(t.get('min_trials', 5)), seed=int(t.get('seed', 0)))
        try:
            recordings = load_inputs(bags=[str(r) for r in runs],
                                     prompt_topic=LABEL_TOPICS[t.get('labels', 'prompt')])
            model, report = train(recordings, cfg, cross_validate=True)
            path = model.save(self.dir / 'models' / f'after_{upto:02d}_{name}')
        except ClassifierError as err:
            msg = (f'The session stops after phase {name}: {err} Give the phase more trials in '
                   f"the plan (or lower training: min_trials), then resume.")
            raise SessionError(msg) from None
        return {'model': str(Path(path).relative_to(self.dir)),
                'cv_accuracy': float(report['accuracy']), 'train_runs': len(runs),
                # the feedback bar fills at the 75th percentile of the model's certainty
                'certainty_q75': max(float(c['q75']) for c in report['certainty'].values()),
                'trials_per_class': {str(k): int(v) for k, v in
                                     report.get('trials_per_class', {}).items()}}

    def _phase_figures(self, phase: Phase, run_dir: Path) -> dict[str, Any]:
        """Trainer distances per trial (CSV of the trainer node) or grasp results (bag)."""
        if phase.kind == 'trainer':
            path = run_dir / 'trainer_trials.csv'
            if not path.is_file():
                return {}
            with path.open(encoding='utf-8') as f:
                rows = list(csv.DictReader(f))
            dist = [float(r['mean_ee_distance_m']) for r in rows if r['mean_ee_distance_m']]
            return {'trainer_trials': [
                {'trial': int(r['trial']), 'class': r['class_name'],
                 'mean_ee_distance_m': float(r['mean_ee_distance_m'] or 'nan'),
                 'aborted': r['aborted']} for r in rows],
                'mean_ee_distance_m': sum(dist) / len(dist) if dist else math.nan}
        if phase.kind == 'test':
            results = _grasp_results(run_dir / 'bag')
            n = len(results)
            lifted = sum(1 for r in results if r['success'])
            correct = sum(1 for r in results if r['success'] and r['grasped'] == r['desired'])
            return {'grasps': results, 'n_grasp_trials': n, 'n_lifted': lifted,
                    'n_correct_grasps': correct}
        return {}

    def heldout_accuracy(self, log: dict[str, Any], phase: str = 'heldout') -> dict[str, Any]:
        """Score the last trained model on the run of ``phase`` (not trained on), and save a
        copy whose probabilities are calibrated on that run (the session's final model).

        Cross-validation inside the training run cannot see the drift between runs, so the
        temperature fitted there leaves the decoder far too sure of itself on the next run (a
        fitted virtual head: T = 0.48, expected calibration error 0.63 on the held-out run).
        The shared control's evidence thresholds mean something only when the certainty does,
        so the temperature is fitted again on the held-out run's windows, decoded as online
        (re-centred on the run, as the classifier's default ``recenter: adaptive`` does). The
        accuracy is the argmax's and does not change with the temperature; the calibration
        figures of the copy are measured on the run they were fitted on (``fitted_on``); those
        in ``unseen`` on windows the temperature was not fitted on (two folds: fitted on one
        half of the run, measured on the other, averaged), which is what the command prints.
        The temperature minimises the log loss (NLL); the expected calibration error, a binned
        gap between confidence and accuracy, can still rise when few windows fall in a bin.

        Returns ``heldout_accuracy``, ``heldout_trials``, ``model_path`` (the calibrated copy,
        relative to the session folder), ``trained_model_path`` and ``temperature``:
        ``{'before': T, 'after': T', 'ece_before', 'ece_after', 'nll_before', 'nll_after',
        'fitted_on': run, 'unseen': {'ece_before', 'ece_after', 'nll_before', 'nll_after'}}``
        (ECE and NLL in nats per window of the held-out run).
        """
        from mindgrasp_classifier.calibration import (
            calibration_summary,
            fit_temperature,
            label_positions,
        )
        from mindgrasp_classifier.data import load_inputs
        from mindgrasp_classifier.errors import ClassifierError
        from mindgrasp_classifier.model import MiModel
        from mindgrasp_classifier.training import evaluate, evaluate_windows

        entry = next(e for e in log['phases'] if e['name'] == phase)
        model_path = next(e['model'] for e in reversed(log['phases']) if e.get('model'))
        try:
            model = MiModel.load(self.dir / model_path)
            recordings = load_inputs(bags=[str(self.dir / entry['run_dir'])])
            report = evaluate(model, recordings)
            _, windows = evaluate_windows(model, recordings, recenter='session')
        except ClassifierError as err:
            msg = f'The held-out run {entry["run_dir"]} could not be scored: {err}'
            raise SessionError(msg) from None
        logits = model.classifier.logits(windows.distances)
        positions = label_positions(model.classes, windows.labels)
        before = calibration_summary(logits, positions, model.temperature)
        trained_temperature, model.temperature = model.temperature, fit_temperature(
            logits, positions)
        after = calibration_summary(logits, positions, model.temperature)
        # the figures a user reads are measured on windows the temperature was not fitted on:
        # two folds, the run's first and second halves in time (fit on one, measure on the
        # other), so the next run's drift is in them as it will be live
        half = len(positions) // 2
        folds = [(slice(0, half), slice(half, None)), (slice(half, None), slice(0, half))]
        unseen = {'ece_before': 0.0, 'ece_after': 0.0, 'nll_before': 0.0, 'nll_after': 0.0}
        for fit_on, test_on in folds if half > 0 else []:
            t_fold = fit_temperature(logits[fit_on], positions[fit_on])
            b = calibration_summary(logits[test_on], positions[test_on], trained_temperature)
            a = calibration_summary(logits[test_on], positions[test_on], t_fold)
            for key, value in (('ece_before', b['ece']), ('ece_after', a['ece']),
                               ('nll_before', b['nll']), ('nll_after', a['nll'])):
                unseen[key] += float(value) / len(folds)
        temperature = {'before': float(trained_temperature),
                       'after': float(model.temperature),
                       'ece_before': float(before['ece']), 'ece_after': float(after['ece']),
                       'nll_before': float(before['nll']), 'nll_after': float(after['nll']),
                       'fitted_on': str(entry['run_dir']),
                       'unseen': unseen if half > 0 else None}
        model.provenance['heldout_temperature'] = temperature
        gate = self._answer_gate(log, model)
        calibrated = Path(model.save(self.dir / 'models' / f'calibrated_on_{phase}'))
        return {'heldout_accuracy': float(report['accuracy']),
                'heldout_trials': int(report['n_trials']),
                'model_path': str(calibrated.relative_to(self.dir)),
                'trained_model_path': model_path, 'temperature': temperature, **gate}

    def _answer_gate(self, log: dict[str, Any], model: Any) -> dict[str, Any]:
        """Choose the person's answer pair and thresholds and give the calibration gate's
        verdict (:func:`mindgrasp_classifier.gate.calibrate_answer`) from every recorded Graz
        and Trainer run of the session, each held out in turn; written into ``model``.
        Returns ``answer_pair``, ``decision_thresholds`` and ``gate`` (``needs_training`` with
        the default pair when the runs are too few to hold any out)."""
        import dataclasses

        from mindgrasp_classifier.data import load_inputs
        from mindgrasp_classifier.errors import ClassifierError
        from mindgrasp_classifier.gate import calibrate_answer
        from mindgrasp_classifier.training import TrainingConfig

        recordings = []
        for e in log['phases']:
            if e.get('kind') in ('graz', 'trainer') and e.get('run_dir'):
                try:
                    recordings += load_inputs(bags=[str(self.dir / e['run_dir'])])
                except ClassifierError:
                    continue
        names = {f.name for f in dataclasses.fields(TrainingConfig)}
        config = {k: v for k, v in (model.provenance.get('config') or {}).items()
                  if k in names}
        if 'band' in config:
            config['band'] = tuple(config['band'])
        entries = calibrate_answer(recordings, TrainingConfig(**config),
                                   temperature=model.temperature)
        model.answer_pair = entries['answer_pair']
        model.decision_thresholds = entries['decision_thresholds']
        model.gate = entries['gate']
        return entries

    def write_report(self, log: dict[str, Any]) -> str:
        """report.yaml and report.md; returns the Markdown."""
        lines = [f"# Session {log['session']} of subject {log['subject']}", '',
                 f"Plan: {log['plan'].get('name', '')}, started {log.get('started')}, ended "
                 f"{log.get('ended', '-')}.", '', '| phase | kind | status | model after | '
                 'cross-validated accuracy | figures |', '|---|---|---|---|---|---|']
        for e in log['phases']:
            acc = f"{100 * e['cv_accuracy']:.1f} %" if 'cv_accuracy' in e else '-'
            fig = ''
            if 'mean_ee_distance_m' in e:
                fig = f"Trainer distance {100 * e['mean_ee_distance_m']:.1f} cm (mean)"
            if 'n_grasp_trials' in e:
                fig = (f"{e['n_correct_grasps']}/{e['n_grasp_trials']} correct grasps "
                       f"({e.get('n_lifted', 0)} lifted)")
            lines.append(f"| {e['name']} | {e['kind']} | {e['status']} | "
                         f"{e.get('model', '-')} | {acc} | {fig} |")
        for e in log['phases']:
            if e.get('trainer_trials'):
                lines += ['', f"## Trainer end-effector distance per trial ({e['name']})", '',
                          '| trial | class | mean distance (cm) | aborted |', '|---|---|---|---|']
                lines += [f"| {t['trial']} | {t['class']} | {100 * t['mean_ee_distance_m']:.1f}"
                          f" | {t['aborted']} |" for t in e['trainer_trials']]
        text = '\n'.join(lines) + '\n'
        (self.dir / 'report.md').write_text(text, encoding='utf-8')
        (self.dir / 'report.yaml').write_text(yaml.safe_dump(
            {'subject': log['subject'], 'session': log['session'], 'phases': log['phases']},
            sort_keys=False), encoding='utf-8')
        return text


@contextlib.contextmanager
def _environment(name: str, value: str | None) -> Iterator[None]:
    """``$name`` set to ``value`` while the block runs (None: left as it is), then restored: the
    launcher reads a phase's parameter files from ``$MINDGRASP_PARAMS_FILES``."""
    previous = os.environ.get(name)
    if value is not None:
        os.environ[name] = value
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = previous


def _phase_outcome(run_dir: Path, code: int, prompters: list[str]) -> tuple[int, str]:
    """Whether a phase's launch counts as done: its prompter (one of ``prompters``, the nodes
    whose end ends the phase) finished (exit code 0), no node died, and the run was recorded. A
    node that needed SIGTERM to stop after the prompter had finished (a slow shutdown on a
    loaded machine) loses nothing and is only noted."""
    summary_path = run_dir / 'summary.yaml'
    if code == 0 or not summary_path.is_file():
        return code, ''
    summary = yaml.safe_load(summary_path.read_text(encoding='utf-8')) or {}
    procs = {p.get('label'): p for p in summary.get('processes', [])}
    prompter = next((procs[name] for name in prompters if name in procs), {})
    died = [label for label, p in procs.items() if p.get('how') == 'died']
    if (prompter.get('how') == 'finished' and prompter.get('returncode') == 0 and not died
            and (run_dir / 'bag' / 'metadata.yaml').is_file()):
        slow = [f"{label} ({p.get('how')})" for label, p in procs.items() if not p.get('clean')]
        return 0, f"all trials ran; slow to stop: {', '.join(slow)}"
    return code, ''


def _grasp_results(bag: Path) -> list[dict[str, Any]]:
    """One entry per trial of a test run's bag: the desired object (/task/target), what was
    grasped and whether it was lifted (/task/result; none: no grasp before the trial ended)."""
    if not bag.is_dir():
        return []
    from mindgrasp_bag.reader import BagReader
    from mindgrasp_ros.typesupport import typestore

    store = typestore()
    trials: dict[int, dict[str, Any]] = {}
    with BagReader(bag) as reader:
        for topic, _, data in reader.messages([TASK_TARGET.name, TASK_RESULT.name]):
            if topic == TASK_TARGET.name:
                m = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/TaskTarget')
                trials.setdefault(int(m.trial), {
                    'trial': int(m.trial), 'desired': f'{m.colour} {m.shape}'.strip(),
                    'grasped': '', 'success': False, 'duration_s': None})
            else:
                m = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/GraspResult')
                entry = trials.setdefault(int(m.trial), {'trial': int(m.trial),
                                                         'desired': m.desired_object})
                entry.update(grasped=m.grasped_object, success=bool(m.success),
                             duration_s=round(float(m.duration), 2))
    return [trials[k] for k in sorted(trials) if k > 0]
