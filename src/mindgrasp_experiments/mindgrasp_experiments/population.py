"""Experiments over many subjects: calibration and the closed loop for each, then the population.

A population is a list of replay subjects (``eegmmidb:<n>`` or subject files,
:mod:`mindgrasp_eeg.subject_file`), given on the command line or in a population file::

    # docs/populations/eegmmidb_local.yaml
    name: eegmmidb_local
    subjects:                                  # paths relative to this file
      - eegmmidb:1
      - {subject: eegmmidb_local/eegmmidb_s002.yaml, group: tuning}
      - {subject: eegmmidb_local/eegmmidb_s006.yaml, group: unseen,
         params: {fsm.offer_delay: 2.0}}       # node parameters for this subject only

Each subject is calibrated (:func:`~mindgrasp_experiments.subject_launch.subject_launch_args`,
the model cached in ``<out>/models``) and runs the set-locations protocol as ``mindgrasp experiment
set-locations --subject S`` does (one :class:`~mindgrasp_experiments.experiment.Experiment`,
its run directory ``<out>/subjects/<label>/``, trials on ``workers`` processes or Ray). A
subject whose run directory holds a finished run of the same options is not run again, so a
killed population restarted with the same ``out`` continues where it stopped, with the same
records (a subject cut off half-way is run again from its first trial: a trial's record depends
on ``(seed, trial)`` and the model only).

:func:`subject_row` reads one row of the per-subject table from the run's ``summary.json``
(the outcomes with Wilson 95 % intervals, median time to a correct grasp, ITR, and, when the
calibration wrote them, the answer pair, the gate's verdict and its predicted correct rate;
``None`` otherwise); :func:`population_figures` gives the figures across subjects (median and
quartiles of the rates, the pooled wrong-grasp rate with its interval, the share of subjects at
>= 50 % correct, the prediction's agreement) and :func:`write_population` writes
``population.csv``, ``population.json``, ``report.md`` and the plots.

    >>> expressible_pairs(('left_hand', 'right_hand'), rest=True)
    ['left_right', 'mi_rest']
    >>> pooled = population_figures([{'trials': 18, 'wrong_grasp_count': 1,
    ...                               'correct_count': 17, 'correct_rate': 17 / 18}])
    >>> pooled['pooled_wrong_grasp_rate'], pooled['share_at_least_half_correct']
    (0.05555555555555555, 1.0)
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError

__all__ = ['NAMED_PAIRS', 'POPULATION_COLUMNS', 'PopulationResults', 'PopulationSubject',
           'expressible_pairs', 'load_population', 'parse_subject_list', 'population_figures',
           'resolve_subjects', 'restricted_pair', 'run_population', 'subject_row', 'targets',
           'write_population']

#: answer pairs of the contract with the answer-pair branch: name -> (yes classes, no classes)
NAMED_PAIRS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    'hands_feet': (('both_hands',), ('both_feet',)),
    'left_right': (('left_hand',), ('right_hand',)),
}
#: --gate: who drives the arm: subjects the calibration gate calls ready (as on hardware), or all
GATES = ('ready', 'any')
#: the gate's predictions and the answer pair, as the calibration writes them into summary.json
CONTRACT_KEYS = ('answer_pair', 'gate_verdict', 'predicted_correct_rate', 'predicted_wrong_rate',
                 'predicted_decision_time_s')
#: columns of population.csv, in order
POPULATION_COLUMNS = (
    'subject', 'label', 'group', 'status', 'trials', 'correct_count', 'correct_rate',
    'correct_ci95', 'wrong_grasp_count', 'wrong_grasp_rate', 'wrong_grasp_ci95',
    'no_grasp_count', 'no_grasp_rate', 'no_grasp_ci95', 'median_time_to_correct_grasp_s',
    'itr_bits_per_min', 'online_accuracy', 'calibration_accuracy', *CONTRACT_KEYS,
    'play_classes', 'restriction', 'wall_s', 'sim_s')
#: a subject's predicted correct rate counts as right when within this of the measured one
PREDICTION_TOLERANCE = 0.20


@dataclasses.dataclass(frozen=True)
class PopulationSubject:
    """One subject of a population.

    Attributes
    ----------
    subject : str
        What the experiment is given: ``eegmmidb:<n>`` or a subject file's absolute path.
    label : str
        The subject's name in the table and its run directory (the subject file's stem, or
        ``eegmmidb_s<nnn>``); unique in a population.
    group : str
        A group the figures are also given for (e.g. ``tuning`` / ``unseen``), or ``''``.
    params : Mapping[str, Any]
        ``{'node.parameter': value}`` for this subject (on top of the run's ``--param``).
    calibration, play : tuple[str, ...]
        The recordings as the subject names them (``eegbci:2:4`` ...).
    play_classes : tuple[str, ...]
        The imagery classes the play recordings' event maps hold (``CLASS_NAMES`` order).
    play_rest : bool
        Whether the play recordings' event maps mark rest.
    """

    subject: str
    label: str
    group: str = ''
    params: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    calibration: tuple[str, ...] = ()
    play: tuple[str, ...] = ()
    play_classes: tuple[str, ...] = ()
    play_rest: bool = True

    @property
    def restricted(self) -> bool:
        """Whether the play recordings hold only some of the four imagery classes."""
        from mindgrasp_common.mi import CLASS_NAMES

        return set(self.play_classes) != set(CLASS_NAMES)

    def restriction(self) -> str:
        """One sentence on what the play data can express, ``''`` when it holds every class."""
        if not self.restricted:
            return ''
        from mindgrasp_classifier.answer_pair import REST_PAIRS_CHOSEN

        # the pairs the automatic choice may take (imagery / rest is not among them)
        pairs = expressible_pairs(self.play_classes, rest=self.play_rest and REST_PAIRS_CHOSEN)
        return (f"play data holds {', '.join(self.play_classes) or 'no imagery class'}"
                f"{' and rest' if self.play_rest else ''} only: answer pairs restricted to "
                f"{', '.join(pairs) or 'none'}")

    def config(self) -> dict[str, Any]:
        """What identifies this subject's records (for the resume check)."""
        return {'subject': self.subject, 'label': self.label, 'params': dict(self.params)}


def expressible_pairs(play_classes: Sequence[str], *, rest: bool = True) -> list[str]:
    """The answer pairs a subject's play data can express: the named pairs (``hands_feet``,
    ``left_right``) whose classes it holds, ``mi_rest`` when it holds rest and some imagery, then
    any other pair of its classes as ``<yes>_<no>`` (``CLASS_NAMES`` order).

        >>> expressible_pairs(('left_hand', 'right_hand', 'both_hands', 'both_feet'))[:3]
        ['hands_feet', 'left_right', 'mi_rest']
        >>> expressible_pairs(('left_hand', 'both_feet'), rest=False)
        ['left_hand_both_feet']
    """
    from mindgrasp_common.mi import CLASS_NAMES

    have = [c for c in CLASS_NAMES if c in set(play_classes)]
    out = [name for name, (yes, no) in NAMED_PAIRS.items()
           if set(yes) <= set(have) and set(no) <= set(have)]
    if rest and have:
        out.append('mi_rest')
    named = {frozenset((*yes, *no)) for yes, no in NAMED_PAIRS.values()}
    out += [f'{a}_{b}' for i, a in enumerate(have) for b in have[i + 1:]
            if frozenset((a, b)) not in named]
    return out


def _pair_classes(name: str) -> tuple[set[str], set[str]] | None:
    """(yes, no) classes of a pair named per the contract (``rest`` for mi_rest's no), or None
    for a name this module does not know."""
    from mindgrasp_common.mi import CLASS_NAMES

    if name in NAMED_PAIRS:
        yes, no = NAMED_PAIRS[name]
        return set(yes), set(no)
    if name == 'mi_rest':
        return set(CLASS_NAMES), {'rest'}
    for a in CLASS_NAMES:
        for b in CLASS_NAMES:
            if a != b and name == f'{a}_{b}':
                return {a}, {b}
    return None


def _expressible(yes: set[str], no: set[str], subject: PopulationSubject) -> bool:
    """Whether the play data has an epoch to stream for each answer (some class of each side)."""
    have = {*subject.play_classes, *(('rest',) if subject.play_rest else ())}
    return bool(yes & have) and bool(no & have)


def parse_subject_list(text: str) -> list[str]:
    """``'eegmmidb:1, s02.yaml'`` -> subjects (each checked when resolved), each once."""
    out = [part.strip() for part in text.split(',')]
    if not all(out):
        msg = (f'--subjects {text!r}: an empty entry; give subjects separated by commas, e.g. '
               'eegmmidb:1,eegmmidb:2,docs/subjects/eegmmidb_s001.yaml.')
        raise ExperimentError(msg)
    return out


def load_population(path: str | Path) -> list[dict[str, Any]]:
    """The entries of a population file (format in the module docstring): dicts with
    ``subject`` (file paths made absolute, relative to the population file), ``group``,
    ``params``. Raises :class:`ExperimentError` naming the problem and the fix."""
    import yaml

    from mindgrasp_common.cli_checks import yaml_error_text

    path = Path(path)
    where = f'--population {path}'
    try:
        doc = yaml.safe_load(path.read_text(encoding='utf-8'))
    except OSError as exc:
        msg = f'{where}: cannot read it ({exc.strerror or exc}); give a population YAML file.'
        raise ExperimentError(msg) from None
    except yaml.YAMLError as exc:
        msg = f'{where}: not valid YAML ({yaml_error_text(exc)}); fix the file.'
        raise ExperimentError(msg) from None
    entries = doc.get('subjects') if isinstance(doc, dict) else None
    unknown = sorted(set(doc) - {'name', 'subjects'}) if isinstance(doc, dict) else []
    if not isinstance(entries, list) or not entries or unknown:
        msg = (f'{where}: expected a mapping with a non-empty subjects: list (and an optional '
               f"name:){f', not {unknown}' if unknown else ''}; see "
               'docs/populations/eegmmidb_local.yaml.')
        raise ExperimentError(msg)
    out = []
    for i, entry in enumerate(entries, 1):
        if isinstance(entry, str):
            entry = {'subject': entry}
        ok = (isinstance(entry, dict) and isinstance(entry.get('subject'), str)
              and set(entry) <= {'subject', 'group', 'params'}
              and isinstance(entry.get('group', ''), str)
              and isinstance(entry.get('params', {}), dict))
        if not ok:
            msg = (f'{where}: subject {i} must be eegmmidb:<n>, a subject file, or a mapping '
                   '{subject: ..., group: NAME, params: {node.parameter: value}}; got '
                   f'{entry!r}.')
            raise ExperimentError(msg)
        subject = entry['subject'].strip()
        if not subject.lower().startswith('eegmmidb:'):
            subject = str((path.parent / subject).resolve())
        out.append({'subject': subject, 'group': entry.get('group', ''),
                    'params': dict(entry.get('params', {}))})
    return out


def resolve_subjects(entries: Sequence[Mapping[str, Any]]) -> list[PopulationSubject]:
    """:class:`PopulationSubject` of each entry (``{'subject': ..., 'group': ..., 'params':
    ...}``): the subject file read and its recordings found (no EEG is loaded). Raises
    :class:`ExperimentError` for a subject that is not a replay subject, a bad subject file or
    a subject given twice."""
    from mindgrasp_common.mi import CLASS_NAMES
    from mindgrasp_eeg import EEGError
    from mindgrasp_eeg.subject_file import is_replay_source, replay_subject

    out: list[PopulationSubject] = []
    for entry in entries:
        text = entry['subject']
        if not is_replay_source(text):
            msg = (f'subject {text!r}: a population runs replay subjects (real EEG); give '
                   'eegmmidb:<n> or a replay subject file (.yaml).')
            raise ExperimentError(msg)
        try:
            files = replay_subject(text)
        except EEGError as exc:
            raise ExperimentError(str(exc)) from None
        classes = {c for f in files.play for c in f.events.values() if c is not None}
        subject = PopulationSubject(
            subject=files.source, label=files.name, group=str(entry.get('group', '')),
            params=dict(entry.get('params', {})),
            calibration=tuple(f.entry for f in files.calibration),
            play=tuple(f.entry for f in files.play),
            play_classes=tuple(CLASS_NAMES[c] for c in sorted(classes)),
            play_rest=any(c is None for f in files.play for c in f.events.values()))
        if any(s.label == subject.label for s in out):
            msg = (f'subject {text!r} is given twice (as {subject.label}); give each subject '
                   'once (subject files need distinct names).')
            raise ExperimentError(msg)
        out.append(subject)
    return out


# -- one subject ----------------------------------------------------------------------------

def _finite(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and math.isfinite(value) else None


def _ci(value: Any) -> list[float | None]:
    if isinstance(value, (list, tuple)) and len(value) == 2:
        return [_finite(value[0]), _finite(value[1])]
    return [None, None]


def _contract_value(doc: Mapping[str, Any], key: str) -> Any:
    """A key of the answer-pair contract from summary.json: flat in its summary, at its top or
    in its run section (whichever the calibration wrote); None when absent."""
    for section in (doc.get('summary', {}), doc, doc.get('run', {})):
        if isinstance(section, Mapping) and section.get(key) is not None:
            return section[key]
    return None


def subject_row(subject: PopulationSubject, doc: Mapping[str, Any] | None,
                status: str = 'done') -> dict[str, Any]:
    """One row of the per-subject table from a run's summary.json document (``None``: the
    subject did not run; ``status`` says why). Absent figures are ``None``."""
    s = (doc or {}).get('summary', {})
    run = (doc or {}).get('run', {})
    row: dict[str, Any] = {
        'subject': subject.subject, 'label': subject.label, 'group': subject.group,
        'status': status, 'trials': s.get('trials'),
        'correct_count': s.get('correct_and_successful_count'),
        'correct_rate': _finite(s.get('correct_and_successful_rate')),
        'correct_ci95': _ci(s.get('correct_and_successful_ci95')),
    }
    for outcome in ('wrong_grasp', 'no_grasp'):
        row[f'{outcome}_count'] = s.get(f'{outcome}_count')
        row[f'{outcome}_rate'] = _finite(s.get(f'{outcome}_rate'))
        row[f'{outcome}_ci95'] = _ci(s.get(f'{outcome}_ci95'))
    for key in ('median_time_to_correct_grasp_s', 'itr_bits_per_min', 'online_accuracy',
                'calibration_accuracy'):
        row[key] = _finite(s.get(key))
    for key in CONTRACT_KEYS:
        value = _contract_value(doc or {}, key)
        row[key] = _finite(value) if key.startswith('predicted_') else value
    row['play_classes'] = ' '.join(subject.play_classes)
    row['restriction'] = subject.restriction()
    row['wall_s'] = _finite(run.get('wall_s'))
    row['sim_s'] = _finite(run.get('sim_s'))
    return row


def _gate_row(subject: PopulationSubject, model_json: str | Path) -> dict[str, Any] | None:
    """The row of a subject whose calibration gate does not say ready (its verdict, reason and
    prediction, no trials), or None when it may drive the arm."""
    try:
        doc = json.loads(Path(model_json).read_text(encoding='utf-8'))
    except (OSError, ValueError):
        doc = {}
    gate = doc.get('gate') if isinstance(doc, dict) and isinstance(doc.get('gate'), dict) else {}
    verdict = str(gate.get('verdict') or 'unassessed')
    if verdict == 'ready':
        return None
    predicted = gate.get('predicted') if isinstance(gate.get('predicted'), dict) else {}
    pair = doc.get('answer_pair') if isinstance(doc.get('answer_pair'), dict) else {}
    summary = {'answer_pair': pair.get('name'), 'gate_verdict': verdict,
               'gate_reason': gate.get('reason'),
               'predicted_correct_rate': predicted.get('correct_rate'),
               'predicted_wrong_rate': predicted.get('wrong_rate'),
               'predicted_decision_time_s': predicted.get('decision_time_s')}
    status = (f"not run: the calibration gate says {verdict} ({gate.get('reason', '')}); it "
              'does not drive the arm, as on hardware (--gate any runs it)')
    return subject_row(subject, {'summary': summary}, status=status)


def restricted_pair(subject: PopulationSubject, model_json: str | Path) -> tuple[str | None, str]:
    """The answer pair to run ``subject`` with when the calibrated model's choice is one its
    play data cannot express, and a note for the report.

    Reads the model's ``answer_pair`` (``{name, yes, no}``) and ``gate.pairs`` (``[{name,
    heldout_accuracy, ...}]``): when the chosen pair has no epoch to stream for one of its
    answers, the expressible pair with the best held-out accuracy is returned (run with
    ``fsm.answer_pair``). ``(None, note)`` when the model's choice stands, or when the model
    names no answer pair (a build without per-person answer pairs: the note says so for a
    restricted subject)."""
    try:
        doc = json.loads(Path(model_json).read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return None, ''
    pair = doc.get('answer_pair') if isinstance(doc, dict) else None
    if not isinstance(pair, dict) or not isinstance(pair.get('name'), str):
        return None, ('the model names no answer pair (this build asks both hands / both '
                      'feet)' if subject.restricted else '')
    yes, no = set(pair.get('yes') or ()), set(pair.get('no') or ())
    if not (yes and no):
        yes, no = _pair_classes(pair['name']) or (set(), set())
    if _expressible(yes, no, subject):
        return None, ''
    gate = doc.get('gate') if isinstance(doc.get('gate'), dict) else {}
    options = []
    for p in gate.get('pairs') or ():
        classes = _pair_classes(str(p.get('name', ''))) if isinstance(p, dict) else None
        if classes and _expressible(*classes, subject):
            options.append((_finite(p.get('heldout_accuracy')) or 0.0, p['name']))
    if not options:
        return None, (f"the model chose {pair['name']}, which the play data cannot express, "
                      'and names no other pair it can')
    best = max(options)[1]
    return best, (f"the model chose {pair['name']}; the play data cannot express it, so "
                  f'{best} (the best expressible pair held out) was run')


# -- the population run -----------------------------------------------------------------------

@dataclasses.dataclass
class PopulationResults:
    """What :func:`run_population` produced: the table's rows (one per subject, in the order
    given), the figures across subjects, the run's configuration and cost."""

    out: Path
    rows: list[dict[str, Any]]
    figures: dict[str, Any]
    info: dict[str, Any]
    interrupted: bool = False


def _check_config(out: Path, config: Mapping[str, Any]) -> None:
    """Write ``population_config.json`` or check a resumed run's against it."""
    path = out / 'population_config.json'
    if path.exists():
        try:
            before = json.loads(path.read_text(encoding='utf-8'))
        except (OSError, ValueError):
            before = None
        if before != json.loads(json.dumps(config)):
            changed = sorted(k for k in config if not isinstance(before, dict)
                             or before.get(k) != json.loads(json.dumps(config[k])))
            msg = (f'--out {out} holds a population run with other options ('
                   f"{', '.join(changed) or 'unreadable population_config.json'}); give the "
                   'same options to continue it, or a new --out.')
            raise ExperimentError(msg)
        return
    # models/: calibrations made before (by digest, e.g. copied from another run) are reused
    if out.exists() and any(p.name not in ('logs', 'models') for p in out.iterdir()):
        msg = (f'--out {out} exists and holds other files than a population run; choose a new '
               '--out or remove it (a run never overwrites recorded data).')
        raise ExperimentError(msg)
    if not out.absolute().parent.is_dir():
        msg = (f'--out {out}: the folder {out.absolute().parent} does not exist; give a run '
               'directory in an existing folder (only the run directory itself is created).')
        raise ExperimentError(msg)
    out.mkdir(exist_ok=True)
    path.write_text(json.dumps(config, indent=2) + '\n', encoding='utf-8')


def _finished(run_dir: Path, trials: int) -> dict | None:
    """The summary.json document of a finished run of ``trials`` trials in ``run_dir``."""
    try:
        doc = json.loads((run_dir / 'summary.json').read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return None
    s, run = doc.get('summary', {}), doc.get('run', {})
    done = (not run.get('interrupted') and s.get('interrupted_trials') == 0
            and s.get('trials') == trials and (run_dir / 'records.csv').exists())
    return doc if done else None


def run_population(subjects: Sequence[PopulationSubject], out: str | Path, *,
                   trials: int, seed: int = 0, accuracy: float = 1.0, workers: int = 1,
                   params: Mapping[str, Any] | None = None, ray: str | None = None,
                   robot: str | None = None, realism: str | None = None,
                   launch: str | None = None, step_s: float = 0.02,
                   trial_timeout_s: float = 240.0, stall_timeout_s: float = 120.0,
                   command: str = '', log: Callable[[str], None] = print,
                   warn: Callable[[str], None] = print,
                   on_subject: Callable[[PopulationSubject, str], None] | None = None,
                   on_trial: Callable[[], None] | None = None,
                   gate: str = 'ready') -> PopulationResults:
    """Calibrate each subject and run its closed loop, in order; write the population.

    ``gate='ready'`` (default) runs the closed loop only for subjects whose calibration gate
    says ready, as ``mindgrasp launch hardware`` lets only them drive a real arm; the others get
    a row with their verdict, prediction and reason. ``gate='any'`` runs every subject (to
    measure what the gate keeps from the arm).

    Subjects with a finished run in ``out`` of the same options are read, not run again
    (``on_subject(subject, 'resumed')``); one cut off half-way is run again from its first
    trial. A subject that cannot be calibrated gets a row with its reason and the run goes on.
    ``on_subject(subject, 'calibrating' | 'running' | 'resumed' | 'failed')`` and ``on_trial()``
    report progress. Ctrl-C stops after writing what is done (``interrupted``). Raises
    :class:`ExperimentError` before any subject runs for options that cannot work (another
    population's ``out``, unknown ``params``).
    """
    from mindgrasp_eeg import EEGError
    from mindgrasp_experiments.experiment import Experiment
    from mindgrasp_experiments.subject_launch import subject_launch_args

    out = Path(out)
    options = {'trials': trials, 'seed': seed, 'accuracy': accuracy, 'params': dict(params or {}),
               'robot': robot, 'realism': realism, 'launch': launch, 'step_s': step_s,
               'trial_timeout_s': trial_timeout_s, 'stall_timeout_s': stall_timeout_s,
               'gate': gate}
    if gate not in GATES:
        msg = f'--gate is {gate!r}; use one of {", ".join(GATES)}.'
        raise ExperimentError(msg)
    _check_config(out, {**options, 'subjects': [s.config() for s in subjects]})
    (out / 'subjects').mkdir(exist_ok=True)
    rows: list[dict[str, Any]] = []
    notes: dict[str, str] = {}
    interrupted = False
    wall0 = time.perf_counter()
    for subject in subjects:
        run_dir = out / 'subjects' / subject.label
        doc = _finished(run_dir, trials)
        if doc is not None:
            if on_subject is not None:
                on_subject(subject, 'resumed')
            notes[subject.label] = doc.get('run', {}).get('population_note', '')
            rows.append(subject_row(subject, doc))
            continue
        if run_dir.exists():            # cut off half-way: its trials are run again
            shutil.rmtree(run_dir)
        if on_subject is not None:
            on_subject(subject, 'calibrating')
        try:
            subject_args = subject_launch_args(subject.subject, out / 'models')
        except (EEGError, ExperimentError) as exc:
            if on_subject is not None:
                on_subject(subject, 'failed')
            warn(f'{subject.label}: not run: {exc}')
            rows.append(subject_row(subject, None, status=f'not run: {exc}'))
            continue
        gated = _gate_row(subject, subject_args.get('model', '')) if gate == 'ready' else None
        if gated is not None:
            if on_subject is not None:
                on_subject(subject, 'gated')
            warn(f"{subject.label}: {gated['status']}")
            rows.append(gated)
            continue
        pair, note = restricted_pair(subject, subject_args.get('model', ''))
        notes[subject.label] = note
        subject_params = {**options['params'], **subject.params}
        if pair is not None and 'fsm.answer_pair' not in subject.params:
            subject_params['fsm.answer_pair'] = pair
        experiment = Experiment('set_locations', subject=subject.subject, trials=trials,
                                seed=seed, workers=workers, accuracy=accuracy,
                                params=subject_params, robot=robot, realism=realism,
                                launch=launch, step_s=step_s, trial_timeout_s=trial_timeout_s,
                                stall_timeout_s=stall_timeout_s, ray=ray)
        if on_subject is not None:
            on_subject(subject, 'running')
        results = experiment.run(
            run_dir, subject_args=subject_args,
            command=f'{command} (subject {subject.label})'.strip(), log=log, warn=warn,
            on_trial=(lambda _runs: on_trial()) if on_trial is not None else None)
        if note:      # kept beside the run, for a resumed population's report
            _add_note(run_dir, note)
        doc = _finished(run_dir, trials) if not results.interrupted else None
        if doc is None:
            doc = {'summary': results.summary, 'run': results.info}
        rows.append(subject_row(subject, doc, 'interrupted' if results.interrupted else 'done'))
        if results.interrupted:
            interrupted = True
            break
    info = {'command': command, **options, 'workers': workers, 'ray': ray,
            'subjects': [s.config() | {'group': s.group, 'calibration': list(s.calibration),
                                       'play': list(s.play), 'restriction': s.restriction(),
                                       'note': notes.get(s.label, '')}
                         for s in subjects],
            'wall_s': time.perf_counter() - wall0, 'interrupted': interrupted}
    figures = write_population(out, rows, info)
    return PopulationResults(out=out, rows=rows, figures=figures, info=info,
                             interrupted=interrupted)


def _add_note(run_dir: Path, note: str) -> None:
    """Keep the population's note on a subject (an answer pair restricted) in its summary."""
    path = run_dir / 'summary.json'
    try:
        doc = json.loads(path.read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return
    doc.setdefault('run', {})['population_note'] = note
    path.write_text(json.dumps(doc, indent=2) + '\n', encoding='utf-8')


# -- figures across subjects --------------------------------------------------------------------

def _quartiles(values: Sequence[float]) -> dict[str, float | None]:
    """Median and quartiles (numpy's linear interpolation) of the finite values."""
    import numpy as np

    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return {'median': None, 'q1': None, 'q3': None, 'n': 0}
    q1, median, q3 = (float(x) for x in np.percentile(values, [25, 50, 75]))
    return {'median': median, 'q1': q1, 'q3': q3, 'n': len(values)}


def population_figures(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Figures across the subjects that ran (``trials`` > 0).

    Median and quartiles across subjects of the correct, wrong-grasp and no-grasp rates, the
    median time to a correct grasp and the ITR; the pooled wrong-grasp rate (all subjects'
    wrong grasps over all their trials) with its Wilson 95 % interval; the most wrong grasps of
    one subject; the share of subjects at >= 50 % correct; and, over subjects with a
    prediction, the share whose predicted correct rate is within 20 points of the measured one
    and, over subjects the gate called ready, the share at >= 50 % correct."""
    from mindgrasp_experiments.summary import wilson

    ran = [r for r in rows if r.get('trials')]
    total = sum(int(r['trials']) for r in ran)
    wrong = sum(int(r.get('wrong_grasp_count') or 0) for r in ran)
    correct = sum(int(r.get('correct_count') or 0) for r in ran)
    low, high = wilson(wrong, total)
    rates = [r.get('correct_rate') for r in ran]
    out: dict[str, Any] = {
        'subjects': len(rows), 'subjects_run': len(ran), 'trials': total,
        'subjects_kept_from_the_arm': sum('calibration gate says' in str(r.get('status', ''))
                                          for r in rows),
        'correct_rate': _quartiles(rates),
        'wrong_grasp_rate': _quartiles([r.get('wrong_grasp_rate') for r in ran]),
        'no_grasp_rate': _quartiles([r.get('no_grasp_rate') for r in ran]),
        'median_time_to_correct_grasp_s': _quartiles(
            [r.get('median_time_to_correct_grasp_s') for r in ran]),
        'itr_bits_per_min': _quartiles([r.get('itr_bits_per_min') for r in ran]),
        'pooled_correct_rate': correct / total if total else None,
        'pooled_wrong_grasp_count': wrong,
        'pooled_wrong_grasp_rate': wrong / total if total else None,
        'pooled_wrong_grasp_ci95': [None if math.isnan(low) else low,
                                    None if math.isnan(high) else high],
        'max_wrong_grasps_per_subject': max((int(r.get('wrong_grasp_count') or 0) for r in ran),
                                            default=None),
        'share_at_least_half_correct': (sum((r.get('correct_rate') or 0.0) >= 0.5 for r in ran)
                                        / len(ran) if ran else None),
    }
    predicted = [r for r in ran if r.get('predicted_correct_rate') is not None
                 and r.get('correct_rate') is not None]
    out['subjects_with_prediction'] = len(predicted)
    out['share_predicted_within_20_points'] = (
        sum(abs(r['predicted_correct_rate'] - r['correct_rate']) <= PREDICTION_TOLERANCE + 1e-9
            for r in predicted) / len(predicted) if predicted else None)
    ready = [r for r in ran if r.get('gate_verdict') == 'ready']
    out['subjects_ready'] = len(ready)
    out['share_of_ready_at_least_half_correct'] = (
        sum((r.get('correct_rate') or 0.0) >= 0.5 for r in ready) / len(ready) if ready else None)
    verdicts: dict[str, int] = {}
    for r in ran:
        verdicts[str(r.get('gate_verdict') or '-')] = verdicts.get(
            str(r.get('gate_verdict') or '-'), 0) + 1
    out['gate_verdicts'] = verdicts
    return out


def targets(figures: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    """The issue's targets against the figures: (target, measured, met / missed / -)."""
    def verdict(value: float | None, ok: Callable[[float], bool]) -> str:
        return '-' if value is None else 'met' if ok(value) else 'missed'

    def pct(value: float | None) -> str:
        return '-' if value is None else f'{100 * value:.1f} %'

    pooled = figures.get('pooled_wrong_grasp_rate')
    worst = figures.get('max_wrong_grasps_per_subject')
    median = (figures.get('correct_rate') or {}).get('median')
    share = figures.get('share_at_least_half_correct')
    ready = figures.get('share_of_ready_at_least_half_correct')
    within = figures.get('share_predicted_within_20_points')
    return [
        ('pooled wrong grasps <= 3 % of trials', pct(pooled), verdict(pooled, lambda v: v <= 0.03)),
        ('no subject with more than 1 wrong grasp in 18 trials',
         '-' if worst is None else f'at most {worst}', verdict(worst, lambda v: v <= 1)),
        ('median correct grasps across subjects >= 70 %', pct(median),
         verdict(median, lambda v: v >= 0.70)),
        ('>= 75 % of subjects at >= 50 % correct', pct(share),
         verdict(share, lambda v: v >= 0.75)),
        ('every subject the gate calls ready reaches >= 50 % correct', pct(ready),
         verdict(ready, lambda v: v >= 1.0)),
        ('predicted correct rate within 20 points for >= 80 % of subjects', pct(within),
         verdict(within, lambda v: v >= 0.80)),
    ]


def _cell(value: Any, kind: str = '') -> str:
    """A table cell: ``-`` for an absent figure."""
    if value is None or value == '' or (isinstance(value, float) and not math.isfinite(value)):
        return '-'
    if kind == 'pct':
        return f'{100 * value:.1f} %'
    if kind == 's':
        return f'{value:.1f} s'
    if kind == 'bits':
        return f'{value:.2f}'
    return str(value)


def _count_cell(row: Mapping[str, Any], outcome: str) -> str:
    count, ci = row.get(f'{outcome}_count'), row.get(f'{outcome}_ci95') or [None, None]
    if count is None or not row.get('trials'):
        return '-'
    text = f"{count}/{row['trials']}"
    if ci[0] is not None and ci[1] is not None:
        text += f' ({100 * ci[0]:.0f}-{100 * ci[1]:.0f} %)'
    return text


def _figures_lines(fig: Mapping[str, Any]) -> list[str]:
    def q(name: str, kind: str) -> str:
        d = fig.get(name) or {}
        if d.get('median') is None:
            return '-'
        return (f"{_cell(d['median'], kind)} (quartiles {_cell(d['q1'], kind)} - "
                f"{_cell(d['q3'], kind)})")

    ci = fig.get('pooled_wrong_grasp_ci95') or [None, None]
    pooled = fig.get('pooled_wrong_grasp_rate')
    verdicts = ', '.join(f'{k} {v}' for k, v in fig['gate_verdicts'].items()) or '-'
    pooled_text = '-' if pooled is None else (
        f"{fig['pooled_wrong_grasp_count']}/{fig['trials']}, {_cell(pooled, 'pct')}"
        + (f' (Wilson 95 % {_cell(ci[0], "pct")} - {_cell(ci[1], "pct")})'
           if ci[0] is not None else ''))
    return [
        f"- subjects run: {fig['subjects_run']} of {fig['subjects']}, {fig['trials']} trials "
        f"({fig.get('subjects_kept_from_the_arm', 0)} kept from the arm by the calibration gate)",
        f"- correct grasp per subject: median {q('correct_rate', 'pct')}",
        f"- wrong grasp per subject: median {q('wrong_grasp_rate', 'pct')}; at most "
        f"{_cell(fig.get('max_wrong_grasps_per_subject'))} in one subject",
        f"- no grasp per subject: median {q('no_grasp_rate', 'pct')}",
        f"- median time to a correct grasp: median {q('median_time_to_correct_grasp_s', 's')}",
        f"- ITR (bits/min): median {q('itr_bits_per_min', 'bits')}",
        f'- pooled wrong grasps: {pooled_text}',
        f"- subjects at >= 50 % correct: {_cell(fig.get('share_at_least_half_correct'), 'pct')}",
        f'- gate verdicts: {verdicts}; ready subjects at >= 50 % correct: '
        f"{_cell(fig.get('share_of_ready_at_least_half_correct'), 'pct')}",
        f"- predicted correct rate within 20 points of the measured one: "
        f"{_cell(fig.get('share_predicted_within_20_points'), 'pct')} of "
        f"{fig['subjects_with_prediction']} subjects with a prediction",
    ]


def render_report(rows: Sequence[Mapping[str, Any]], figures: Mapping[str, Any],
                  info: Mapping[str, Any], plots: Sequence[str]) -> str:
    """report.md of a population run."""
    lines = ['# Population run', '']
    where = f"Ray {info['ray']}" if info.get('ray') else f"{info['workers']} worker(s)"
    if info.get('command'):
        lines += ['```bash', str(info['command']), '```', '']
    lines += [f"Set locations, {info['trials']} trials per subject, seed {info['seed']}, "
              f"accuracy {info['accuracy']:g}, trial timeout {info['trial_timeout_s']:g} s"
              f"{', params ' + str(info['params']) if info['params'] else ''}; "
              f"{info['wall_s'] / 60:.1f} min wall for the subjects run now "
              f'({where}).'
              + (' **Interrupted**: the table holds the subjects done so far.'
                 if info.get('interrupted') else ''), '',
              '## Per subject', '',
              '| subject | group | correct (Wilson 95 %) | wrong grasp | no grasp | median time '
              'to a correct grasp | ITR (bits/min) | answer pair | gate | predicted / measured '
              'correct |',
              '|---|---|---|---|---|---|---|---|---|---|']
    for r in rows:
        if not r.get('trials'):
            status = 'not run (below)' if r['status'].startswith('not run') else r['status']
            lines.append(f"| {r['label']} | {_cell(r['group'])} | {status} | - | - | - | - "
                         '| - | - | - |')
            continue
        lines.append(
            f"| {r['label']} | {_cell(r['group'])} | {_count_cell(r, 'correct')} | "
            f"{_count_cell(r, 'wrong_grasp')} | {_count_cell(r, 'no_grasp')} | "
            f"{_cell(r['median_time_to_correct_grasp_s'], 's')} | "
            f"{_cell(r['itr_bits_per_min'], 'bits')} | {_cell(r['answer_pair'])} | "
            f"{_cell(r['gate_verdict'])} | {_cell(r['predicted_correct_rate'], 'pct')} / "
            f"{_cell(r['correct_rate'], 'pct')} |")
    not_run = [r for r in rows if str(r.get('status', '')).startswith('not run')]
    if not_run:
        lines += ['', 'Not run (the run went on with the next subject):', '']
        lines += [f"- {r['label']}: {r['status'].removeprefix('not run: ')}" for r in not_run]
    subjects = {s['label']: s for s in info.get('subjects', [])}
    restricted = [(label, s) for label, s in subjects.items() if s.get('restriction')
                  or s.get('note')]
    lines += ['', '## Subjects and their recordings', '']
    for label, s in subjects.items():
        lines.append(f"- {label}: calibrated on {', '.join(s.get('calibration', [])) or '-'}, "
                     f"played from {', '.join(s.get('play', [])) or '-'}"
                     + (f"; params {s['params']}" if s.get('params') else ''))
    if restricted:
        lines += ['', 'Subjects whose play recordings hold only some classes (the closed loop '
                  'can stream only those):', '']
        lines += [f"- {label}: {'; '.join(x for x in (s.get('restriction'), s.get('note')) if x)}"
                  for label, s in restricted]
    groups = [g for g in dict.fromkeys(r.get('group') for r in rows) if g]
    lines += ['', '## Across subjects', '', *_figures_lines(figures)]
    for group in groups:
        lines += ['', f'### Group {group}', '',
                  *_figures_lines(figures['groups'][group])]
    lines += ['', '## Targets (all subjects run)', '', '| target | measured | |', '|---|---|---|']
    lines += [f'| {t} | {m} | {v} |' for t, m, v in targets(figures)]
    if plots:
        lines += ['', '## Plots', '']
        lines += [f'![{p}]({p})' for p in plots if p.endswith('.png')]
    lines += ['', 'Each subject\'s run (records, summary.json, report.md, plots) is in '
              '`subjects/<subject>/`; its calibrated model in `models/`.', '']
    return '\n'.join(lines)


def write_population(out: str | Path, rows: Sequence[Mapping[str, Any]],
                     info: Mapping[str, Any]) -> dict[str, Any]:
    """Write population.csv, population.json, the plots and report.md into ``out``; returns
    the figures (with ``groups``: the same per group)."""
    from mindgrasp_experiments.plots import write_population_plots
    from mindgrasp_experiments.report import finite

    out = Path(out)
    figures = population_figures(rows)
    figures['groups'] = {g: population_figures([r for r in rows if r.get('group') == g])
                         for g in dict.fromkeys(r.get('group') for r in rows) if g}
    figures['targets'] = [{'target': t, 'measured': m, 'verdict': v}
                          for t, m, v in targets(figures)]
    with (out / 'population.csv').open('w', newline='', encoding='utf-8') as stream:
        writer = csv.DictWriter(stream, fieldnames=POPULATION_COLUMNS)
        writer.writeheader()
        for r in rows:
            writer.writerow({k: _csv(r.get(k)) for k in POPULATION_COLUMNS})
    plots = [p.name for p in write_population_plots(rows, out)]
    doc = finite({'subjects': list(rows), 'population': figures, 'run': dict(info),
                  'plots': plots})
    (out / 'population.json').write_text(json.dumps(doc, indent=2) + '\n', encoding='utf-8')
    (out / 'report.md').write_text(render_report(rows, figures, info, plots), encoding='utf-8')
    return figures


def _csv(value: Any) -> Any:
    if value is None:
        return ''
    if isinstance(value, list):
        return ' '.join('' if v is None else f'{v:.6g}' for v in value)
    return value

