"""Figures of a set of trial records, with Wilson 95 % confidence intervals, and the paper's.

Rates are fractions (0..1); times simulated seconds. ``summarise(records)`` is what the trial
manager logs, ``summary.json`` holds, ``report.md`` shows and every ``--json`` prints; the sweep
table takes its rates from it, under the same names.

Interrupted trials (``failure == 'interrupted'``: Ctrl-C cut them off) are counted apart
(``interrupted_trials``) and left out of every figure: ``trials`` is the number the rates are
over.
"""

from __future__ import annotations

import math
import statistics
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from mindgrasp_experiments.itr import bits_per_selection, itr_bits_per_min
from mindgrasp_experiments.protocols import SHAPES
from mindgrasp_experiments.records import TrialRecord, shape_of

__all__ = ['PAPER', 'SET_LOCATIONS_CHOICES', 'calibration_accuracy_of', 'counted',
           'model_calibration_accuracy', 'selection_choices', 'summarise', 'wilson']

#: The MIndGrasp paper's results (fractions; seconds).
PAPER = {
    'set_locations': {'success_rate': 0.356, 'correct_choice_rate': 0.144,
                      'correct_and_successful_rate': 0.031, 'mean_duration_s': 246.4,
                      'trials': 160},
    'random_locations': {'success_rate': 0.335, 'success_rate_cube': 0.605,
                         'success_rate_cylinder': 0.176, 'success_rate_sphere': 0.133,
                         'trials': 507},
}

#: objects to select among in the set-locations scene (for records without ``n_objects``)
SET_LOCATIONS_CHOICES = 9


