"""Honest calibration figures: leave-one-run-out, the class/run confound, rest as a class,
temperature scaling, pseudo-online scoring and the reliability diagram."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from mindgrasp_classifier.calibration import (
    calibration_bins,
    expected_calibration_error,
    fit_temperature,
    nll,
    plot_reliability,
)
from mindgrasp_classifier.commands._common import format_cv_report
from mindgrasp_classifier.data import add_rest_events
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.params import ClassifierParams
from mindgrasp_classifier.pipelines import softmax
from mindgrasp_classifier.pseudo_online import (
    format_pseudo_online,
    label_segments,
    node_adaptation,
    pseudo_online,
    window_labels,
)
from mindgrasp_classifier.training import TrainingConfig, evaluate, train

from .classifier_synth import make_recording

REST = 4


@pytest.fixture(scope='module')
def rest_runs():
    """Two annotated recordings with every class and rest (T0), as EEGMMIDB runs would be."""
    return [make_recording(trials_per_class=5, seed=s, annotate=True, source=f'S0R0{s}.edf')
            for s in (1, 2)]


def test_several_recordings_are_cross_validated_leave_one_run_out(tmp_path):
    recs = [make_recording(trials_per_class=5, seed=s, source=f'run{s}.edf') for s in (1, 2)]
    model, report = train(recs, TrainingConfig(channels='all'))
    cv = model.provenance['cross_validation']
    assert cv['scheme'] == report['scheme'] == 'leave_one_run_out'
    assert cv['folds'] == 2 and not cv['confounded'] and 'confound' not in cv
    assert cv['accuracy'] >= 0.9 and cv['balanced_accuracy'] >= 0.9
    assert [r['recording'] for r in cv['per_run']] == ['run1.edf', 'run2.edf']
    assert all(r['n_trials'] == 20 and r['accuracy'] >= 0.9 for r in cv['per_run'])
    # the figures survive the model file
    loaded = MiModel.load(model.save(tmp_path / 'm'))
    assert loaded.provenance['cross_validation']['scheme'] == 'leave_one_run_out'
    # a single recording keeps the trial-grouped k-fold
    single, rep = train(recs[:1], TrainingConfig(channels='all', cv_folds=3))
    assert single.provenance['cross_validation']['scheme'] == 'trial_grouped_kfold'
    assert rep['folds'] == 3 and 'per_run' not in rep
    assert 'Cross-validation (3 folds, grouped by trial; scheme trial_grouped_kfold' in \
        format_cv_report(rep)


def test_class_run_confound_is_said_and_the_kfold_labelled_optimistic():
    # as EEGMMIDB runs 4 and 6: left/right in one recording, both hands/feet in the other
    recs = [make_recording(classes=(0, 1), trials_per_class=6, seed=1, source='S001R04.edf'),
            make_recording(classes=(2, 3), trials_per_class=6, seed=2, source='S001R06.edf',
                           mixing_seed=99)]   # class mixings of their own
    model, report = train(recs, TrainingConfig(channels='all', cv_folds=3))
    cv = model.provenance['cross_validation']
    assert cv['scheme'] == 'leave_one_run_out' and cv['confounded']
    assert cv['confound'].startswith(
        'Classes and recordings are confounded (left_hand, right_hand only in S001R04.edf; '
        'both_hands, both_feet only in S001R06.edf): ')
    # no held-out recording has a class the other contains: nothing honest to report
    assert cv['accuracy'] is None and cv['balanced_accuracy'] is None
    assert cv['n_unscored_trials'] == 24
    assert cv['optimistic']['scheme'] == 'trial_grouped_kfold'
    assert cv['optimistic']['accuracy'] >= 0.9
    text = format_cv_report(report)
    assert cv['confound'] in text and 'optimistic (trial_grouped_kfold, 3 folds' in text
    assert 'measures nothing here' in text
    # temperature from the k-fold (leave-one-run-out has no held-out windows)
    assert model.provenance['calibration']['source'] == 'trial_grouped_kfold'


def test_confounded_runs_with_rest_score_the_shared_class(rest_runs):
    a = make_recording(classes=(0, 1), trials_per_class=5, seed=3, annotate=True,
                       source='a.edf')
    b = make_recording(classes=(2, 3), trials_per_class=5, seed=4, annotate=True,
                       source='b.edf', mixing_seed=99)
    model, report = train([a, b], TrainingConfig(channels='all', rest=True, cv_folds=3))
    assert model.classes == [0, 1, 2, 3, REST]
    assert report['confounded'] and report['scored_classes'] == ['rest']
    assert [r['scored_classes'] for r in report['per_run']] == [['rest'], ['rest']]
    assert report['n_trials'] == 20 and report['accuracy'] >= 0.9    # rest is white noise


def test_rest_as_a_class(rest_runs):
    model, report = train(rest_runs, TrainingConfig(channels='all', rest=True))
    assert model.classes == [0, 1, 2, 3, REST]
    assert model.class_names[-1] == 'rest'
    assert model.provenance['trials_per_class']['rest'] == 40
    assert report['accuracy'] >= 0.9
    # three classes: rest, both hands, both feet (rest implied by the classes)
    three, rep3 = train(rest_runs, TrainingConfig(channels='all', classes=[2, 3, REST]))
    assert three.classes == [2, 3, REST] and rep3['accuracy'] >= 0.9
    assert three.provenance['config']['classes'] == [2, 3, REST]
    ev = evaluate(three, [add_rest_events(rest_runs[0])])
    assert ev['trials_per_class'] == {'both_hands': 5, 'both_feet': 5, 'rest': 20}
    with pytest.raises(ClassifierError, match="no 'T0' annotations to label as rest"):
        train([make_recording(seed=1)], TrainingConfig(channels='all', rest=True))
    with pytest.raises(ClassifierError, match='leave rest out'):
        train(rest_runs, TrainingConfig(channels='all', rest=True, classes=[2, 3]))


def test_temperature_scaling_lowers_the_nll():
    rng = np.random.RandomState(0)
    n, k = 4000, 3
    true_logits = rng.randn(n, k) * 1.5
    labels = np.array([rng.choice(k, p=p) for p in softmax(true_logits)])
    over = 3.0 * true_logits                 # an over-confident classifier
    t = fit_temperature(over, labels)
    assert 2.5 < t < 3.5
    assert nll(over, labels, t) < nll(over, labels, 1.0) - 0.1
    assert expected_calibration_error(softmax(over / t), labels) < 0.03 < \
        expected_calibration_error(softmax(over), labels)
    # classes a fold did not know (-inf logits) keep probability 0
    masked = over.copy()
    masked[labels != 2, 2] = -np.inf
    assert np.isfinite(nll(masked, labels, fit_temperature(masked, labels)))


def test_training_fits_the_temperature_on_held_out_windows(rest_runs):
    noisy = [make_recording(trials_per_class=5, seed=s, annotate=True, source=f'r{s}.edf',
                            amplitude=10e-6) for s in (5, 6)]
    for rec in noisy:   # sensor noise so that held-out predictions are not all certain
        rec.data = rec.data + np.random.RandomState(9).randn(*rec.data.shape) * 14e-6
    model, report = train(noisy, TrainingConfig(channels='all', rest=True))
    cal = model.provenance['calibration']
    assert cal['method'] == 'temperature_scaling' and cal['source'] == 'leave_one_run_out'
    assert cal['temperature'] == model.temperature != 1.0
    assert cal['nll'] <= cal['nll_uncalibrated']
    assert report['calibration'] == cal
    uncal, _ = train(noisy, TrainingConfig(channels='all'), cross_validate=False)
    assert uncal.temperature == 1.0


def test_calibration_bins():
    p = np.array([[0.95, 0.05], [0.9, 0.1], [0.55, 0.45], [0.6, 0.4]])
    b = calibration_bins(p, np.array([0, 1, 0, 0]), n_bins=2)
    assert b['count'] == [0, 4] and b['accuracy'] == [None, 0.75]
    assert b['ece'] == pytest.approx(abs(0.75 - np.mean([0.95, 0.9, 0.55, 0.6])))


def test_windows_are_labelled_by_the_annotation_they_lie_in(rest_runs):
    rec = add_rest_events(rest_runs[0])
    seg = label_segments(rec)
    onset, cls = rec.events[0]
    assert tuple(seg[0]) == (onset, onset + round(3.0 * rec.rate), cls)  # the 3 s cue
    n = 128
    ends = np.array([onset + n - 2, onset + n - 1, onset + 3 * 128 - 1, onset + 3 * 128 + 10])
    labels = window_labels(ends, n, seg)
    # starts before the cue; inside; ends on the cue's last sample; straddles cue -> rest
    assert labels.tolist() == [-1, cls, cls, -1]
    # events without annotations: their cue epoch [tmin, tmax]
    bare = make_recording(seed=1)
    o = bare.events[0, 0]
    assert tuple(label_segments(bare, 0.5, 2.5)[0][:2]) == (o + 64, o + 320)


def test_pseudo_online_report(rest_runs, tmp_path):
    model, _ = train(rest_runs, TrainingConfig(channels='all', rest=True))
    test = add_rest_events(make_recording(trials_per_class=2, seed=7, annotate=True))
    report, windows = pseudo_online(model, [test])
    assert set(report) >= {'trial', 'window', 'binary', 'calibration', 'classes',
                           'n_predictions'}
    assert set(report['window']) >= {'accuracy', 'balanced_accuracy', 'per_class', 'confusion',
                                     'n_windows', 'windows_per_class', 'n_left_out'}
    assert set(report['binary']) == {'left_vs_right', 'hands_vs_feet', 'rest_vs_imagery',
                                     'rest_vs_both_hands', 'rest_vs_both_feet',
                                     'both_feet_vs_others'}
    assert report['binary']['both_feet_vs_others']['n_windows'][1] > \
        report['binary']['rest_vs_imagery']['n_windows'][0]        # rest and hands both count
    for b in report['binary'].values():
        assert set(b) == {'accuracy', 'balanced_accuracy', 'auc', 'n_windows'}
        assert b['accuracy'] >= 0.9
    assert set(report['calibration']) >= {'ece', 'ece_uncalibrated', 'nll', 'temperature'}
    assert report['window']['per_class']['rest'] >= 0.9 and report['trial']['accuracy'] >= 0.9
    assert report['window']['n_windows'] == len(windows.labels)
    assert report['window']['n_left_out'] > 0      # straddling windows, first second
    # the trial figure is the offline evaluation's (one code path with the online decoder)
    assert report['trial']['accuracy'] == evaluate(model, [test])['accuracy']
    assert 'rest_vs_both_hands' in format_pseudo_online(report)
    assert report['adaptation'] == {'mode': 'none', 'recenter': 'fixed'}
    # as the classifier node decodes by default (its parameter defaults)
    loop = node_adaptation()
    assert (loop.recenter, loop.mode, loop.recenter_rate, loop.recenter_prior) == (
        ClassifierParams.recenter, ClassifierParams.adaptation, ClassifierParams.recenter_rate,
        ClassifierParams.recenter_prior)
    rep_loop, _ = pseudo_online(model, [test], adaptation=loop)
    assert rep_loop['adaptation']['recenter'] == loop.recenter
    assert rep_loop['window']['n_windows'] == report['window']['n_windows']
    # a model without rest leaves rest windows out, and has no rest binaries
    no_rest, _ = train(rest_runs, TrainingConfig(channels='all', classes=[0, 1, 2, 3]))
    rep2, win2 = pseudo_online(no_rest, [test])
    assert REST not in win2.labels and 'rest' not in rep2['window']['per_class']
    assert set(rep2['binary']) == {'left_vs_right', 'hands_vs_feet', 'both_feet_vs_others'}


def test_reliability_diagram_is_written(tmp_path):
    rng = np.random.RandomState(1)
    logits = rng.randn(500, 3) * 2
    labels = rng.randint(0, 3, 500)
    path = plot_reliability(logits, labels, 1.7, tmp_path / 'plots' / 'rel.png', title='x')
    assert path.is_file() and path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def _mindgrasp(*args):
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_train_and_evaluate_rest_model_on_eegmmidb(tmp_path, eegbci_path):
    """Runs 4 and 6 confound classes and runs: the printout says so; pseudo-online on run 10."""
    out = _mindgrasp('train', 'classifier', '--eegbci', '1', '--runs', '4', '6', '--classes',
                     'rest,both_hands,both_feet', '--train-step', '0.25', '-o',
                     str(tmp_path / 'm'), '--json')
    assert out.returncode == 0, out.stderr
    assert 'Classes and recordings are confounded (both_hands, both_feet only in S001R06.edf)' \
        in out.stdout
    assert 'optimistic (trial_grouped_kfold, 5 folds over all recordings)' in out.stdout
    assert "trials {'both_hands': 7, 'both_feet': 8, 'rest': 30}" in out.stdout
    report = json.loads(out.stdout.strip().splitlines()[-1])
    assert report['scheme'] == 'leave_one_run_out' and report['classes'] == [
        'both_hands', 'both_feet', 'rest']
    res = _mindgrasp('evaluate', 'classifier', '--model', str(tmp_path / 'm.json'), '--eegbci',
                     '1', '--runs', '10', '--pseudo-online', '--plots', str(tmp_path / 'plots'),
                     '--json')
    assert res.returncode == 0, res.stderr
    result = json.loads(res.stdout.strip().splitlines()[-1])
    online = result['pseudo_online']
    assert online['trial']['trials_per_class'] == {'both_hands': 7, 'both_feet': 8, 'rest': 15}
    assert online['window']['windows_per_class']['rest'] > 0
    assert set(online['binary']) == {'hands_vs_feet', 'rest_vs_imagery', 'rest_vs_both_hands',
                                     'rest_vs_both_feet', 'both_feet_vs_others'}
    assert online['binary']['hands_vs_feet']['accuracy'] >= 0.7      # 0.89 when written
    assert (tmp_path / 'plots' / 'reliability_pseudo_online.png').is_file()
    assert (tmp_path / 'plots' / 'reliability_offline.png').is_file()
    assert 'Pseudo-online (' in res.stdout and 'rest_vs_both_hands' in res.stdout


def test_ts_lr_carries_no_prior_from_the_class_counts():
    from pyriemann.datasets import make_matrices

    from mindgrasp_classifier.pipelines import TsLrClassifier

    # one distribution, four times as many windows of class 4 as of class 2: nothing to learn
    covs = make_matrices(200, 4, 'spd', np.random.RandomState(3))
    y = np.array([REST] * 160 + [2] * 40)
    balanced = TsLrClassifier().fit(covs, y).predict_proba(covs).mean(axis=0)
    counted = TsLrClassifier(class_weight=None).fit(covs, y).predict_proba(covs).mean(axis=0)
    assert abs(balanced[1] - 0.5) < 0.1 and counted[1] > 0.7   # columns: 2, rest