def wilson(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (NaN, NaN when ``n`` is 0)."""
    if n <= 0:
        return (math.nan, math.nan)
    from scipy.stats import binomtest

    ci = binomtest(int(successes), int(n)).proportion_ci(confidence_level=confidence,
                                                         method='wilson')
    return (float(ci.low), float(ci.high))


def _count_rate(k: int, n: int) -> dict:
    low, high = wilson(k, n)
    return {'count': k, 'trials': n, 'rate': k / n if n else math.nan, 'ci95': [low, high]}


def _rate(records: Sequence[TrialRecord], field: str) -> dict:
    return _count_rate(sum(bool(getattr(r, field)) for r in records), len(records))


def _stats(values: list[float]) -> tuple[float, float]:
    values = [v for v in values if math.isfinite(v)]
    if not values:
        return math.nan, math.nan
    return statistics.fmean(values), statistics.median(values)


def counted(records: Sequence[TrialRecord]) -> list[TrialRecord]:
    """The records the figures are over: every trial but the interrupted ones."""
    return [r for r in records if r.failure != 'interrupted']


def selection_choices(records: Sequence[TrialRecord]) -> int:
    """``N`` of the information transfer rate: the objects a trial selects among, the most
    frequent over ``records`` (ties: the larger). A trial's own is its scene's ``n_objects``
    (records without it: 9 in set locations), at least 2: a random-locations trial has one
    object, and a grasp of it still tells a selection from none. 0 without records."""
    def own(r: TrialRecord) -> int:
        n = r.n_objects or (SET_LOCATIONS_CHOICES if r.protocol == 'set_locations' else 0)
        return max(2, n)

    counts = Counter(own(r) for r in records)
    return max(counts, key=lambda n: (counts[n], n)) if counts else 0


def model_calibration_accuracy(model_json: str | Path) -> float | None:
    """The cross-validated accuracy a classifier model JSON was trained with
    (``provenance.cross_validation.accuracy``, else its ``balanced_accuracy``), or None when
    the file or the figure is missing."""
    import json

    try:
        doc = json.loads(Path(model_json).read_text(encoding='utf-8'))
        cv = doc['provenance']['cross_validation']
    except (OSError, ValueError, KeyError, TypeError):
        return None
    for key in ('accuracy', 'balanced_accuracy'):
        value = cv.get(key) if isinstance(cv, dict) else None
        if isinstance(value, (int, float)) and math.isfinite(value):
            return float(value)
    return None


def calibration_accuracy_of(run_dir: str | Path) -> float | None:
    """The classifier's cross-validated accuracy in a run directory: the ``model`` parameter of
    ``<run_dir>/params/classifier.yaml`` (as the experiment launched it: ``package://...`` or
    a path) read by :func:`model_calibration_accuracy`. None when the run has no classifier
    (oracle, autonomous, a live run without params) or its model says nothing."""
    import yaml

    from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

    path = Path(run_dir) / 'params' / 'classifier.yaml'
    try:
        doc = yaml.safe_load(path.read_text(encoding='utf-8'))
        model = next(iter(doc.values()))['ros__parameters']['model']
        model_path = resolve_path(str(model), 'mindgrasp_classifier', ('.json',))
    except (OSError, yaml.YAMLError, AttributeError, KeyError, TypeError, StopIteration,
            ResourceNotFoundError):
        return None
    if model_path.suffix != '.json':      # a model named by its stem
        model_path = model_path.with_name(model_path.name + '.json')
    return model_calibration_accuracy(model_path)


#: the flat summary keys of the answer pair and the calibration gate (answer_summary)
ANSWER_KEYS = ('answer_pair', 'gate_verdict', 'gate_reason', 'predicted_correct_rate',
               'predicted_wrong_rate', 'predicted_decision_time_s')


def answer_summary(run_dir: str | Path, records: Sequence[TrialRecord] = ()) -> dict:
    """The run's answer pair and its calibration gate, as flat summary keys
    (:data:`ANSWER_KEYS`): the pair the records name (the controller's, from ``/fsm/state``),
    else the one ``<run_dir>/params/fsm.yaml`` would resolve; the gate's verdict and predicted
    figures from the classifier model the fsm was given (``classifier_model``). Missing figures
    are NaN / ''; nothing for a run without a scan controller."""
    import json

    import yaml

    from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

    out: dict = {k: '' for k in ANSWER_KEYS[:3]}
    out.update({k: math.nan for k in ANSWER_KEYS[3:]})
    pairs = sorted({r.answer_pair for r in records if r.answer_pair})
    out['answer_pair'] = ','.join(pairs)
    try:
        doc = yaml.safe_load((Path(run_dir) / 'params' / 'fsm.yaml').read_text(encoding='utf-8'))
        params = next(iter(doc.values()))['ros__parameters']
    except (OSError, yaml.YAMLError, AttributeError, KeyError, TypeError, StopIteration):
        return out
    model = str(params.get('classifier_model') or '')
    meta: dict = {}
    if model:
        try:
            path = resolve_path(model, 'mindgrasp_classifier', ('.json',))
            if path.suffix != '.json':
                path = path.with_name(path.name + '.json')
            meta = json.loads(path.read_text(encoding='utf-8'))
        except (OSError, ValueError, ResourceNotFoundError):
            meta = {}
    if not out['answer_pair']:
        chosen = str(params.get('answer_pair', 'auto'))
        if chosen == 'auto':
            chosen = (meta.get('answer_pair') or {}).get('name', 'hands_feet')
        out['answer_pair'] = chosen if params.get('paradigm', 'scan') == 'scan' else ''
    gate = meta.get('gate') if isinstance(meta.get('gate'), dict) else {}
    predicted = gate.get('predicted') or {}
    out['gate_verdict'] = str(gate.get('verdict', ''))
    out['gate_reason'] = str(gate.get('reason', ''))
    for key in ('correct_rate', 'wrong_rate', 'decision_time_s'):
        value = predicted.get(key)
        out[f'predicted_{key}'] = float(value) if isinstance(value, (int, float)) else math.nan
    return out


def summarise(records: Sequence[TrialRecord], calibration_accuracy: float | None = None) -> dict:
    """Every figure of a set of trials (interrupted ones left out, counted apart):

    - ``success``, ``correct_choice``, ``correct_and_successful`` (the ``correct_grasp``
      outcome), ``wrong_grasp``, ``no_grasp``: ``<name>_rate``, ``<name>_ci95`` (Wilson 95 %),
      ``<name>_count``; success per desired shape;
    - times (s): mean and median time to a successful grasp, ``median_time_to_correct_grasp_s``
      (NaN without a correct grasp), mean and median trial duration;
    - the decoder's ``online_accuracy`` (pooled over classifier windows judged against the
      subject's intent) and ``online_decision_accuracy`` (per held intent), with Wilson CIs and
      their ``online_windows`` / ``online_decisions``; ``calibration_accuracy`` (the model's
      cross-validated accuracy, given by the caller: :func:`calibration_accuracy_of`);
    - the selection's information transfer rate ``itr_bits_per_min`` (:mod:`.itr`) with its
      ``itr_choices`` (N), ``selection_accuracy`` (P: correct grasps among grasps),
      ``selections`` and ``itr_bits_per_selection``;
    - failures by kind, node errors, cancels, mean certainty, path length and class switches.
    """
    records = list(records)
    kept = counted(records)
    n = len(kept)
    out: dict = {'trials': n, 'interrupted_trials': len(records) - n}
    for field in ('success', 'correct_choice', 'correct_and_successful'):
        r = _rate(kept, field)
        out[f'{field}_rate'] = r['rate']
        out[f'{field}_ci95'] = r['ci95']
        out[f'{field}_count'] = r['count']
    outcomes = Counter(r.outcome for r in kept)
    for outcome in ('wrong_grasp', 'no_grasp'):
        r = _count_rate(outcomes[outcome], n)
        out[f'{outcome}_rate'] = r['rate']
        out[f'{outcome}_ci95'] = r['ci95']
        out[f'{outcome}_count'] = r['count']
    out['success_by_shape'] = {shape: _rate([r for r in kept if shape_of(r.desired) == shape],
                                            'success') for shape in SHAPES}
    out['mean_time_to_grasp_s'], out['median_time_to_grasp_s'] = _stats(
        [r.time_to_grasp_s for r in kept if r.success])
    _, out['median_time_to_correct_grasp_s'] = _stats(
        [r.time_to_grasp_s for r in kept if r.outcome == 'correct_grasp'])
    out['mean_duration_s'], out['median_duration_s'] = _stats([r.duration_s for r in kept])
    failures: dict[str, int] = {}
    for r in kept:
        if r.failure:
            failures[r.failure] = failures.get(r.failure, 0) + 1
    out['failures'] = failures
    out['node_errors'] = failures.get('node_error', 0)
    out['cancels'] = sum(r.cancels for r in kept)
    # the decoder: windows pooled over trials (a trial with many windows weighs more)
    windows = sum(r.decoder_windows for r in kept)
    hits = sum(r.decoder_hits for r in kept)
    decisions = sum(r.decoder_decisions for r in kept)
    decision_hits = sum(r.decoder_decision_hits for r in kept)
    out['online_accuracy'] = hits / windows if windows else math.nan
    out['online_accuracy_ci95'] = list(wilson(hits, windows))
    out['online_windows'] = windows
    out['online_decision_accuracy'] = decision_hits / decisions if decisions else math.nan
    out['online_decision_accuracy_ci95'] = list(wilson(decision_hits, decisions))
    out['online_decisions'] = decisions
    out['calibration_accuracy'] = (math.nan if calibration_accuracy is None
                                   else float(calibration_accuracy))
    # the selection: a grasp of some object is one; the time is that of every counted trial
    selections = outcomes['correct_grasp'] + outcomes['wrong_grasp']
    p = outcomes['correct_grasp'] / selections if selections else math.nan
    choices = selection_choices(kept)
    minutes = math.fsum(r.duration_s for r in kept) / 60.0
    out['itr_choices'] = choices
    out['selections'] = selections
    out['selection_accuracy'] = p
    out['itr_bits_per_selection'] = bits_per_selection(choices, p) if choices else math.nan
    out['itr_bits_per_min'] = itr_bits_per_min(choices, p, selections, minutes) if choices \
        else math.nan
    out['mean_certainty'], _ = _stats([r.mean_certainty for r in kept])
    out['mean_path_length_m'], _ = _stats([r.path_length_m for r in kept])
    out['mean_class_switches'], _ = _stats([float(r.class_switches) for r in kept])
    return out
